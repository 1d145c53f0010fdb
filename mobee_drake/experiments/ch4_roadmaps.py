"""The demonstrations of adaptive roadmap planning (dissertation ch. 4.3.1-4.3.2) in simulation.

- **Roadmap from scratch**: the home pose and 20 random poses of the torso and right arm
  (10 joints; the others at home), each joined to its 10 nearest in joint space, no edge
  checked; the robot, under MoBeE 1.0, explores until every edge out of every vertex it can reach
  is known (a table in front of it, as in the motor babbling scenario). We add the home pose as
  the start vertex, since the robot has to begin somewhere. Two readings of the source are
  options (issue 34): ``vertex_sampling`` ``free`` (ours: the random poses are drawn among the
  valid ones with nothing inside MoBeE's fields, since a vertex the reflex forbids could never be
  reached) or ``uniform`` (the source's "20 random samples in the configuration space", checked
  for nothing); ``edges`` ``both-ways`` (ours) or ``out`` (the source's "connected to their 10
  nearest neighbors" read as each vertex's commands to its nearest). The source reports
  unreachable vertices and edges (Fig. 4.6); each run counts them, and the dead ends (reachable
  vertices with no feasible edge out).
- **Adaptive re-planning**: a small graph built on purpose around a ball in front of the right
  hand: poses A and B put the palm on either side of the ball, D and E above A and B; the edge
  A-B is the short way (the hand passes through the ball), A-D-E-B the long way over it. With the
  ball a ghost the planner takes A -> B; then the ball is made solid, and the way back, B -> A,
  makes the reflex fire: the edge is removed and the planner goes around, B -> E -> D -> A.

Run: ``mobee-drake experiment roadmaps [--seed S] [--meshcat]``; the readings' table over
several seeds: ``mobee-drake experiment roadmaps --scratch-table --seeds 0 1 2 [--doc FILE]``.
"""

import dataclasses as dc
import time

import numpy as np
from pydrake.geometry import StartMeshcat

from mobee_drake.experiments.arguments import CommandParser, NonNegativeInt
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.ngik.costs import CollisionCost, HomeCost, MarkerPositionCost
from mobee_drake.ngik.kinematic_model import KinematicModel
from mobee_drake.ngik.nes import NesConfig
from mobee_drake.ngik.solver import IkProblem, SolveNgik
from mobee_drake.roadmaps.adaptive_roadmap import (
    AdaptiveRoadmap,
    EdgeStatus,
    ExploreRoadmap,
    ReflexRobot,
)
from mobee_drake.robots.icub import RIGHT_ARM_JOINTS, TORSO_JOINTS, IcubConfig
from mobee_drake.scenario import BuildScenario, Scenario
from mobee_drake.station.config import DataLog, Reflex, Visualization
from mobee_drake.station.executor import StateActionAttractor
from mobee_drake.station.settling import ActionTiming
from mobee_drake.world.objects import Box, SceneObject, Sphere

TABLE = SceneObject(name="table", shape=Box(size=[0.5, 0.9, 0.04]), position=[-0.38, 0.0, -0.17])
BALL_CENTRE = np.array([-0.32, 0.2, -0.02])
BALL = SceneObject(name="ball", shape=Sphere(radius=0.05), position=list(BALL_CENTRE), role="ghost")
# Palm positions of A, B (either side of the ball) and D, E (above A and B).
SIDE, ABOVE = 0.17, 0.26
PALM_OFFSETS = np.array([[0, -SIDE, 0], [0, SIDE, 0], [0, -SIDE, ABOVE], [0, SIDE, ABOVE]])


def _ReflexRobot(objects: list[SceneObject], seed: int, meshcat) -> ReflexRobot:
    """The iCub under MoBeE 1.0 among ``objects``, its commands transitions of a state-action
    executor that end when the robot has settled (or after a minute)."""
    scenario = Scenario(
        robot=IcubConfig(),
        objects=objects,
        attractor=StateActionAttractor(timing=ActionTiming(timeout=60.0)),
        mover=Reflex(),
        time_step=0.02,
        random_seed=seed,
        visualization=Visualization(show_attractor=False),
        data_log=DataLog(enabled=False),  # (The experiment keeps its own data.)
    )
    return ReflexRobot(BuildScenario(scenario, meshcat))


DOC_TABLE = "roadmap-from-scratch"
VERTEX_SAMPLINGS = ("free", "uniform")
EDGE_READINGS = ("both-ways", "out")


@dc.dataclass
class ScratchResult:
    vertices: int
    edges: int
    feasible: int
    infeasible: int
    untried: int  # edges out of vertices the robot could never reach
    unreachable_vertices: int
    # Vertices (home excluded) that are invalid, colliding or inside MoBeE's fields.
    forbidden_vertices: int
    # Reachable vertices with no feasible edge out.
    dead_ends: int
    commands: int
    reflexes: int
    simulated_minutes: float
    wall_seconds: float


