"""The reach learner's robot: the kinematic iCub under MoBeE, one state-action at a time.

The target's role (ch. 8.1 footnote 2: a target is an obstacle until the reach touches it): the
target sphere is an obstacle of MoBeE's world (``SetProblem``); during a reach, and only then, a
transient collision filter excludes the pairs of the hand (the reaching marker's body and every
body beyond it: the iCub's hand has none, the Katana's wrist carries its fingers) and the
target, so the palm may touch and enter it while the rest of the arm is still kept out. A reach
ends its problem-try: when it has ended (settled back at its state's centre) the filter and the
target go, so that nothing the robot does before the next problem (an evaluation's walk to its
start state) has to push the hand out of a target it was let into; the next problem's target
appears with ``SetProblem``. A try that runs out of actions ends too (``EndProblem``): its
target goes, so that the walk does not go around the target of a problem that is over. A
transition therefore must go around the target, and fails when it cannot.
"""

import numpy as np
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet
from pydrake.math import RigidTransform
from pydrake.systems.analysis import InitializeParams

from mobee_drake.planning.actuation_noise import NoisyPosture, ValidateNoise
from mobee_drake.planning.state_space import StateActionSpace
from mobee_drake.reaching.targets import TARGET_NAME, TargetObject
from mobee_drake.station.builder import Station
from mobee_drake.station.checkpoint import ReadCheckpointFiles, WriteCheckpointFiles
from mobee_drake.station.executor import StateActionExecutor
from mobee_drake.station.safety import SafetyReport
from mobee_drake.station.world_events import MakeSimulator


def _BodiesFrom(plant, body) -> set:
    """The indices of ``body`` and of every body beyond it in the tree (a hand and its fingers)."""
    outboard = [
        joint.index()
        for joint in (plant.get_joint(i) for i in plant.GetJointIndices())
        if joint.parent_body().index() == body.index()
    ]
    return {body.index(), *(plant.GetBodiesKinematicallyAffectedBy(outboard) if outboard else [])}


