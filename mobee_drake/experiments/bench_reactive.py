"""Benchmark: MoBeE 2.0 against Drake's differential inverse kinematics as reactive controllers
(issue 22, point 1; docs/reactive.md).

Both controllers move the same kinematic iCub upper body (20 joints, MoBeE's overlay of
primitives and its collision filters) among the same obstacles at the same control period
(10 ms), from the same start posture, on seeded random reach-past-obstacle tasks:

- ``ball``: a goal posture of the torso and the right arm drawn at random within the joint
  limits (see :func:`DrawGoal`), and a ball of 5-10 cm diameter on the straight path of the
  right palm between start and goal, the robot's solids at least 5 cm clear of it at both ends;
- ``two_balls``: two such balls, one in each half of the path;
- ``shelf``: a ball and a board (a 25 x 25 x 2 cm box) 5-8 cm above it, on a palm path no
  steeper than 30 degrees;
- ``behind_arm``: the left arm held across the chest and a goal of the right arm whose straight
  palm path runs through the left arm (the obstacle is the robot's own body);
- and the shipped ``reach_around_ball``.

MoBeE is given the goal posture as its attractor (the station of the scenario, kinematic
mover); Drake's ``DifferentialInverseKinematicsSystem`` the goal's palm position (its
``LeastSquaresCost`` on the palm's translation), with the goal posture as the nominal posture of
its ``JointCenteringCost``, its ``CollisionConstraint`` on a ``SceneGraphCollisionChecker`` of
the same plant, and its ``JointVelocityLimitConstraint`` at 0.4 rad/s. Its commanded velocities
are integrated every period and the integrated positions fed back. DiffIK runs at two safety
distances: 1 cm, and MoBeE's field margin (equal clearance).

Per controller: the tasks whose palm came within 2 cm of the goal's palm position by 5 s and by
the horizon, the median time to reach, the median final error, the worst clearance (signed
distance of the robot's solids to the obstacles, and to themselves), the control periods in
which solids penetrated, the tasks that broke a joint-space constraint (MoBeE's clauses, or the
joint limits), and the wall time of the controller's own step (median and 95th percentile).

Run: ``mobee-drake bench reactive [--tasks 20] [--seed 0] [--horizon 15] [--controllers ...]
[--mobee-preset defaults] [--detail] [--plot FILE.png]``.
"""

from collections.abc import Callable
import contextlib
import dataclasses as dc
import logging
import math
import os
import sys
import time

from matplotlib.ticker import MaxNLocator
import numpy as np
from pydrake.common import Parallelism
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.inverse_kinematics import DifferentialInverseKinematicsSystem
from pydrake.multibody.math import SpatialVelocity
from pydrake.multibody.tree import FixedOffsetFrame
from pydrake.planning import DofMask, JointLimits, RobotDiagramBuilder, SceneGraphCollisionChecker
from pydrake.systems.framework import BusValue

from mobee_drake.experiments.arguments import CommandParser, NonNegativeInt, PositiveFloat
from mobee_drake.experiments.bench_forces import BuildPosedScene
from mobee_drake.experiments.plots import Legend, SaveFigure, plt
from mobee_drake.mobee.flow import FlowParams
from mobee_drake.mobee.params import Dissertation, MobeeParams
from mobee_drake.resources import ResolveModelFile
from mobee_drake.robots.controlled_robot import ControlledRobot
from mobee_drake.robots.icub import (
    RIGHT_ARM_JOINTS,
    TORSO_JOINTS,
    IcubConfig,
)
from mobee_drake.robots.overlay import LoadOverlay
from mobee_drake.robots.scenario_robot import AddScenarioRobot
from mobee_drake.scenario import BuildScenario, LoadScenario, Scenario
from mobee_drake.station.attractors import FixedAttractor, MarkerGoal
from mobee_drake.station.config import DataLog, Kinematic
from mobee_drake.station.safety import SELF
from mobee_drake.station.world_events import MakeSimulator
from mobee_drake.world.live_world import LiveWorld
from mobee_drake.world.objects import Box, SceneObject, Sphere

# The control period of both controllers (s): the shipped scenarios' time step.
PERIOD = 0.01
# Reached: the palm within this distance of the goal's palm position (m); counted by EARLY (s)
# and by the horizon.
REACHED = 0.02
EARLY = 5.0
HORIZON = 15.0
# DiffIK's joint speed limit (rad/s).
SPEED_LIMIT = 0.4
# DiffIK's clamp on the palm's desired speed (m/s per axis) at SPEED_LIMIT.
PALM_SPEED = 0.3
# The gain of MoBeE's palm goal (a MarkerGoal), when it is given the palm's target.
PALM_GOAL_GAIN = 200.0
# MoBeE's speed cap with its default constants (spring maximum / damping, rad/s), at which DiffIK
# runs too for a comparison at equal speed.
MOBEE_SPEED_CAP = MobeeParams().spring_squash.m / MobeeParams().damping
# DiffIK's collision constraint ignores pairs farther apart than this (m).
INFLUENCE_DISTANCE = 0.10
# The clearance of the robot's solids to every obstacle at the start and at the goal (m), and
# the diameters of the balls (m).
CLEAR = 0.05
BALL_DIAMETER = (0.05, 0.10)
# A shelf: a board of this size (m), its underside this far above the ball's top (m).
SHELF_SIZE = (0.25, 0.25, 0.02)
SHELF_GAP = (0.05, 0.08)
# The marker that reaches, and the joints whose goal angles are drawn.
PALM = "r_palm"
GOAL_JOINTS = TORSO_JOINTS + RIGHT_ARM_JOINTS
# The left arm raised across the chest (behind_arm tasks): the ranges its joints are drawn from
# (deg), the others at home.
LEFT_ARM_ACROSS_DEG = {
    "l_shoulder_pitch": (-75.0, -30.0),
    "l_shoulder_roll": (10.0, 40.0),
    "l_shoulder_yaw": (20.0, 80.0),
    "l_elbow": (40.0, 100.0),
}
LEFT_ARM_PARTS = ("l_shoulder", "l_upper_arm", "l_elbow", "l_forearm", "l_hand")
# The shortest straight palm path (m) that leaves room for the obstacles of each kind, CLEAR of
# the hand at both ends (a quick test before the geometric ones).
MIN_PATH = {"ball": 0.2, "two_balls": 0.35, "shelf": 0.2}
# Goals drawn for one random task before giving up, and placements of its obstacles per goal.
MAX_GOALS, PLACEMENTS = 20_000, 20
# The random tasks' kinds, in turn (task i is KINDS[i % len(KINDS)]), and the shipped task.
KINDS = ("ball", "two_balls", "ball", "shelf", "behind_arm")
SHIPPED = "reach_around_ball"
# Signed distances are queried up to this distance (m): a clearance never below it is shown as
# at least this.
QUERY_DISTANCE = 0.25
# A joint limit or a clause is broken when a posture is beyond it by more than this (rad).
LIMIT_TOLERANCE = 1e-9


