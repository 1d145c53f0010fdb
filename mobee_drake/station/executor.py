"""State-actions on the robot: state transitions and dynamic reaches (dissertation ch. 8.2).

A *transition* sets MoBeE's attractor q* to a state's centre and ends when the robot has settled (as
the actions of ch. 6-7, :mod:`mobee_drake.station.settling`, watching all of MoBeE's joints). A
*reach* keeps q* at the centre of the state it starts from and forces a marker (the palm) toward a
workspace target x* through MoBeE's workspace force f_work (eq. 5.10, the J^T direction), in real
time; when the robot stops (or the timeout passes) the marker's position is taken for the reward of
eq. 8.4, the forcing stops, the attractor pulls the robot back, and the reach ends when the robot
has settled a second time.

The force on the marker points at the target with a magnitude that fades within
``softening`` of it: ``F (x* - x) / (|x* - x| + softening)`` (the source interprets Alg. 5's
``dq`` as a direction; the fading keeps the force from chattering once the marker is there).
How far the marker gets is decided by MoBeE: the squashed force against the attractor spring,
the joint limits, the constraints and the obstacles.

The executor also notes whether MoBeE's fields felt a workspace object (a field pair whose other
geometry is not the robot's) at any poll of the action in flight: the learner of ch. 9.4.1 tells
a problem's obstacle from its own model's error by it. Sampled at the poll period, like the
settling; a touch shorter than a poll can be missed, a transition blocked by an object is not.

Everything the executor knows is in its discrete state, so a checkpoint of the diagram's
discrete states (:mod:`mobee_drake.station.checkpoint`) holds the action in flight too.
"""

import dataclasses as dc
import enum

import numpy as np
from pydrake.common.containers import namedview
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import BasicVector, LeafSystem

from mobee_drake.mobee.fields import NO_FIELD_PAIRS, FieldPairs
from mobee_drake.station.parts import ClientPorts, StationParts
from mobee_drake.station.settling import ActionTiming


class Phase(enum.IntEnum):
    IDLE = 0  # no action in flight: q* stays where the last one put it
    MOVING = 1  # a transition: q* at the goal state's centre
    FORCING = 2  # a reach, the marker forced toward the target
    RETURNING = 3  # a reach, the forcing stopped, back to the state's centre


# The executor's discrete state, named (q* of MoBeE's joints follows as q_star_<i>): the phase,
# the actions finished, the phase's start time, since when the robot has been slow (inf: not
# slow), whether the fields felt an object, the reaches whose forcing has ended, the target x*
# of the last reach and where the marker was when its forcing stopped.
SLOTS = ("phase", "finished_actions", "started", "slow_since", "felt_object", "reaches")
SLOTS += tuple(f"target_{c}" for c in "xyz") + tuple(f"reached_{c}" for c in "xyz")
TARGET = slice(SLOTS.index("target_x"), SLOTS.index("target_z") + 1)
REACHED = slice(SLOTS.index("reached_x"), SLOTS.index("reached_z") + 1)
Q_STAR = len(SLOTS)
# What the data log keeps of the state (see DataLogColumns).
LOGGED = [SLOTS.index("phase"), SLOTS.index("finished_actions")]


@dc.dataclass
class ReachForcing:
    """The workspace force of a reach (ch. 8.2)."""

    # The marker forced toward the target.
    marker: str = "r_palm"
    # Force magnitude far from the target (N on the marker, before MoBeE's squashing).
    force: float = 300.0
    # Within about this distance of the target the force fades linearly (m).
    softening: float = 0.05


