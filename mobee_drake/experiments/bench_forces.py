"""Benchmark: MoBeE total-force evaluations per second for a robot among boxes (Fig. 2.4).

Like the scalability experiment of dissertation ch. 2.4: every controlled joint is driven through
its range by its own oscillator, and for each new pose the whole MoBeE evaluation runs (forward
kinematics, SceneGraph's signed-distance query, every force term and their total), against 0 to
several hundred boxes in the robot's workspace: the iCub upper body (20 joints, 14 primitives),
the same with 125 boxes fitted to its meshes (``icub_dense``, about the source's 129 primitives)
or the Katana of App. B (5 joints, 10 primitives). With ``--churn``, as in Alg. 1, objects are
removed and inserted while the robot moves: before every evaluation one box is removed and a new one
inserted (our single-threaded stand-in for the source's sensory thread flooding the model).
One process, one core.

Beside MoBeE's time each row prints Drake's own cost of the same work on the same poses, the
*floor*: ``SetPositions`` and SceneGraph's signed-distance query up to the largest field margin
(with ``--churn``, the same box replacements too), timed in alternate sweeps with MoBeE's so
that both see the machine at the same speed; their ratio; and the process's peak resident
memory after the row.

Run: ``mobee-drake bench forces [--robot katana] [--churn] [--plot FILE.png]`` (or
``python -m mobee_drake.experiments.bench_forces``).
"""

import dataclasses as dc
import resource
import sys
import time

import numpy as np
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, MultibodyPlant
from pydrake.systems.framework import Diagram, DiagramBuilder

from mobee_drake.experiments.arguments import (
    CommandParser,
    Fraction,
    NonNegativeInt,
    PositiveInt,
)
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.experiments.plots import Figure, SaveFigure, plt
from mobee_drake.mobee.barrier import StepModel
from mobee_drake.mobee.system import Mobee
from mobee_drake.owned_folders import CanWrite
from mobee_drake.robots.icub import IcubConfig
from mobee_drake.robots.scenario_robot import AddScenarioRobot
from mobee_drake.robots.zero_position import ZeroPositionConfig
from mobee_drake.world.live_world import LiveWorld
from mobee_drake.world.objects import Box, SceneObject

# Where boxes are placed, per robot (root frame, metres). In front of the iCub (x backwards, y
# right, z up): 60 cm in front of the chest, 1.2 m across and 1 m high; the arms reach about half
# of it. Around the Katana: its reach (about 0.5 m around the shoulder at (0, 0, -0.01)).
BOX_REGIONS = {
    "icub": (np.array([-0.80, -0.60, -0.40]), np.array([-0.20, 0.60, 0.60])),
    "katana": (np.array([-0.50, -0.50, -0.20]), np.array([0.50, 0.50, 0.55])),
}
BOX_REGIONS["icub_dense"] = BOX_REGIONS["icub"]
ROBOTS = {
    "icub": IcubConfig,
    # The iCub with boxes fitted to its meshes (models/icub_dense_overlay.yaml, 125 primitives,
    # about the source's 129; issue 34).
    "icub_dense": lambda: IcubConfig(overlay="icub_dense_overlay.yaml"),
    "katana": ZeroPositionConfig,
}


@dc.dataclass
class ForceBenchmarkResult:
    num_obstacles: int
    # The best and the median rate over the repeats (this machine's speed varies between runs).
    best_per_second: float
    median_per_second: float
    mean_pairs_in_fields: float
    # Drake's floor for the same poses (best sweep, us per pose), and MoBeE's best over it.
    floor_us: float = 0.0
    # Peak resident memory of the process after the row (MiB).
    peak_rss_mib: float = 0.0
    # The mean norm of MoBeE's total over the poses (M rad/s^2): what the evaluations computed.
    mean_total_norm: float = 0.0

    @property
    def ratio(self) -> float:
        return 1e6 / self.best_per_second / self.floor_us


def _RandomBox(name: str, robot: str, rng: np.random.Generator) -> SceneObject:
    low, high = BOX_REGIONS[robot]
    return SceneObject(
        name=name,
        shape=Box(size=rng.uniform(0.02, 0.05, size=3).tolist()),
        position=rng.uniform(low, high).tolist(),
    )