# ----------------------------------------------------------------------------------------------
# Tasks.


@dc.dataclass
class ReachTask:
    """One reach: from ``start`` to ``goal`` (MoBeE's joint order, rad) among ``objects``."""

    name: str
    kind: str
    joints: list[str]
    start: np.ndarray
    goal: np.ndarray
    objects: list[SceneObject]
    start_palm: np.ndarray  # the right palm's position at the start and at the goal (world, m)
    goal_palm: np.ndarray

    def Robot(self) -> IcubConfig:
        """The iCub, its home posture (where a run starts) the task's start."""
        return IcubConfig(
            home_deg={j: math.degrees(a) for j, a in zip(self.joints, self.start, strict=True)}
        )

    def GoalDegrees(self) -> dict[str, float]:
        return {j: math.degrees(a) for j, a in zip(self.joints, self.goal, strict=True)}


class TaskScene:
    """The iCub with MoBeE's overlay, posed by ``SetPositions`` (no simulator), with a task's
    objects added to its context: palm positions, signed distances and MoBeE's constraints, for
    drawing tasks and for measuring runs."""

    def __init__(self):
        self.scene = BuildPosedScene(IcubConfig(), [])
        self.mobee = self.scene.mobee
        self.joints = self.mobee.joints
        self.context, self._plant_context, self._mobee_context = self.scene.Contexts()
        self._order = self.scene.PositionOrder()
        self._x = self.scene.plant.GetPositions(self._plant_context)
        self._palm = self.mobee.marker_index(PALM)
        self._markers = self.mobee.GetOutputPort("marker_positions")
        self._pairs = self.mobee.GetOutputPort("field_pairs")
        self._query = self.mobee.GetInputPort("geometry_query")
        self._objects: list[str] = []

    def SetObjects(self, objects: list[SceneObject]) -> None:
        """Replaces the objects of the previous task (or draw) by ``objects``."""
        for name in self._objects:
            self.scene.world.Remove(self.context, name)
        for obj in objects:
            self.scene.world.Add(self.context, obj)
        self._objects = [obj.name for obj in objects]

    def Pose(self, q: np.ndarray) -> None:
        self._x[self._order] = q
        self.scene.plant.SetPositions(self._plant_context, self._x)

    def Palm(self) -> np.ndarray:
        return self._markers.Eval(self._mobee_context)[3 * self._palm : 3 * self._palm + 3].copy()

    def InsideFields(self) -> int:
        """How many pairs are inside MoBeE's fields (0: MoBeE's collision force is zero)."""
        return len(self._pairs.Eval(self._mobee_context))

    def Clearances(self, within: float = QUERY_DISTANCE) -> dict[str, float]:
        """The least signed distance (m) of the robot's solids to each object and to themselves
        (``SELF``), among the pairs closer than ``within`` (absent: none closer)."""
        query = self._query.Eval(self._mobee_context)
        inspector = query.inspector()
        world = inspector.world_frame_id()
        closest: dict[str, float] = {}
        for pair in query.ComputeSignedDistancePairwiseClosestPoints(within):
            a_robot = inspector.GetFrameId(pair.id_A) != world
            b_robot = inspector.GetFrameId(pair.id_B) != world
            if a_robot and b_robot:
                name = SELF
            elif a_robot or b_robot:
                name = inspector.GetName(pair.id_B if a_robot else pair.id_A)
            else:
                continue  # two objects
            closest[name] = min(closest.get(name, np.inf), pair.distance)
        return closest

    def PointClearance(self, point: np.ndarray) -> float:
        """The least signed distance (m) of ``point`` (world) to the robot's solids (up to
        QUERY_DISTANCE; the scene without objects)."""
        query = self._query.Eval(self._mobee_context)
        distances = [d.distance for d in query.ComputeSignedDistanceToPoint(point, QUERY_DISTANCE)]
        return min(distances, default=QUERY_DISTANCE)

    def LeftArmDistance(self, points: np.ndarray) -> float:
        """The least signed distance (m) of ``points`` (world) to the left arm's solids."""
        query = self._query.Eval(self._mobee_context)
        inspector = query.inspector()
        least = np.inf
        for p in points:
            for d in query.ComputeSignedDistanceToPoint(p, QUERY_DISTANCE):
                if inspector.GetName(d.id_G).rsplit("::", 1)[-1] in LEFT_ARM_PARTS:
                    least = min(least, d.distance)
        return least

    def RightLeftClearance(self, within: float = QUERY_DISTANCE) -> float:
        """The least signed distance (m) between the right arm's and the left arm's solids,
        among the pairs closer than ``within`` (inf: none closer)."""
        query = self._query.Eval(self._mobee_context)
        inspector = query.inspector()
        least = np.inf
        for pair in query.ComputeSignedDistancePairwiseClosestPoints(within):
            sides = {inspector.GetName(g).rsplit("::", 1)[-1][:2] for g in (pair.id_A, pair.id_B)}
            if sides == {"r_", "l_"}:
                least = min(least, pair.distance)
        return least