class StateActionExecutor(LeafSystem):
    """Executes one state-action at a time on MoBeE: transitions and reaches.

    .. pydrake_system::

        name: StateActionExecutor
        input_ports:
        - robot_state
        - marker_positions
        - field_pairs
        output_ports:
        - attractor
        - marker_forces
        - data_log

    ``robot_state`` is (q, v) of MoBeE's n joints, ``marker_positions`` MoBeE's output of the same
    name (3m), ``field_pairs`` MoBeE's :class:`FieldPairs`; ``attractor`` is q* (n),
    ``marker_forces`` the force on every marker (3m, zero but on the reaching marker while it is
    forced).

    A client starts an action with :meth:`StartTransition` or :meth:`StartReach` and polls
    :meth:`Done`; :meth:`ReachedPosition` is the marker's position at the end of the forcing,
    :meth:`FeltObject` whether the fields felt a workspace object during the action.
    """

    def __init__(
        self,
        *,
        num_joints: int,
        marker_index: int,
        num_markers: int,
        initial_attractor: np.ndarray,
        forcing: ReachForcing | None = None,
        timing: ActionTiming | None = None,
        period: float = 0.1,
    ):
        super().__init__()
        self._n, self._marker, self._num_markers = num_joints, marker_index, num_markers
        self._forcing = forcing or ReachForcing()
        self._timing = timing or ActionTiming()
        if not (self._forcing.force > 0 and self._forcing.softening > 0):
            raise ValueError(
                f"reach forcing: force and softening must be > 0, got "
                f"{self._forcing.force} and {self._forcing.softening}"
            )
        self._View = namedview(
            "ExecutorState", SLOTS + tuple(f"q_star_{i}" for i in range(num_joints))
        )
        initial = self._View(np.zeros(len(SLOTS) + num_joints))
        initial.slow_since = np.inf
        initial[Q_STAR:] = initial_attractor
        self._state_port = self.DeclareVectorInputPort("robot_state", 2 * num_joints)
        self._markers_port = self.DeclareVectorInputPort("marker_positions", 3 * num_markers)
        self._pairs_port = self.DeclareAbstractInputPort(
            "field_pairs", AbstractValue.Make(NO_FIELD_PAIRS)
        )
        self._state = self.DeclareDiscreteState(BasicVector(initial[:]))
        self.DeclarePeriodicDiscreteUpdateEvent(
            period_sec=period, offset_sec=period, update=self._Poll
        )
        self.DeclareVectorOutputPort(
            "attractor",
            num_joints,
            lambda context, output: output.SetFromVector(self._Vector(context)[Q_STAR:]),
            prerequisites_of_calc={self.discrete_state_ticket(self._state)},
        )
        self.DeclareVectorOutputPort(
            "marker_forces",
            3 * num_markers,
            self._CalcMarkerForces,
            prerequisites_of_calc={
                self.discrete_state_ticket(self._state),
                self._markers_port.ticket(),
            },
        )

        # What the station's data log keeps (see DataLogColumns).
        self.DeclareVectorOutputPort(
            "data_log",
            2,
            lambda context, output: output.SetFromVector(self._Vector(context)[LOGGED]),
            prerequisites_of_calc={self.discrete_state_ticket(self._state)},
        )

    def DataLogColumns(self) -> list[tuple[str, str]]:
        """The phase of the action in flight (a :class:`Phase`) and the actions finished (see
        :mod:`mobee_drake.station.data_log`)."""
        return [("executor.phase", "Phase"), ("executor.finished_actions", "count")]

    def _Vector(self, context) -> np.ndarray:
        return context.get_discrete_state(self._state).value()

    def State(self, context):
        """A copy of the discrete state in ``context`` (its own), as a named view (:data:`SLOTS`,
        then ``q_star_<i>``); :meth:`SetState` writes one back."""
        return self._View(self._Vector(context).copy())

    def SetState(self, context, state) -> None:
        context.SetDiscreteState(self._state, state[:])

    def _Marker(self, context) -> np.ndarray:
        return self._markers_port.Eval(context)[3 * self._marker : 3 * self._marker + 3]

    def _CalcMarkerForces(self, context, output) -> None:
        x = self._View(self._Vector(context))
        forces = np.zeros(3 * self._num_markers)
        if x.phase == Phase.FORCING:
            error = x[TARGET] - self._Marker(context)
            forces[3 * self._marker : 3 * self._marker + 3] = (
                self._forcing.force * error / (np.linalg.norm(error) + self._forcing.softening)
            )
        output.SetFromVector(forces)

    def _Poll(self, context, discrete_state) -> None:
        x = self.State(context)
        phase = Phase(int(x.phase))
        if phase == Phase.IDLE:
            return
        now, timing = context.get_time(), self._timing
        v = self._state_port.Eval(context)[self._n :]
        pairs: FieldPairs = self._pairs_port.Eval(context)
        if not np.all(pairs.b_is_robot):
            x.felt_object = 1.0
        x.slow_since = timing.SlowSince(x.slow_since, now, v)
        if timing.Ended(now, x.started, x.slow_since):
            if phase == Phase.FORCING:
                x[REACHED] = self._Marker(context)
                x.reaches += 1
                x.phase = Phase.RETURNING
            else:
                x.phase = Phase.IDLE
                x.finished_actions += 1
            x.started, x.slow_since = now, np.inf
        discrete_state.set_value(self._state, x[:])

    def _Start(self, context, phase: Phase, q_star: np.ndarray, target=None) -> None:
        q_star = np.asarray(q_star, dtype=float)
        if q_star.shape != (self._n,):
            raise ValueError(f"q* must have {self._n} entries, got shape {q_star.shape}")
        x = self.State(context)
        if x.phase != Phase.IDLE:
            raise ValueError(f"an action is in flight (phase {Phase(int(x.phase)).name})")
        x.phase, x.started, x.slow_since = phase, context.get_time(), np.inf
        x.felt_object = 0.0
        x[Q_STAR:] = q_star
        if target is not None:
            x[TARGET] = target
        self.SetState(context, x)

    def StartTransition(self, context, q_star: np.ndarray) -> None:
        """Starts a state transition to the attractor ``q_star`` (this system's context)."""
        self._Start(context, Phase.MOVING, q_star)

    def StartReach(self, context, q_star: np.ndarray, target: np.ndarray) -> None:
        """Starts a reach for ``target`` (world, m) from the state whose centre is ``q_star``."""
        target = np.asarray(target, dtype=float)
        if target.shape != (3,) or not np.all(np.isfinite(target)):
            raise ValueError(f"a reach target must be three finite numbers, got {target}")
        self._Start(context, Phase.FORCING, q_star, target)

    @property
    def marker_name(self) -> str:
        """The marker a reach forces toward its target."""
        return self._forcing.marker

    def CurrentPhase(self, context) -> Phase:
        return Phase(int(self.State(context).phase))

    def Done(self, context) -> bool:
        """Whether no action is in flight."""
        return self.CurrentPhase(context) == Phase.IDLE

    def CompletedActions(self, context) -> int:
        """How many actions it has finished (a run with a checkpoint saves one after each)."""
        return int(self.State(context).finished_actions)

    def ReachedPosition(self, context) -> np.ndarray:
        """Where the marker was when the last reach's forcing stopped (world, m)."""
        return self.State(context)[REACHED].copy()

    def Outcome(self, context) -> dict:
        """The actions finished and, after a reach, the marker's distance to its target then."""
        x = self.State(context)
        outcome = {"finished_actions": int(x.finished_actions)}
        if x.reaches > 0:  # (a target may be anywhere, the origin too)
            distance = np.linalg.norm(x[REACHED] - x[TARGET])
            outcome["last_reach_distance_to_target_m"] = float(distance)
        return outcome

    def FeltObject(self, context) -> bool:
        """Whether MoBeE's fields felt a workspace object during the last (or current) action."""
        return bool(self.State(context).felt_object)