class SimulatedRobot:
    """Runs the learner's state-actions on a built station whose client is a
    :class:`StateActionExecutor` (a scenario with a ``StateActionAttractor``), alone or among
    behaviours (a torso beside it, say).

    ``joints`` are the MDP's joints (``space``'s dimensions, in fractions of their ranges); the
    rest of MoBeE's joints stay at home. With ``realtime`` the robot moves in real time (for a
    station shown in Meshcat). ``transition_noise`` makes the robot stochastic: every transition
    is commanded to its goal state's centre plus actuation noise of that standard deviation (a
    fraction of each joint's range, drawn from ``noise_seed``; see
    :mod:`mobee_drake.planning.actuation_noise`).
    """

    def __init__(
        self,
        station: Station,
        joints: list[str],
        space: StateActionSpace,
        target_radius: float,
        poll: float = 0.1,
        realtime: bool = False,
        transition_noise: float = 0.0,
        noise_seed: int = 0,
    ):
        executors = [
            s for s in station.Hooks("action_counters") if isinstance(s, StateActionExecutor)
        ]
        if len(executors) != 1:
            raise ValueError("the reach learner's station needs one StateActionAttractor client")
        self.station = station
        self.simulator = MakeSimulator(station)
        if realtime:
            self.simulator.set_target_realtime_rate(1.0)
        self.simulator.Initialize()
        self.context = self.simulator.get_mutable_context()
        # (the station's client, or one of its behaviours: station/composition.py)
        self.executor: StateActionExecutor = executors[0]
        self._executor_context = self.executor.GetMyMutableContextFromRoot(self.context)
        mobee = station.mobee
        unknown = [j for j in joints if j not in mobee.joints]
        if unknown:
            raise ValueError(
                f"the MDP's joints {unknown} are not MoBeE's: " + ", ".join(mobee.joints)
            )
        ValidateNoise(transition_noise)
        self._noise, self._noise_seed = transition_noise, noise_seed
        self.space, self._poll, self._radius = space, poll, target_radius
        self._columns = np.array([mobee.joints.index(j) for j in joints])
        self._lower, self._upper = mobee.position_limits
        self._home = mobee.home
        plant = station.plant
        marker = self.executor.marker_name
        hand_body = [m.body_name for m in station.robot.markers if m.name == marker][0]
        self._marker = mobee.marker_index(marker)
        # The current problem's target (None before the first problem and after a reach).
        self.target: np.ndarray | None = None
        # The shoulder's frame, and where it stands with every joint at home (a scratch plant
        # context: the station's plant is not simulated).
        self._scratch = plant.CreateDefaultContext()
        self._shoulder = plant.GetJointByName(joints[0]).frame_on_parent()
        self._shoulder_at_home = self._ShoulderPose(self._home)
        hand = _BodiesFrom(plant, plant.GetBodyByName(hand_body))
        self._hand = [
            g
            for g, frame in station.robot.geometry_frames.items()
            if plant.get_frame(frame).body().index() in hand
        ]

    # The configuration of a state's centre, and the state of the robot's configuration.
    def _Centre(self, state: int) -> np.ndarray:
        q = self._home.copy()
        q[self._columns] = self.space.Centre(
            state, self._lower[self._columns], self._upper[self._columns]
        )
        return q

    def State(self) -> int:
        q = self.station.robot_state.Eval(self.context)[: len(self._home)]
        return self.space.StateOfConfiguration(
            q[self._columns], self._lower[self._columns], self._upper[self._columns]
        )

    def SetProblem(self, target: np.ndarray) -> None:
        self.target = np.asarray(target, dtype=float)
        world = self.station.world
        if TARGET_NAME in world.Names(self.context):
            world.Move(self.context, TARGET_NAME, [float(c) for c in target])
        else:
            world.Add(self.context, TargetObject(target, self._radius))

    def _Finish(self) -> None:
        while not self.executor.Done(self._executor_context):
            self.simulator.AdvanceTo(self.context.get_time() + self._poll)

    def Transition(self, goal: int) -> int:
        q_star, columns = self._Centre(goal), self._columns
        q_star[columns] = NoisyPosture(
            q_star[columns],
            self._lower[columns],
            self._upper[columns],
            self._noise,
            self._noise_seed,
            0,
            self.context.get_time(),
        )
        self.MoveTo(q_star)
        return self.State()

    def MoveTo(self, q_star: np.ndarray) -> None:
        """Sets MoBeE's attractor to ``q_star`` (every joint of MoBeE's) and waits until the
        robot has settled."""
        self.executor.StartTransition(self._executor_context, q_star)
        self._Finish()

    def Reach(self, target: np.ndarray) -> np.ndarray:
        scene_graph = self.station.scene_graph
        filters = scene_graph.collision_filter_manager(
            scene_graph.GetMyMutableContextFromRoot(self.context)
        )
        touch = filters.ApplyTransient(
            CollisionFilterDeclaration().ExcludeBetween(
                GeometrySet(self._hand),
                GeometrySet(self.station.world.GeometryIdOf(self.context, TARGET_NAME)),
            )
        )
        self.executor.StartReach(self._executor_context, self._Centre(self.State()), target)
        self._Finish()
        filters.RemoveDeclaration(touch)
        self.EndProblem()  # (the problem-try is over)
        return self.executor.ReachedPosition(self._executor_context)

    def EndProblem(self) -> None:
        if self.target is not None:
            self.station.world.Remove(self.context, TARGET_NAME)
            self.target = None

    def FeltObject(self) -> bool:
        return self.executor.FeltObject(self._executor_context)

    def _ShoulderPose(self, q: np.ndarray) -> RigidTransform:
        """X_WS: the shoulder's frame (where the MDP's first joint sits on its parent body) with
        MoBeE's joints at ``q``."""
        self.station.plant.SetPositions(self._scratch, self.station.mobee.PlantPositions(q))
        return self._shoulder.CalcPoseInWorld(self._scratch)

    @property
    def shoulder_at_home(self) -> RigidTransform:
        """X_WS with every joint at home: the learning frame's place in the world."""
        return self._shoulder_at_home

    def LearningFrame(self, target: np.ndarray) -> np.ndarray:
        """``target`` where it is relative to the shoulder now, put back in the world as the
        shoulder stood with the torso at home (see ``Robot.LearningFrame``)."""
        target = np.asarray(target, dtype=float)
        q = self.station.robot_state.Eval(self.context)[: len(self._home)]
        X_WS = self._ShoulderPose(q)
        if np.array_equal(X_WS.GetAsMatrix34(), self._shoulder_at_home.GetAsMatrix34()):
            return target  # (exactly: a run without a torso repeats bit for bit)
        return self._shoulder_at_home @ (X_WS.inverse() @ target)

    def MarkerPosition(self) -> np.ndarray:
        """Where the reaching marker (the palm) is now (world, m)."""
        mobee = self.station.mobee
        positions = mobee.GetOutputPort("marker_positions").Eval(
            mobee.GetMyContextFromRoot(self.context)
        )
        return positions[3 * self._marker : 3 * self._marker + 3].copy()

    @property
    def simulated_seconds(self) -> float:
        return self.context.get_time()

    def Save(self, folder) -> None:
        """Saves where the robot is (and the executor's state) as a simulation checkpoint."""
        WriteCheckpointFiles(self.station, self.context, folder)

    def Load(self, folder) -> None:
        ReadCheckpointFiles(self.station, self.context, folder)
        self.simulator.Initialize(InitializeParams(suppress_initialization_events=True))

    def Safety(self) -> SafetyReport:
        """The station's safety monitor so far (penetrations, the barrier's periods)."""
        monitor = self.station.monitor
        return monitor.Report(monitor.GetMyContextFromRoot(self.context))