def DrawGoal(
    rng: np.random.Generator,
    scene: TaskScene,
    start: np.ndarray,
    joints: tuple[str, ...],
    params: MobeeParams,
) -> np.ndarray:
    """A goal posture: ``joints`` drawn uniformly within their limits less MoBeE's limit band,
    the others at ``start``; accepted once no clause of MoBeE's constraints is near switching on
    and no pair of solids is inside MoBeE's fields (so that the goal is an equilibrium of MoBeE's
    field-free dynamics and keeps the robot's joint-space constraints)."""
    lower, upper = scene.mobee.position_limits
    index = [scene.joints.index(j) for j in joints]
    low, high = lower[index] + params.limit_delta, upper[index] - params.limit_delta
    for _ in range(MAX_GOALS):
        goal = start.copy()
        goal[index] = rng.uniform(low, high)
        if scene.mobee.clauses.ActiveClauses(goal, params.constraint_delta).any():
            continue
        scene.Pose(goal)
        if scene.InsideFields() == 0:
            return goal
    raise RuntimeError(f"no goal posture found in {MAX_GOALS} draws")


def _Ball(name: str, center: np.ndarray, diameter: float) -> SceneObject:
    return SceneObject(name=name, shape=Sphere(radius=diameter / 2), position=center.tolist())


def _Clear(scene: TaskScene, objects: list[SceneObject], postures) -> bool:
    """Whether the robot's solids are at least CLEAR from every object at each posture: balls
    by their centres' distances (cheap, no geometry added), then the other objects added."""
    scene.SetObjects([])
    balls = [obj for obj in objects if isinstance(obj.shape, Sphere)]
    others = [obj for obj in objects if not isinstance(obj.shape, Sphere)]
    for q in postures:
        scene.Pose(q)
        for ball in balls:
            if scene.PointClearance(np.array(ball.position)) - ball.shape.radius < CLEAR:
                return False
    if others:
        scene.SetObjects(others)
        names = [obj.name for obj in others]
        for q in postures:
            scene.Pose(q)
            if any(name in scene.Clearances(within=CLEAR) for name in names):
                return False
    return True


def _PlaceObstacles(
    rng: np.random.Generator, scene: TaskScene, task: ReachTask
) -> ReachTask | None:
    """``task`` with obstacles of its kind on its straight palm path (None: a draw whose
    obstacles are not CLEAR of the robot at the start and at the goal)."""
    p0, p1 = task.start_palm, task.goal_palm
    length, rise = np.linalg.norm(p1 - p0), abs(p1[2] - p0[2])
    if length < MIN_PATH[task.kind] or (task.kind == "shelf" and rise > 0.5 * length):
        return None  # (too short for obstacles CLEAR of both ends; a shelf across the way)

    def OnPath(low: float, high: float) -> tuple[np.ndarray, float]:
        return p0 + rng.uniform(low, high) * (p1 - p0), rng.uniform(*BALL_DIAMETER)

    if task.kind == "ball":
        center, diameter = OnPath(0.2, 0.8)
        objects = [_Ball("ball", center, diameter)]
    elif task.kind == "two_balls":
        (c1, d1), (c2, d2) = OnPath(0.2, 0.45), OnPath(0.55, 0.8)
        if np.linalg.norm(c2 - c1) < (d1 + d2) / 2:
            return None
        objects = [_Ball("ball", c1, d1), _Ball("ball2", c2, d2)]
    elif task.kind == "shelf":
        center, diameter = OnPath(0.3, 0.7)
        height = diameter / 2 + rng.uniform(*SHELF_GAP) + SHELF_SIZE[2] / 2
        shelf = SceneObject(
            name="shelf",
            shape=Box(size=list(SHELF_SIZE)),
            position=(center + [0.0, 0.0, height]).tolist(),
        )
        objects = [_Ball("ball", center, diameter), shelf]
    else:
        raise ValueError(f"unknown task kind '{task.kind}'")
    if not _Clear(scene, objects, (task.start, task.goal)):
        return None
    return dc.replace(task, objects=objects)


def _LeftArmAcross(
    rng: np.random.Generator, scene: TaskScene, task: ReachTask, params: MobeeParams
) -> ReachTask | None:
    """``task`` with the left arm drawn across the right palm's straight path (within its ranges
    and out of MoBeE's limit band), held there from start to goal (None: a draw that misses the
    path, breaks a constraint, puts a pair inside MoBeE's fields, or comes closer than CLEAR to
    the right arm at the start or the goal)."""
    index = [scene.joints.index(j) for j in LEFT_ARM_ACROSS_DEG]
    low, high = np.radians(list(LEFT_ARM_ACROSS_DEG.values())).T
    lower, upper = scene.mobee.position_limits
    low = np.maximum(low, lower[index] + params.limit_delta)  # (out of the limits' band)
    high = np.minimum(high, upper[index] - params.limit_delta)
    start, goal = task.start.copy(), task.goal.copy()
    start[index] = goal[index] = rng.uniform(low, high)
    for q in (goal, start):  # (the start last: the path is checked there)
        if scene.mobee.clauses.ActiveClauses(q, params.constraint_delta).any():
            return None
        scene.Pose(q)
        if scene.InsideFields() or scene.RightLeftClearance(within=CLEAR) < CLEAR:
            return None
    path = task.start_palm + np.linspace(0.2, 0.8, 16)[:, None] * (task.goal_palm - task.start_palm)
    if scene.LeftArmDistance(path) >= 0.0:
        return None
    return _Task(scene, task.name, task.kind, start, goal, [])