@dc.dataclass
class StateActionAttractor:
    """The attractor and a marker's force are set by a client's state-actions, one at a time:
    transitions and dynamic reaches (ch. 8)."""

    forcing: ReachForcing = dc.field(default_factory=ReachForcing)
    timing: ActionTiming = dc.field(default_factory=ActionTiming)

    def Validate(self) -> None:
        self.timing.Validate()
        if not (
            np.isfinite([self.forcing.force, self.forcing.softening]).all()
            and self.forcing.force > 0
            and self.forcing.softening > 0
        ):
            raise ValueError(
                f"reach forcing: force and softening must be > 0, got "
                f"{self.forcing.force} and {self.forcing.softening}"
            )

    def AddToBuilder(self, parts: StationParts) -> ClientPorts:
        mobee, builder = parts.mobee, parts.builder
        executor = builder.AddNamedSystem(
            f"{parts.prefix}state_action_executor",
            StateActionExecutor(
                num_joints=len(mobee.joints),
                marker_index=mobee.marker_index(self.forcing.marker),
                num_markers=len(mobee.marker_names),
                initial_attractor=mobee.home,
                forcing=self.forcing,
                timing=self.timing,
            ),
        )
        builder.Connect(parts.robot_state, executor.GetInputPort("robot_state"))
        builder.Connect(
            mobee.GetOutputPort("marker_positions"), executor.GetInputPort("marker_positions")
        )
        builder.Connect(mobee.GetOutputPort("field_pairs"), executor.GetInputPort("field_pairs"))
        return ClientPorts(
            system=executor,
            attractor=executor.GetOutputPort("attractor"),
            marker_forces=executor.GetOutputPort("marker_forces"),
            outcome=executor,
            action_counters=[executor],
            data_log=executor,
        )