@dc.dataclass
class PosedScene:
    """A robot, its objects and MoBeE, posed by ``SetPositions`` on the plant (no simulator)."""

    diagram: Diagram
    plant: MultibodyPlant
    mobee: Mobee
    world: LiveWorld
    max_margin: float  # the largest field margin: the floor's query distance

    def Contexts(self):
        """A fresh root context, the plant's and MoBeE's in it."""
        context = self.diagram.CreateDefaultContext()
        return (
            context,
            self.plant.GetMyMutableContextFromRoot(context),
            self.mobee.GetMyContextFromRoot(context),
        )

    def PositionOrder(self) -> list[int]:
        """Where MoBeE's joints are in the plant's positions."""
        return [self.plant.GetJointByName(j).position_start() for j in self.mobee.joints]


def BuildPosedScene(robot_config, objects, period: float = 0.0) -> PosedScene:
    """The robot of ``robot_config`` among ``objects`` (SceneObjects), with MoBeE; with a
    ``period`` (s), MoBeE's safety barrier as the kinematic robot runs it at that period."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    overlay, joints = AddScenarioRobot(plant, scene_graph, robot_config)
    world = LiveWorld(plant, scene_graph)
    for obj in objects:
        world.Register(obj)
    plant.Finalize()
    mobee = Mobee.AddToBuilder(
        builder,
        plant=plant,
        scene_graph=scene_graph,
        robot=overlay,
        joints=joints,
        step=StepModel(period) if period > 0 else None,
    )
    return PosedScene(builder.Build(), plant, mobee, world, max(overlay.field_margins.values()))


def FloorEvaluation(scene: PosedScene, mobee_context):
    """Drake's floor for one pose already set: SceneGraph's signed-distance query up to the
    largest field margin (the pose update included)."""
    query = scene.mobee.GetInputPort("geometry_query")
    return lambda: query.Eval(mobee_context).ComputeSignedDistancePairwiseClosestPoints(
        scene.max_margin
    )


def _OscillatorPoses(
    mobee: Mobee, num_poses: int, rng: np.random.Generator, amplitude: float = 1.0
) -> np.ndarray:
    """Poses 10 ms apart, each joint on its own sinusoid.

    With ``amplitude`` 1 every joint sweeps its whole range (Fig. 2.4); with a smaller amplitude it
    sweeps that fraction of its range around the home posture (clipped to the limits).
    """
    q_min, q_max = mobee.position_limits
    period = rng.uniform(4.0, 12.0, size=q_min.size)  # seconds per sweep
    phase = rng.uniform(0, 2 * np.pi, size=q_min.size)
    t = 0.01 * np.arange(num_poses)[:, None]
    center = (q_min + q_max) / 2 if amplitude >= 1 else mobee.home
    q = center + amplitude * (q_max - q_min) / 2 * np.sin(2 * np.pi * t / period + phase)
    return np.clip(q, q_min, q_max)


def MeasureForceEvaluations(
    num_obstacles: int,
    *,
    robot: str = "icub",
    num_poses: int = 2000,
    repeats: int = 5,
    amplitude: float = 1.0,
    churn: bool = False,
    seed: int = 0,
    period: float = 0.0,
) -> ForceBenchmarkResult:
    """Times ``repeats`` sweeps of ``num_poses`` total-force evaluations among boxes; with
    ``churn``, each evaluation follows the removal of one box and the insertion of another; with
    a ``period``, MoBeE's safety barrier runs as at that period."""
    rng = np.random.default_rng(seed)
    objects = [_RandomBox(f"box{i}", robot, rng) for i in range(num_obstacles)]
    scene = BuildPosedScene(ROBOTS[robot](), objects, period)
    plant, mobee, world = scene.plant, scene.mobee, scene.world
    context, plant_context, mobee_context = scene.Contexts()
    boxes = [obj.name for obj in objects]
    replacements = [
        _RandomBox(f"new{k}", robot, rng)
        for k in range(num_poses * repeats if churn and boxes else 0)
    ]
    total, contacts = mobee.GetOutputPort("total"), mobee.GetOutputPort("field_contacts")
    # The plant's positions are the controlled joints, possibly in another order.
    order = scene.PositionOrder()
    poses = _OscillatorPoses(mobee, num_poses, rng, amplitude)
    x = plant.GetPositions(plant_context)

    def Sweep(repeat: int, evaluate) -> float:
        """Seconds for one sweep of the poses, each after its box replacement (with churn)."""
        start = time.perf_counter()
        for k, q in enumerate(poses):
            if replacements:
                new = replacements[repeat * num_poses + k]
                world.Remove(context, boxes[k % len(boxes)])
                world.Add(context, new)
                boxes[k % len(boxes)] = new.name
            x[order] = q
            plant.SetPositions(plant_context, x)
            evaluate()
        return time.perf_counter() - start

    floor = FloorEvaluation(scene, mobee_context)
    rates, floors = [], []
    for repeat in range(repeats):
        floors.append(Sweep(repeat, floor) / num_poses)
        if replacements:  # The churn's boxes are used once each: draw the sweep's anew.
            replacements[repeat * num_poses : (repeat + 1) * num_poses] = [
                _RandomBox(f"floor{repeat}_{k}", robot, rng) for k in range(num_poses)
            ]
        rates.append(num_poses / Sweep(repeat, lambda: total.Eval(mobee_context)))
    pairs, norms = 0, []
    for q in poses[::10]:  # Untimed: how busy the field term was, and what MoBeE computed.
        x[order] = q
        plant.SetPositions(plant_context, x)
        pairs += len(contacts.Eval(mobee_context))
        norms.append(np.linalg.norm(total.Eval(mobee_context)))
    return ForceBenchmarkResult(
        num_obstacles,
        max(rates),
        float(np.median(rates)),
        pairs / len(poses[::10]),
        floor_us=1e6 * min(floors),
        peak_rss_mib=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        mean_total_norm=float(np.mean(norms)),
    )