def _Task(scene: TaskScene, name: str, kind: str, start, goal, objects) -> ReachTask:
    scene.Pose(start)
    start_palm = scene.Palm()
    scene.Pose(goal)
    return ReachTask(name, kind, scene.joints, start, goal, objects, start_palm, scene.Palm())


def RandomTask(
    index: int, seed: int, scene: TaskScene, params: MobeeParams | None = None
) -> ReachTask:
    """Random task ``index`` of ``seed`` (its own generator: the same task whatever the count),
    of kind ``KINDS[index % len(KINDS)]``: a goal drawn by :func:`DrawGoal` (the torso and the
    right arm; the right arm only behind the left arm, so that the left arm stays where it was
    drawn), then up to PLACEMENTS draws of its obstacles."""
    params = params or MobeeParams()
    rng = np.random.default_rng([seed, index])
    kind = KINDS[index % len(KINDS)]
    home = scene.mobee.home
    joints = RIGHT_ARM_JOINTS if kind == "behind_arm" else GOAL_JOINTS
    for _ in range(MAX_GOALS):
        scene.SetObjects([])
        goal = DrawGoal(rng, scene, home, joints, params)
        task = _Task(scene, f"random {index}", kind, home, goal, [])
        for _ in range(PLACEMENTS):
            if kind == "behind_arm":
                placed = _LeftArmAcross(rng, scene, task, params)
            else:
                placed = _PlaceObstacles(rng, scene, task)
            if placed is not None:
                return placed
    raise RuntimeError(f"no {kind} task found in {MAX_GOALS} goals (seed {seed}, task {index})")


def ShippedTask(scene: TaskScene) -> ReachTask:
    """The shipped ``reach_around_ball``: its objects, from home to its attractor."""
    scenario = LoadScenario(SHIPPED)
    goal = scene.mobee.home
    for joint, value in scenario.attractor.joints_deg.items():
        goal[scene.joints.index(joint)] = math.radians(value)
    return _Task(scene, SHIPPED, "shipped", scene.mobee.home, goal, list(scenario.objects))


def MakeTasks(count: int, seed: int, scene: TaskScene, *, shipped: bool = True) -> list[ReachTask]:
    """``count`` random tasks of ``seed``, after the shipped one (with ``shipped``)."""
    tasks = [ShippedTask(scene)] if shipped else []
    return tasks + [RandomTask(i, seed, scene) for i in range(count)]


# ----------------------------------------------------------------------------------------------
# Controllers: each runs a task for a horizon from its start and returns the trajectory.


@dc.dataclass
class Trajectory:
    """The joint positions every period from the start (steps + 1 rows, MoBeE's order), the wall
    time (s) of each control step of the controller alone, and the periods in which the
    controller gave up (DiffIK: its QP failed and it commanded zero velocity)."""

    q: np.ndarray
    step_seconds: np.ndarray
    failed_steps: int = 0


@dc.dataclass
class ReactiveController:
    """A controller under benchmark: its label and ``run(task, horizon) -> Trajectory``."""

    label: str
    run: Callable[[ReachTask, float], Trajectory]


# MoBeE's parameter sets under benchmark, by name (later presets join here).
MOBEE_PRESETS: dict[str, Callable[[], MobeeParams]] = {
    "defaults": MobeeParams,
    "dissertation": Dissertation,
    # The defaults without the obstacle-aware flow (what the flow adds).
    "defaults_no_flow": lambda: MobeeParams(flow=FlowParams(enabled=False)),
}


def MobeeController(
    params: MobeeParams, label: str = "MoBeE", palm_goal_gain: float = 0.0
) -> ReactiveController:
    """MoBeE with ``params``, moving the kinematic robot of the task's station (its virtual
    dynamics, eq. 5.7, integrated every period) towards the goal posture as its attractor, and
    with ``palm_goal_gain`` > 0 also pulling the palm to the goal's palm position (a
    :class:`MarkerGoal`, eq. 5.10: the target DiffIK is given).

    A step's cost is the evaluation of MoBeE's total force (forward kinematics, SceneGraph's
    signed-distance query, every term and the safety barrier), which the station's integration
    then reads from the cache; the integration itself (a few us) is not counted.
    """

    def Run(task: ReachTask, horizon: float) -> Trajectory:
        scenario = Scenario(
            robot=task.Robot(),
            objects=list(task.objects),
            mobee=params,
            mover=Kinematic(),
            time_step=PERIOD,
            attractor=FixedAttractor(
                joints_deg=task.GoalDegrees(),
                marker_goals=[
                    MarkerGoal(marker="r_palm", position=list(task.goal_palm), gain=palm_goal_gain)
                ]
                if palm_goal_gain > 0
                else [],
            ),
            duration=horizon,
            data_log=DataLog(enabled=False),
        )
        station = BuildScenario(scenario)
        simulator = MakeSimulator(station)
        simulator.Initialize()
        context = simulator.get_mutable_context()
        total = station.mobee.GetOutputPort("total")
        mobee_context = station.mobee.GetMyContextFromRoot(context)
        n, steps = len(task.joints), round(horizon / PERIOD)
        q, seconds = np.empty((steps + 1, n)), np.empty(steps)
        q[0] = station.robot_state.Eval(context)[:n]
        for k in range(steps):
            begin = time.perf_counter()
            total.Eval(mobee_context)
            seconds[k] = time.perf_counter() - begin
            simulator.AdvanceTo((k + 1) * PERIOD)
            q[k + 1] = station.robot_state.Eval(context)[:n]
        return Trajectory(q, seconds)

    return ReactiveController(label, Run)