def RoadmapFromScratch(
    seed: int = 0,
    *,
    samples: int = 20,
    k: int = 10,
    vertex_sampling: str = "free",
    edges: str = "both-ways",
    meshcat=None,
) -> tuple[ScratchResult, AdaptiveRoadmap]:
    """Ch. 4.3.1 under the given readings (see the module's docstring)."""
    if vertex_sampling not in VERTEX_SAMPLINGS or edges not in EDGE_READINGS:
        raise ValueError(f"unknown reading: vertex_sampling {vertex_sampling!r}, edges {edges!r}")
    rng = np.random.default_rng(seed)
    robot = _ReflexRobot([TABLE], seed, meshcat)
    mobee = robot.station.mobee
    lower, upper = mobee.position_limits
    columns = [mobee.joint_index(j) for j in TORSO_JOINTS + RIGHT_ARM_JOINTS]
    model = KinematicModel(IcubConfig(), [TABLE], inside_fields=True)

    def Free(q: np.ndarray) -> bool:
        return model.IsValid(q) and not model.Evaluate(q).collision_pairs

    poses = [mobee.home]
    while len(poses) < samples + 1:
        q = mobee.home.copy()
        q[columns] = rng.uniform(lower[columns], upper[columns])
        if vertex_sampling == "uniform" or Free(q):
            poses.append(q)
    roadmap = AdaptiveRoadmap.KNearest(np.array(poses), k, both_ways=edges == "both-ways")
    began = time.perf_counter()
    record = ExploreRoadmap(roadmap, robot, 0, rng)
    wall = time.perf_counter() - began
    reachable = roadmap.Reachable(0)
    feasible = roadmap.edges[roadmap.status == EdgeStatus.FEASIBLE]
    return ScratchResult(
        vertices=len(poses),
        edges=len(roadmap.edges),
        feasible=int(np.sum(roadmap.status == EdgeStatus.FEASIBLE)),
        infeasible=int(np.sum(roadmap.status == EdgeStatus.INFEASIBLE)),
        untried=int(np.sum(roadmap.status == EdgeStatus.UNTRIED)),
        unreachable_vertices=int(np.sum(~reachable)),
        forbidden_vertices=sum(not Free(q) for q in poses[1:]),
        dead_ends=int(np.sum(reachable & ~np.isin(np.arange(len(poses)), feasible[:, 0]))),
        commands=record.commands,
        reflexes=record.reflexes,
        simulated_minutes=robot.context.get_time() / 60,
        wall_seconds=wall,
    ), roadmap


def BallPoses(seed: int = 0) -> np.ndarray:
    """Poses A, B, D, E of the torso and right arm (palm beside the ball, and above those
    points), found by NGIK with no pair inside MoBeE's fields, such that along the edge A-B the
    hand enters the ball's field and along A-D, D-E, E-B nothing does."""
    model = KinematicModel(IcubConfig(), [dc.replace(BALL, role="obstacle")], inside_fields=True)
    palm = model.MarkerIndex("r_palm")
    rng = np.random.default_rng(seed)
    poses = []
    for offset in PALM_OFFSETS:
        problem = IkProblem(
            model,
            [
                MarkerPositionCost(palm, BALL_CENTRE + offset),
                HomeCost(model.home, weight=0.05),
                CollisionCost(),
            ],
            joints=list(TORSO_JOINTS + RIGHT_ARM_JOINTS),
        )
        solution = SolveNgik(problem, model.home, 0.2, NesConfig(max_evaluations=6000), rng)
        if not solution.solved:
            raise RuntimeError(f"NGIK found no pose with the palm at {BALL_CENTRE + offset}")
        poses.append(solution.q)

    def Blocked(a, b) -> bool:
        return any(
            model.Evaluate((1 - s) * a + s * b).collision_pairs for s in np.linspace(0, 1, 41)
        )

    A, B, D, E = poses
    if not Blocked(A, B) or Blocked(A, D) or Blocked(D, E) or Blocked(E, B):
        raise RuntimeError("the ball poses do not make a short blocked way and a clear detour")
    return np.array(poses)


@dc.dataclass
class ReplanningResult:
    ghost_path: list[int]  # A -> B planned with the ball a ghost
    ghost_arrived: bool
    first_solid_path: list[int]  # B -> A planned before the ball was felt
    direct_arrived: bool  # whether the direct edge worked once the ball was solid
    replanned_path: list[int]  # B -> A after the edge was removed
    arrived_home: bool  # reached A along the re-planned path
    reflexes: int


HOME, A, B, D, E = range(5)


def AdaptiveReplanning(seed: int = 0, *, meshcat=None) -> ReplanningResult:
    poses = BallPoses(seed)
    robot = _ReflexRobot([BALL], seed, meshcat)
    edges = [(HOME, A), (A, B), (A, D), (D, E), (E, B)]
    edges += [(b, a) for a, b in edges]
    roadmap = AdaptiveRoadmap(np.vstack([robot.station.mobee.home, poses]), edges)
    reflexes = 0

    def Travel(path: list[int]) -> bool:
        nonlocal reflexes
        for a, b in zip(path[:-1], path[1:]):
            arrived = robot.Command(roadmap.poses[b])
            roadmap.Record(a, b, arrived)
            if not arrived:
                reflexes += 1
                return False
        return True

    if not Travel([HOME, A]):
        raise RuntimeError("the robot could not reach pose A from home")
    ghost_path = roadmap.Plan(A, B)
    ghost_arrived = Travel(ghost_path)
    robot.SetRole("ball", "obstacle")
    first = roadmap.Plan(B, A)
    direct = Travel(first)
    replanned = roadmap.Plan(B, A)
    arrived = Travel(replanned)
    return ReplanningResult(ghost_path, ghost_arrived, first, direct, replanned, arrived, reflexes)