# The stages of one evaluation timed by ``--stages``, each after the previous ones (so each
# stage's time is its own: the caches of the earlier stages are up to date).
STAGES = (
    "pose update",  # SceneGraph's poses of the robot's geometries (forward kinematics)
    "query",  # the signed-distance query up to the largest field margin
    "field pairs",  # reading the query's results into MoBeE's field pairs (the query again)
    "forces",  # MoBeE's total: its plant context, screws, normals and every term
)


def MeasureStages(
    num_obstacles: int, *, robot: str = "icub", num_poses: int = 2000, repeats: int = 5, seed=0
) -> dict[str, float]:
    """Microseconds per evaluation of each of :data:`STAGES` (best of ``repeats`` sweeps), through
    MoBeE's public ports; "field pairs" includes a second query (MoBeE's own), which is then
    subtracted, so that the stages add up to one evaluation."""
    rng = np.random.default_rng(seed)
    objects = [_RandomBox(f"box{i}", robot, rng) for i in range(num_obstacles)]
    scene = BuildPosedScene(ROBOTS[robot](), objects)
    plant, mobee = scene.plant, scene.mobee
    _, plant_context, mobee_context = scene.Contexts()
    order, poses = scene.PositionOrder(), _OscillatorPoses(mobee, num_poses, rng)
    x = plant.GetPositions(plant_context)
    query_port = mobee.GetInputPort("geometry_query")
    pairs_port, total_port = mobee.GetOutputPort("field_pairs"), mobee.GetOutputPort("total")
    some_geometry = query_port.Eval(mobee_context).inspector().GetAllGeometryIds()[0]
    best = dict.fromkeys(STAGES, np.inf)
    clock = time.perf_counter
    for _ in range(repeats):
        spent = dict.fromkeys(STAGES, 0.0)
        for q in poses:
            x[order] = q
            plant.SetPositions(plant_context, x)
            t0 = clock()
            query = query_port.Eval(mobee_context)
            query.GetPoseInWorld(some_geometry)
            t1 = clock()
            query.ComputeSignedDistancePairwiseClosestPoints(scene.max_margin)
            t2 = clock()
            pairs_port.Eval(mobee_context)
            t3 = clock()
            total_port.Eval(mobee_context)
            t4 = clock()
            for stage, seconds in zip(STAGES, (t1 - t0, t2 - t1, t3 - t2 - (t2 - t1), t4 - t3)):
                spent[stage] += seconds
        for stage in STAGES:
            best[stage] = min(best[stage], 1e6 * spent[stage] / num_poses)
    return best


def ScalabilityFigure(curves: dict[str, list[tuple]], churn: bool) -> Figure:
    """Fig. 2.4: MoBeE evaluations per second against the boxes in the workspace, per robot
    (``curves``: robot -> rows of boxes, best and median rate)."""
    figure, axis = plt.subplots(figsize=(7, 4.5))
    for i, (robot, points) in enumerate(curves.items()):
        n, best, median = np.array(points).T
        axis.plot(n, best, "o-", color=f"C{i}", label=f"{robot}, best sweep")
        axis.plot(n, median, "x--", color=f"C{i}", label=f"{robot}, median sweep")
    axis.set_yscale("log")
    axis.set(
        xlabel="boxes in the workspace [count]",
        ylabel="MoBeE evaluations [1/s]",
        title="Fig. 2.4 redone: MoBeE's whole force computation per second"
        + ("\n(one box removed and one inserted before every evaluation)" if churn else ""),
    )
    axis.grid(True, which="both", alpha=0.3)
    axis.legend()
    return figure