@contextlib.contextmanager
def _Quiet():
    """Drake's log at errors only (DiffIK warns at every period its QP fails, with the QP's
    violated constraints) and the process's standard output closed to C code (OSQP prints
    "Polishing not needed" at some solves)."""
    logger = logging.getLogger("drake")
    level = logger.level
    logger.setLevel(logging.ERROR)
    sys.stdout.flush()
    saved, devnull = os.dup(1), os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    try:
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)
        logger.setLevel(level)


def DiffIkController(
    safety_distance: float, label: str, speed_limit: float = SPEED_LIMIT
) -> ReactiveController:
    """Drake's ``DifferentialInverseKinematicsSystem``, all 20 joints active.

    Its ``SceneGraphCollisionChecker`` sees the task's robot and objects in a ``RobotDiagram``
    built as the station builds them (the same overlay primitives, filters and objects). The
    recipe:

    - ``LeastSquaresCost`` on the palm's translation (rotation masked out; weight 100, as Drake
      advises over the centering cost), the goal's palm position as the desired pose and
      ``K_VX`` = 1, the desired palm speed clamped to 0.3 m/s per axis;
    - ``JointCenteringCost`` (gain 1/s) towards the goal posture (the nominal posture);
    - ``CollisionConstraint`` at ``safety_distance`` (pairs within ``INFLUENCE_DISTANCE``);
    - ``JointVelocityLimitConstraint`` at ``speed_limit`` (rad/s; Drake's default margins), the
      palm's speed clamp scaled with it (0.3 m/s at ``SPEED_LIMIT``).

    The commanded velocity is integrated every period (explicit Euler) and the positions fed
    back. A step's cost is the evaluation of the commanded velocity (the checker's distances,
    Jacobians and the QP).
    """

    def Run(task: ReachTask, horizon: float) -> Trajectory:
        builder = RobotDiagramBuilder(time_step=0.0)
        plant, scene_graph = builder.plant(), builder.scene_graph()
        overlay, joints = AddScenarioRobot(plant, scene_graph, task.Robot())
        world = LiveWorld(plant, scene_graph)
        for obj in task.objects:
            world.Register(obj)
        (marker,) = [m for m in overlay.markers if m.name == PALM]
        palm = plant.AddFrame(
            FixedOffsetFrame(
                f"{PALM}_marker",
                plant.GetBodyByName(marker.body_name, overlay.instance).body_frame(),
                RigidTransform(marker.p_BM),
            )
        )
        plant.Finalize()
        robot = ControlledRobot.Of(plant, overlay, joints, "DiffIK")
        diagram = builder.Build()
        with _Quiet():
            checker = SceneGraphCollisionChecker(
                model=diagram,
                robot_model_instances=[overlay.instance],
                edge_step_size=0.05,
                env_collision_padding=0.0,
                self_collision_padding=0.0,
                implicit_context_parallelism=Parallelism(1),
            )
        system = _DiffIkSystem(
            plant, checker, palm.scoped_name().to_string(), safety_distance, speed_limit
        )
        context = system.CreateDefaultContext()
        positions = plant.GetPositions(plant.CreateDefaultContext())
        goal_positions = robot.PlantPositions(task.goal, positions.copy())
        plant_context = plant.CreateDefaultContext()
        plant.SetPositions(plant_context, goal_positions)
        desired = BusValue()
        desired.Set(palm.scoped_name().to_string(), AbstractValue.Make(palm.CalcPoseInWorld(
            plant_context
        )))  # fmt: skip
        system.get_input_port_desired_cartesian_poses().FixValue(context, desired)
        system.get_input_port_nominal_posture().FixValue(context, goal_positions)
        position_port = system.get_input_port_position()
        command = system.get_output_port_commanded_velocity()
        n, steps = len(task.joints), round(horizon / PERIOD)
        q, seconds = np.empty((steps + 1, n)), np.empty(steps)
        q[0] = task.start
        failed = 0
        with _Quiet():
            for k in range(steps):
                position_port.FixValue(context, robot.PlantPositions(q[k], positions))
                begin = time.perf_counter()
                v = command.Eval(context)
                seconds[k] = time.perf_counter() - begin
                failed += not v.any()
                q[k + 1] = q[k] + PERIOD * v[robot.v_index]
        return Trajectory(q, seconds, failed)

    return ReactiveController(label, Run)


def _DiffIkSystem(plant, checker, frame: str, safety_distance: float, speed_limit: float):
    """Drake's DiffIK with the recipe of :func:`DiffIkController`."""
    System = DifferentialInverseKinematicsSystem
    translation = {frame: np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])}
    recipe = System.Recipe()
    recipe.AddIngredient(
        System.LeastSquaresCost(
            System.LeastSquaresCost.Config(
                cartesian_qp_weight=100.0, cartesian_axis_masks=translation
            )
        )
    )
    recipe.AddIngredient(
        System.JointCenteringCost(
            System.JointCenteringCost.Config(posture_gain=1.0, cartesian_axis_masks=translation)
        )
    )
    recipe.AddIngredient(
        System.CollisionConstraint(
            System.CollisionConstraint.Config(
                safety_distance=safety_distance, influence_distance=INFLUENCE_DISTANCE
            )
        )
    )
    limits = JointLimits(plant)
    n = plant.num_velocities()
    recipe.AddIngredient(
        System.JointVelocityLimitConstraint(
            System.JointVelocityLimitConstraint.Config(),
            JointLimits(
                limits.position_lower(),
                limits.position_upper(),
                np.full(n, -speed_limit),
                np.full(n, speed_limit),
                limits.acceleration_lower(),
                limits.acceleration_upper(),
            ),
        )
    )
    return System(
        recipe=recipe,
        task_frame="world",
        collision_checker=checker,
        active_dof=DofMask(n, True),
        time_step=PERIOD,
        K_VX=1.0,
        Vd_TG_limit=SpatialVelocity(
            w=np.full(3, 1.0), v=np.full(3, PALM_SPEED * speed_limit / SPEED_LIMIT)
        ),
    )