def ScratchTable(seeds: list[int]) -> list[str]:
    """Markdown: ch. 4.3.1 under every reading, one row per reading and seed."""
    lines = [
        "| vertex sampling | edges | seed | directed edges | feasible | infeasible | never "
        "reachable | forbidden vertices | unreachable vertices | dead ends | commands | simulated "
        "min |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for sampling in VERTEX_SAMPLINGS:
        for edges in EDGE_READINGS:
            for seed in seeds:
                r, _ = RoadmapFromScratch(seed, vertex_sampling=sampling, edges=edges)
                lines.append(
                    f"| {sampling} | {edges} | {seed} | {r.edges} | {r.feasible} | "
                    f"{r.infeasible} | {r.untried} | {r.forbidden_vertices} | "
                    f"{r.unreachable_vertices} | {r.dead_ends} | {r.commands} | "
                    f"{r.simulated_minutes:.1f} |"
                )
                print(lines[-1], flush=True)
    return lines


def _Parser() -> CommandParser:
    parser = CommandParser(
        prog="mobee-drake experiment roadmaps",
        description=__doc__.split("\n")[0],
    )
    parser.add_argument(
        "--seed", type=NonNegativeInt, default=0, help="seed of the roadmap and its exploration"
    )
    parser.add_argument(
        "--vertex-sampling",
        choices=VERTEX_SAMPLINGS,
        default="free",
        help="ch. 4.3.1's vertices: free (valid, nothing inside MoBeE's fields) or uniform (the "
        "source's random samples, unchecked)",
    )
    parser.add_argument(
        "--edges",
        choices=EDGE_READINGS,
        default="both-ways",
        help="ch. 4.3.1's edges to the 10 nearest: both ways, or out of each vertex only",
    )
    parser.add_argument(
        "--scratch-table",
        action="store_true",
        help="instead, ch. 4.3.1 under every reading for each of --seeds, as a table",
    )
    parser.add_argument(
        "--seeds", type=NonNegativeInt, nargs="+", default=[0, 1, 2], help="--scratch-table's"
    )
    parser.add_argument("--doc", help="a doc whose block 'roadmap-from-scratch' gets the table")
    parser.add_argument("--meshcat", action="store_true", help="watch the robot in Meshcat")
    return parser


def main(argv: list[str] | None = None) -> None:
    parser = _Parser()
    args = parser.parse_args(argv)
    if args.doc and not args.scratch_table:
        parser.error("--doc writes the table of --scratch-table")
    CheckDocBlocks(parser, args.doc, DOC_TABLE)
    if args.scratch_table:
        lines = ScratchTable(args.seeds)
        if args.doc:
            command = "mobee-drake experiment roadmaps --scratch-table --seeds " + " ".join(
                map(str, args.seeds)
            )
            WriteGeneratedTable(
                args.doc, DOC_TABLE, f"{command} --doc {args.doc}", "\n".join(lines)
            )
        return
    meshcat = None
    if args.meshcat:
        meshcat = StartMeshcat()
    scratch, _ = RoadmapFromScratch(
        args.seed, vertex_sampling=args.vertex_sampling, edges=args.edges, meshcat=meshcat
    )
    print("Roadmap from scratch (ch. 4.3.1):")
    print(
        f"  {scratch.vertices} vertices, {scratch.edges} directed edges: {scratch.feasible} "
        f"feasible, {scratch.infeasible} infeasible, {scratch.untried} never reachable "
        f"({scratch.unreachable_vertices} vertices unreachable, {scratch.forbidden_vertices} "
        f"forbidden, {scratch.dead_ends} dead ends)"
    )
    print(
        f"  {scratch.commands} commands, {scratch.reflexes} reflexes, "
        f"{scratch.simulated_minutes:.1f} simulated minutes, {scratch.wall_seconds:.1f} s wall"
    )
    names = {HOME: "home", A: "A", B: "B", D: "D", E: "E"}
    replanning = AdaptiveReplanning(args.seed, meshcat=meshcat)

    def Named(path):
        return " -> ".join(names[v] for v in path)

    print("Adaptive re-planning (ch. 4.3.2):")
    print(
        f"  ball a ghost: planned {Named(replanning.ghost_path)}, arrived: "
        f"{replanning.ghost_arrived}"
    )
    print(
        f"  ball solid: planned {Named(replanning.first_solid_path)}, arrived: "
        f"{replanning.direct_arrived}; re-planned {Named(replanning.replanned_path)}, "
        f"arrived: {replanning.arrived_home}; {replanning.reflexes} reflex(es)"
    )
    if meshcat is not None:
        input("Press Enter to quit (Meshcat stops with this process).")


if __name__ == "__main__":
    main()