def _Parser() -> CommandParser:
    """The command line of ``mobee-drake bench forces``."""
    parser = CommandParser(
        prog="mobee-drake bench forces",
        description=__doc__,
    )
    parser.add_argument(
        "--robot", choices=sorted(ROBOTS), nargs="+", default=["icub"], help="the robots to measure"
    )
    parser.add_argument(
        "--obstacles",
        type=NonNegativeInt,
        nargs="+",
        default=[0, 10, 30, 100, 300],
        help="numbers of random boxes, one row each",
    )
    parser.add_argument("--poses", type=PositiveInt, default=2000, help="evaluations per sweep")
    parser.add_argument("--repeats", type=PositiveInt, default=5, help="sweeps per row")
    parser.add_argument(
        "--amplitude",
        type=Fraction,
        default=1.0,
        help="fraction of each joint's range swept (1: the whole range, Fig. 2.4)",
    )
    parser.add_argument(
        "--churn",
        action="store_true",
        help="remove one box and insert another before every evaluation (Alg. 1)",
    )
    parser.add_argument("--plot", default="", help="save the curves (like Fig. 2.4) to this PNG")
    parser.add_argument(
        "--seed", type=NonNegativeInt, default=0, help="seed of the boxes and the oscillators"
    )
    parser.add_argument(
        "--barrier-period",
        type=float,
        default=0.0,
        help="with a period (s, > 0), evaluate MoBeE's safety barrier too, as the kinematic "
        "robot runs it at that period (the poses are at rest)",
    )
    parser.add_argument(
        "--doc", help="a doc whose generated block (--doc-table) to rewrite with the table"
    )
    parser.add_argument("--doc-table", default="forces", help="the name of --doc's block")
    parser.add_argument(
        "--stages",
        action="store_true",
        help="instead, time each stage of one evaluation: " + ", ".join(STAGES),
    )
    return parser


def main(argv=None) -> None:
    parser = _Parser()
    args = parser.parse_args(argv)
    if args.plot and not CanWrite(args.plot):  # (checked before the work)
        parser.error(f"--plot {args.plot}: cannot be written (its folder is missing, read-only?)")
    CheckDocBlocks(parser, args.doc, args.doc_table)
    if args.stages:
        print("| robot | boxes | " + " | ".join(f"{s} (us)" for s in STAGES) + " |")
        print("|---|---:|" + "---:|" * len(STAGES))
        for robot in args.robot:
            for n in args.obstacles:
                stages = MeasureStages(
                    n, robot=robot, num_poses=args.poses, repeats=args.repeats, seed=args.seed
                )
                cells = " | ".join(f"{stages[s]:.1f}" for s in STAGES)
                print(f"| {robot} | {n} | {cells} |", flush=True)
        return
    lines = [
        "| robot | boxes | evaluations/s (best) | evaluations/s (median) | us/evaluation (best) "
        "| floor us (best) | ratio | pairs inside fields (mean) | peak RSS (MiB) |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    print("\n".join(lines))
    curves = {}
    for robot in args.robot:
        for n in args.obstacles:
            r = MeasureForceEvaluations(
                n,
                robot=robot,
                num_poses=args.poses,
                repeats=args.repeats,
                amplitude=args.amplitude,
                churn=args.churn,
                seed=args.seed,
                period=args.barrier_period,
            )
            curves.setdefault(robot, []).append((n, r.best_per_second, r.median_per_second))
            lines.append(
                f"| {robot} | {n} | {r.best_per_second:,.0f} | {r.median_per_second:,.0f} | "
                f"{1e6 / r.best_per_second:.0f} | {r.floor_us:.0f} | {r.ratio:.2f} | "
                f"{r.mean_pairs_in_fields:.2f} | {r.peak_rss_mib:.0f} |"
            )
            print(lines[-1], flush=True)
    if args.doc:
        command = "mobee-drake bench forces " + " ".join(sys.argv[1:] if argv is None else argv)
        WriteGeneratedTable(args.doc, args.doc_table, command, "\n".join(lines))
    if args.plot:
        SaveFigure(ScalabilityFigure(curves, args.churn), args.plot, dpi=90)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