def FieldMargin() -> float:
    """MoBeE's default field margin of the iCub's overlay (m): DiffIK's safety distance at
    equal clearance (the forearms' and the head's fields are 1 cm wider)."""
    return LoadOverlay(ResolveModelFile(IcubConfig().overlay)).default_field


CONTROLLERS = [
    "mobee",
    "mobee_posture",
    "mobee_dissertation",
    "diffik_1cm",
    "diffik_field",
    "diffik_fast",
]


def Controllers(preset: str = "defaults") -> dict[str, ReactiveController]:
    """The controllers under benchmark, by name: MoBeE with the named preset, given the goal
    posture and the palm's target (what DiffIK is given) or the posture only; MoBeE with the
    dissertation's constants; DiffIK at a 1 cm safety distance and at MoBeE's field margin, and
    at 1 cm with MoBeE's speed cap."""
    field = FieldMargin()
    params = MOBEE_PRESETS[preset]
    return {
        "mobee": MobeeController(params(), f"MoBeE ({preset}), palm goal", PALM_GOAL_GAIN),
        "mobee_posture": MobeeController(params(), f"MoBeE ({preset}), posture only"),
        "mobee_dissertation": MobeeController(Dissertation(), "MoBeE (dissertation)"),
        "diffik_1cm": DiffIkController(0.01, "DiffIK, 1 cm"),
        "diffik_field": DiffIkController(field, f"DiffIK, {100 * field:g} cm (MoBeE's field)"),
        "diffik_fast": DiffIkController(
            0.01, f"DiffIK, 1 cm, {MOBEE_SPEED_CAP:g} rad/s", speed_limit=MOBEE_SPEED_CAP
        ),
    }


# ----------------------------------------------------------------------------------------------
# Measurements.


@dc.dataclass
class RunResult:
    """One controller on one task (distances in m, times in s, angles in rad)."""

    controller: str
    task: str
    kind: str
    # The first time the palm was within REACHED of the goal's palm position (None: never).
    reached_at: float | None
    final_error: float
    # The least signed distance of the robot's solids to the obstacles and to themselves over
    # the run (QUERY_DISTANCE when never closer).
    obstacle_clearance: float
    self_clearance: float
    # Periods in which two solids penetrated (a signed distance < 0).
    penetrating_steps: int
    # Periods that broke a clause of MoBeE's constraints or a joint limit, and the worst depth.
    violating_steps: int
    worst_violation: float
    peak_speed: float  # rad/s, the fastest joint
    step_seconds: np.ndarray = dc.field(repr=False)
    failed_steps: int = 0
    palm_error: np.ndarray = dc.field(default_factory=lambda: np.zeros(0), repr=False)


def MeasureRun(
    scene: TaskScene, task: ReachTask, trajectory: Trajectory, controller: str
) -> RunResult:
    """Replays ``trajectory`` on ``scene`` with the task's objects and measures it."""
    scene.SetObjects(task.objects)
    lower, upper = scene.mobee.position_limits
    clauses = scene.mobee.clauses
    errors = np.empty(len(trajectory.q))
    obstacle = clearance_self = QUERY_DISTANCE
    penetrating = violating = 0
    worst = 0.0
    for k, q in enumerate(trajectory.q):
        scene.Pose(q)
        errors[k] = np.linalg.norm(scene.Palm() - task.goal_palm)
        closest = scene.Clearances()
        here_self = closest.pop(SELF, QUERY_DISTANCE)
        here_obstacle = min(closest.values(), default=QUERY_DISTANCE)
        obstacle, clearance_self = min(obstacle, here_obstacle), min(clearance_self, here_self)
        penetrating += min(here_obstacle, here_self) < 0
        depth = max(
            clauses.Violation(q),
            float(np.max(lower - q, initial=0.0)),
            float(np.max(q - upper, initial=0.0)),
        )
        if depth > LIMIT_TOLERANCE:
            violating += 1
            worst = max(worst, depth)
    inside = np.flatnonzero(errors < REACHED)
    speeds = np.abs(np.diff(trajectory.q, axis=0)) / PERIOD
    return RunResult(
        controller=controller,
        task=task.name,
        kind=task.kind,
        reached_at=float(inside[0] * PERIOD) if inside.size else None,
        final_error=float(errors[-1]),
        obstacle_clearance=float(obstacle),
        self_clearance=float(clearance_self),
        penetrating_steps=int(penetrating),
        violating_steps=violating,
        worst_violation=worst,
        peak_speed=float(speeds.max(initial=0.0)),
        step_seconds=trajectory.step_seconds,
        failed_steps=trajectory.failed_steps,
        palm_error=errors,
    )


@dc.dataclass
class ControllerSummary:
    """One controller over the task set (distances in m, times in s, angles in rad)."""

    label: str
    tasks: int
    reached_early: int
    reached: int
    median_time: float | None  # over the tasks reached by the horizon
    median_final_error: float
    obstacle_clearance: float
    self_clearance: float
    penetrating_steps: int
    penetrating_tasks: int
    violating_tasks: int
    worst_violation: float
    step_median: float
    step_p95: float
    peak_speed: float
    failed_steps: int


