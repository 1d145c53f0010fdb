"""The reach-past-obstacle tasks of the reactive benchmark
(:mod:`mobee_drake.experiments.bench_reactive`): seeded random tasks and the shipped one, and the
kinematic scene that poses them."""

import dataclasses as dc
import math

import numpy as np

from mobee_drake.experiments.bench_forces import BuildPosedScene
from mobee_drake.mobee.params import MobeeParams
from mobee_drake.robots.icub import (
    RIGHT_ARM_JOINTS,
    TORSO_JOINTS,
    IcubConfig,
)
from mobee_drake.scenario import LoadScenario
from mobee_drake.station.safety import SELF
from mobee_drake.world.objects import Box, SceneObject, Sphere

# The control period of both controllers (s): the shipped scenarios' time step.
PERIOD = 0.01
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