def Summarize(label: str, results: list[RunResult], early: float = EARLY) -> ControllerSummary:
    times = [r.reached_at for r in results if r.reached_at is not None]
    steps = np.concatenate([r.step_seconds for r in results])
    return ControllerSummary(
        label=label,
        tasks=len(results),
        reached_early=sum(t <= early for t in times),
        reached=len(times),
        median_time=float(np.median(times)) if times else None,
        median_final_error=float(np.median([r.final_error for r in results])),
        obstacle_clearance=min(r.obstacle_clearance for r in results),
        self_clearance=min(r.self_clearance for r in results),
        penetrating_steps=sum(r.penetrating_steps for r in results),
        penetrating_tasks=sum(r.penetrating_steps > 0 for r in results),
        violating_tasks=sum(r.violating_steps > 0 for r in results),
        worst_violation=max(r.worst_violation for r in results),
        step_median=float(np.median(steps)),
        step_p95=float(np.percentile(steps, 95)),
        peak_speed=max(r.peak_speed for r in results),
        failed_steps=sum(r.failed_steps for r in results),
    )


def RunBenchmark(
    tasks: list[ReachTask],
    controllers: dict[str, ReactiveController],
    horizon: float,
    scene: TaskScene,
    progress: Callable[[str], None] | None = None,
) -> dict[str, list[RunResult]]:
    """Every controller on every task: the results by controller name."""
    results = {name: [] for name in controllers}
    for task in tasks:
        for name, controller in controllers.items():
            trajectory = controller.run(task, horizon)
            results[name].append(MeasureRun(scene, task, trajectory, name))
            if progress:
                progress(f"{task.name} ({task.kind}), {name}: {_Reached(results[name][-1])}")
    return results


def _Reached(result: RunResult) -> str:
    if result.reached_at is None:
        return f"not reached, {100 * result.final_error:.1f} cm short"
    return f"reached at {result.reached_at:.2f} s"


# ----------------------------------------------------------------------------------------------
# Reports.


def _Cm(value: float) -> str:
    shown = f"{100 * value:+.1f}"
    return f">= {shown}" if value >= QUERY_DISTANCE else shown


def Table(summaries: list[ControllerSummary], horizon: float, early: float = EARLY) -> str:
    """The markdown table of the controllers' summaries."""
    lines = [
        f"| controller | reached (< {100 * REACHED:g} cm) by {early:g} s | by {horizon:g} s "
        "| median time to reach (s) | median final error (cm) | worst clearance to obstacles "
        "(cm) | worst self clearance (cm) | penetrating periods (tasks) | constraint violations: "
        "tasks (worst, deg) | step cost median / p95 (ms) | peak joint speed (rad/s) |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for s in summaries:
        time_to_reach = "-" if s.median_time is None else f"{s.median_time:.2f}"
        lines.append(
            f"| {s.label} | {s.reached_early}/{s.tasks} | {s.reached}/{s.tasks} | "
            f"{time_to_reach} | {100 * s.median_final_error:.1f} | "
            f"{_Cm(s.obstacle_clearance)} | {_Cm(s.self_clearance)} | "
            f"{s.penetrating_steps} ({s.penetrating_tasks}) | "
            f"{s.violating_tasks} ({math.degrees(s.worst_violation):.1f}) | "
            f"{1000 * s.step_median:.2f} / {1000 * s.step_p95:.2f} | {s.peak_speed:.2f} |"
        )
    return "\n".join(lines)


def KindTable(
    results: dict[str, list[RunResult]],
    labels: dict[str, str],
    horizon: float,
    early: float = EARLY,
) -> str:
    """Per task kind: tasks reached by ``early`` / by the horizon, of the kind's tasks."""
    kinds = list(dict.fromkeys(r.kind for rows in results.values() for r in rows))
    lines = [
        f"| controller | {' | '.join(kinds)} |",
        "|---|" + "---:|" * len(kinds),
    ]
    for name, rows in results.items():
        cells = []
        for kind in kinds:
            mine = [r for r in rows if r.kind == kind]
            by_early = sum(r.reached_at is not None and r.reached_at <= early for r in mine)
            by_end = sum(r.reached_at is not None for r in mine)
            cells.append(f"{by_early} / {by_end} of {len(mine)}")
        lines.append(f"| {labels[name]} | {' | '.join(cells)} |")
    return f"Reached by {early:g} s / by {horizon:g} s, per kind of task:\n" + "\n".join(lines)


# (An empty reached_at_s: not reached; an empty obstacle_clearance_cm: no obstacle ever within
# QUERY_DISTANCE.)
DETAIL_COLUMNS = (
    "controller,task,kind,reached_at_s,final_error_cm,obstacle_clearance_cm,self_clearance_cm,"
    "penetrating_periods,violating_periods,worst_violation_deg,peak_speed_rad_s,"
    "step_median_ms,step_p95_ms,failed_periods"
)


def DetailRows(results: dict[str, list[RunResult]]) -> list[str]:
    """One CSV row per controller and task (DETAIL_COLUMNS)."""
    rows = []
    for name, mine in results.items():
        for r in mine:
            reached = "" if r.reached_at is None else f"{r.reached_at:.2f}"
            obstacle = (
                ""
                if r.obstacle_clearance >= QUERY_DISTANCE
                else f"{100 * r.obstacle_clearance:.2f}"
            )
            rows.append(
                f"{name},{r.task},{r.kind},{reached},{100 * r.final_error:.2f},"
                f"{obstacle},{100 * r.self_clearance:.2f},"
                f"{r.penetrating_steps},{r.violating_steps},"
                f"{math.degrees(r.worst_violation):.2f},{r.peak_speed:.3f},"
                f"{1000 * np.median(r.step_seconds):.3f},"
                f"{1000 * np.percentile(r.step_seconds, 95):.3f},{r.failed_steps}"
            )
    return rows


# The kinds as the figure's task axis names them.
SHORT_KINDS = {"ball": "ball", "two_balls": "2 balls", "shelf": "shelf", "behind_arm": "arm"}


def ReactiveFigure(
    results: dict[str, list[RunResult]],
    labels: dict[str, str],
    horizon: float,
    early: float = EARLY,
):
    """Three panels: tasks reached over time; the palm's distance to its goal over time
    (median and interquartile range over the tasks, below 1 mm shown at 1 mm); each task's time
    to reach."""
    figure = plt.figure(figsize=(13, 8.5))
    grid = figure.add_gridspec(2, 2)
    reached_axis, error_axis = figure.add_subplot(grid[0, 0]), figure.add_subplot(grid[0, 1])
    task_axis = figure.add_subplot(grid[1, :])
    count = len(results)
    for i, (name, rows) in enumerate(results.items()):
        colour, label = f"C{i}", labels[name]
        times = np.sort([r.reached_at for r in rows if r.reached_at is not None])
        reached_axis.step(
            np.concatenate([[0.0], times, [horizon]]),
            np.concatenate([[0], np.arange(1, len(times) + 1), [len(times)]]),
            where="post",
            color=colour,
            label=label,
        )
        errors = np.maximum(100 * np.array([r.palm_error for r in rows]), 0.1)
        t = PERIOD * np.arange(errors.shape[1])
        low, median, high = np.percentile(errors, [25, 50, 75], axis=0)
        error_axis.plot(t, median, color=colour, label=label)
        error_axis.fill_between(t, low, high, color=colour, alpha=0.15)
        x = np.arange(len(rows)) + (i - (count - 1) / 2) * 0.2
        reached = np.array([r.reached_at is not None for r in rows])
        y = np.array([horizon if r.reached_at is None else r.reached_at for r in rows])
        task_axis.plot(x[reached], y[reached], "o", color=colour, label=f"{label}, reached")
        task_axis.plot(x[~reached], y[~reached], "x", color=colour, label=f"{label}, not reached")
    reached_axis.axvline(early, color="grey", linestyle=":", label=f"{early:g} s")
    reached_axis.set(
        xlabel="time [s]",
        ylabel="tasks reached [count]",
        title=f"Tasks reached (palm within {100 * REACHED:g} cm)",
    )
    error_axis.axhline(100 * REACHED, color="grey", linestyle=":", label="reached")
    error_axis.set(
        xlabel="time [s]",
        ylabel="palm to goal [cm]",
        yscale="log",
        title="Palm to goal: median, quartiles",
    )
    first = next(iter(results.values()))
    names = [
        "S" if r.kind == "shipped" else f"{r.task.removeprefix('random ')}\n{SHORT_KINDS[r.kind]}"
        for r in first
    ]
    task_axis.set_xticks(np.arange(len(names)), names, fontsize="x-small")
    reached_axis.yaxis.set_major_locator(MaxNLocator(integer=True))
    task_axis.set(
        xlabel="task",
        ylabel="time to reach [s]",
        title=f"Time to reach per task (S: {SHIPPED}; x: not reached by {horizon:g} s)",
    )
    for axis in (reached_axis, error_axis, task_axis):
        Legend(axis)
    return figure


def main(argv=None) -> None:
    parser = CommandParser(prog="mobee-drake bench reactive", description=__doc__)
    parser.add_argument(
        "--tasks", type=NonNegativeInt, default=20, help="random tasks (after the shipped one)"
    )
    parser.add_argument("--seed", type=NonNegativeInt, default=0, help="the tasks' seed")
    parser.add_argument(
        "--horizon", type=PositiveFloat, default=HORIZON, help="simulated seconds per run"
    )
    parser.add_argument(
        "--controllers",
        nargs="+",
        choices=CONTROLLERS,
        default=CONTROLLERS,
        help="which controllers to run",
    )
    parser.add_argument(
        "--mobee-preset",
        choices=sorted(MOBEE_PRESETS),
        default="defaults",
        help="MoBeE's parameters",
    )
    parser.add_argument("--detail", action="store_true", help="print one CSV row per run")
    parser.add_argument("--plot", default="", help="save the figure to this PNG")
    parser.add_argument("--quiet", action="store_true", help="no line per run while running")
    args = parser.parse_args(argv)
    scene = TaskScene()
    tasks = MakeTasks(args.tasks, args.seed, scene)
    available = Controllers(args.mobee_preset)
    controllers = {name: available[name] for name in args.controllers}
    labels = {name: c.label for name, c in controllers.items()}
    begin = time.perf_counter()
    results = RunBenchmark(
        tasks,
        controllers,
        args.horizon,
        scene,
        progress=None if args.quiet else lambda line: print(line, flush=True),
    )
    wall = time.perf_counter() - begin
    early = min(EARLY, args.horizon)
    summaries = [Summarize(labels[name], rows, early) for name, rows in results.items()]
    print(
        f"\n{len(tasks)} tasks ({SHIPPED} and {args.tasks} random, seed {args.seed}), "
        f"{args.horizon:g} s each at {1000 * PERIOD:g} ms, in {wall:.0f} s:\n"
    )
    print(Table(summaries, args.horizon, early))
    print()
    print(KindTable(results, labels, args.horizon, early))
    if args.detail:
        print(f"\n{DETAIL_COLUMNS}")
        print("\n".join(DetailRows(results)))
    if args.plot:
        SaveFigure(ReactiveFigure(results, labels, args.horizon, early), args.plot, dpi=90)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
