"""Experiment: a torso that brings targets into the learned reach (ch. 9.4.2; docs/behaviours.md).

A reach learner trained by ``mobee-drake experiment ch8`` (``--learner``: one of its run folders)
is evaluated as in ch. 8.3.3 (a random start state, then every problem greedily, nothing learned)
on two sets of targets: its own (inside the arm's reach) and the same targets moved ``--beyond``
farther from the shoulder (outside it), each with and without the torso module
(:class:`~mobee_drake.behaviours.torso.PlaceTorso` on the torso's three joints, its map the
learner's best predicted reach reward). Without the module the torso's joints are controlled too
and stay at home, so the two stations differ by the module only. Per evaluation (a run): the
share of problems whose reach ends with the palm within ``--success`` of the target's centre, the
mean distance left, and the robot's simulated time per problem. On minus off is compared paired
by seed (the same start and order of problems), Holm-corrected over the two target sets and the
two measures; on the inside targets the comparison is the check that the module does not spoil
what the arm reaches alone.

Run: ``mobee-drake experiment torso-reach --learner results/ch8/runs/<run> [--seeds 10]
[--beyond 0.1] [--map evidence] [--torso-levels 9] [--torso-range 0.8] [--settle]
[--output results/torso_reach] [--doc docs/behaviours.md]``.
"""

import dataclasses as dc
import pathlib
import time

import numpy as np

from mobee_drake.behaviours.torso import REACH_MAPS, PlaceTorso, ReachMap
from mobee_drake.experiments.arguments import (
    CommandParser,
    Fraction,
    PositiveFloat,
    PositiveInt,
)
from mobee_drake.experiments.battery import (
    AddBackendArguments,
    BackendOf,
    Job,
    RunBattery,
    RunFolder,
)
from mobee_drake.experiments.ch8_reaching import RIGHT_ARM, LoadTrainedLearner, ReachScenario
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.experiments.statistics import FiniteMean, PairedBySeed
from mobee_drake.owned_folders import OwnedFolder
from mobee_drake.reaching.appearance import AppearanceWatch
from mobee_drake.reaching.robot import SimulatedRobot
from mobee_drake.reaching.targets import TARGET_NAME, TargetObject
from mobee_drake.robots.icub import TORSO_JOINTS, IcubConfig
from mobee_drake.scenario import BuildScenario
from mobee_drake.station.builder import MakeMobeeStation
from mobee_drake.station.composition import Behaviour, ComposeBehaviours
from mobee_drake.station.settling import ActionTiming

TARGET_SETS = ("inside", "outside")
CONDITIONS = ("off", "on")
# Where the problems' target object waits before the first problem (out of every reach).
_PARKED = [2.0, 2.0, 2.0]


@dc.dataclass
class TorsoReachRun:
    """One evaluation: a seed, a target set, the torso module on or off (m, s)."""

    seed: int
    targets: str
    condition: str
    # Per problem: the palm's distance to the target's centre at the reach's end (None: the
    # try ended without a reach).
    distances: list[float | None]
    robot_seconds: float
    wall_seconds: float
    # Control periods in which the robot's solids penetrated (the safety of the whole); the
    # problems whose target appeared inside the robot (ch. 8's targets may appear where the arm
    # rests; MoBeE then pushes the arm out), and the penetrating periods of the other problems.
    penetrating_steps: int
    appeared_inside: int = 0
    other_penetrating_steps: int = 0

    def Successes(self, within: float) -> float:
        """The share of problems reached within ``within`` of the target's centre."""
        return float(np.mean([d is not None and d <= within for d in self.distances]))

    @property
    def mean_distance(self) -> float:
        reached = [d for d in self.distances if d is not None]
        return float(np.mean(reached)) if reached else float("nan")


@dc.dataclass(frozen=True)
class TorsoModule:
    """The torso module's settings: its reach map (one of REACH_MAPS), its grid of postures
    (``levels`` angles per joint over ``range_fraction`` of each joint's range), and whether the
    torso settles where the module puts it before the arm's first action of each problem."""

    reach_map: str = "prediction"
    levels: int = PlaceTorso.levels
    range_fraction: float = PlaceTorso.range_fraction
    settle: bool = False

    def Label(self) -> str:
        """The settings that differ from the defaults, joined by '-' ('' for none)."""
        default = TorsoModule()
        parts = [self.reach_map] if self.reach_map != default.reach_map else []
        if self.levels != default.levels:
            parts.append(f"levels{self.levels}")
        if self.range_fraction != default.range_fraction:
            parts.append(f"range{self.range_fraction:g}")
        return "-".join(parts + (["settled"] if self.settle else []))


def TorsoReachRobot(
    learner, radius: float, torso: bool, module: TorsoModule = TorsoModule()
) -> SimulatedRobot:
    """The reach learner's robot with the torso's joints controlled, and, with ``torso``, the
    torso ``module`` beside the state-action executor."""
    scenario = ReachScenario()
    scenario.robot = IcubConfig(controlled_joints=list(TORSO_JOINTS) + RIGHT_ARM)
    # (SetProblem moves it, or adds it again after a reach took it away; the torso module reads
    # it, and nothing runs between a reach and the next problem here)
    scenario.objects = [TargetObject(_PARKED, radius)]
    if not torso:
        return SimulatedRobot(BuildScenario(scenario), RIGHT_ARM, learner.space, radius)
    placement = PlaceTorso(
        reach_map=ReachMap(learner, module.reach_map),
        target=TARGET_NAME,
        levels=module.levels,
        range_fraction=module.range_fraction,
    )
    station = MakeMobeeStation(
        scenario,
        prebuild_callback=lambda parts: ComposeBehaviours(
            parts,
            [
                Behaviour(
                    "reach",
                    tuple(RIGHT_ARM),
                    scenario.attractor.AddToBuilder,
                    (scenario.attractor.forcing.marker,),
                ),
                Behaviour("torso", TORSO_JOINTS, placement.AddToBuilder),
            ],
        ),
    )
    return SimulatedRobot(station, RIGHT_ARM, learner.space, radius)


def Beyond(robot: SimulatedRobot, targets: np.ndarray, distance: float) -> np.ndarray:
    """``targets`` moved ``distance`` farther from the shoulder (as it stands at home: where the
    arm's first joint sits on the chest)."""
    away = targets - robot.shoulder_at_home.translation()
    return targets + distance * away / np.linalg.norm(away, axis=1, keepdims=True)


class SettledTorso:
    """The robot, whose torso settles where the module puts it once a problem's target has
    appeared, before the arm's first action (the arm holds where it is meanwhile): the learner
    then decides every action of a problem with the torso in place. Settled is the actions'
    test (:class:`ActionTiming`) on the torso's joints, from the module's first choice."""

    def __init__(self, robot, period: float = PlaceTorso.period):
        self.robot, self._period, self._timing = robot, period, ActionTiming()
        mobee = robot.station.mobee
        self._speeds = len(mobee.joints) + np.array([mobee.joint_index(j) for j in TORSO_JOINTS])

    def __getattr__(self, name):  # (the rest of the Robot protocol, as it is)
        return getattr(self.robot, name)

    def SetProblem(self, target: np.ndarray) -> None:
        self.robot.SetProblem(target)
        simulator, context = self.robot.simulator, self.robot.context
        simulator.AdvanceTo(context.get_time() + self._period)  # (the module chooses)
        started, slow_since = context.get_time(), np.inf
        while True:
            now = context.get_time()
            v = self.robot.station.robot_state.Eval(context)[self._speeds]
            slow_since = self._timing.SlowSince(slow_since, now, v)
            if self._timing.Ended(now, started, slow_since):
                return
            simulator.AdvanceTo(now + self._period / 5)


def RunOne(
    run: RunFolder, learner_dir: str, seed: int, targets: str, condition: str, beyond: float,
    problems: int, **module,
) -> dict:  # fmt: skip
    """The battery job: one evaluation of the trained learner (``module``: the torso module's
    settings that differ from TorsoModule's defaults)."""
    learner, grid = LoadTrainedLearner(learner_dir)
    module = TorsoModule(**module)
    on = condition == "on"
    robot = TorsoReachRobot(learner, grid.radius, torso=on, module=module)
    chosen = grid.Centres()[:problems]
    if targets == "outside":
        chosen = Beyond(robot, chosen, beyond)
    began, start = time.perf_counter(), robot.context.get_time()
    watched = AppearanceWatch(robot)
    results = learner.Evaluate(
        SettledTorso(watched) if on and module.settle else watched, seed, chosen
    )
    watched.Close()
    by_problem = {r.problem: r for r in results}
    distances = [
        None
        if by_problem[i].reached is None
        else float(np.linalg.norm(np.array(by_problem[i].reached) - chosen[i]))
        for i in range(len(chosen))
    ]
    return dc.asdict(
        TorsoReachRun(
            seed=seed,
            targets=targets,
            condition=condition,
            distances=distances,
            robot_seconds=(robot.context.get_time() - start) / len(chosen),
            wall_seconds=time.perf_counter() - began,
            penetrating_steps=robot.Safety().penetrating_steps,
            appeared_inside=watched.counts.appeared_inside,
            other_penetrating_steps=watched.counts.other_penetrating_steps,
        )
    )


def Report(runs: list[TorsoReachRun], within: float, command: str) -> str:
    """The report's table and the paired comparisons (markdown)."""
    lines = [
        f"| targets | torso module | runs | reached within {100 * within:g} cm (mean over runs) "
        "| palm to target at the reach's end, cm | robot s per problem | penetrating periods "
        "| targets that appeared inside the robot | penetrating periods of the other problems "
        "| wall s per run |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    group = {
        (t, c): sorted(
            (r for r in runs if (r.targets, r.condition) == (t, c)), key=lambda r: r.seed
        )
        for t in TARGET_SETS
        for c in CONDITIONS
    }
    for (targets, condition), rs in group.items():
        if rs:
            lines.append(
                f"| {targets} | {condition} | {len(rs)} | "
                f"{100 * np.mean([r.Successes(within) for r in rs]):.0f} % | "
                f"{100 * FiniteMean([r.mean_distance for r in rs]):.1f} | "
                f"{np.mean([r.robot_seconds for r in rs]):.1f} | "
                f"{sum(r.penetrating_steps for r in rs)} | "
                f"{sum(r.appeared_inside for r in rs)} | "
                f"{sum(r.other_penetrating_steps for r in rs)} | "
                f"{np.mean([r.wall_seconds for r in rs]):.0f} |"
            )
    measures = {
        "share reached": lambda r: r.Successes(within),
        "robot s per problem": lambda r: r.robot_seconds,
    }
    families = {f"{t} targets": (group[(t, "on")], group[(t, "off")]) for t in TARGET_SETS}
    lines += PairedBySeed(families, measures, "On minus off")
    return "\n".join(lines) + f"\n\nCommand: `{command}`."


def _Parser() -> CommandParser:
    parser = CommandParser(
        prog="mobee-drake experiment torso-reach", description=__doc__.split("\n\n")[0]
    )
    required = parser.add_argument_group("required options")
    required.add_argument(
        "--learner", required=True, help="a run folder of `mobee-drake experiment ch8`"
    )
    parser.add_argument("--seeds", type=PositiveInt, default=10, help="evaluations per setting")
    parser.add_argument(
        "--beyond", type=PositiveFloat, default=0.1, help="the outside targets' shift (m)"
    )
    parser.add_argument(
        "--success", type=PositiveFloat, default=0.05, help="a reach within this (m) succeeds"
    )
    parser.add_argument(
        "--problems", type=PositiveInt, default=27, help="the first N of the learner's targets"
    )
    parser.add_argument(
        "--map",
        choices=REACH_MAPS,
        default="prediction",
        help="the torso's reach map: eq. 8.5's best prediction, or the best mean reward recorded "
        "within 5 cm (0 where none was)",
    )
    parser.add_argument(
        "--torso-levels",
        type=PositiveInt,
        default=TorsoModule.levels,
        help="the torso's grid: angles per joint",
    )
    parser.add_argument(
        "--torso-range",
        type=Fraction,
        default=TorsoModule.range_fraction,
        help="the torso's grid: the share of each joint's range it spans, around home",
    )
    parser.add_argument(
        "--settle",
        action="store_true",
        help="let the torso settle where the module puts it before the arm's first action",
    )
    parser.add_argument("--output", default="results/torso_reach", help="the battery folder")
    parser.add_argument(
        "--doc",
        help="a doc whose generated block gets the report: --block, or 'torso-reach' with the "
        "torso module's settings that differ from the defaults appended (e.g. "
        "'torso-reach-evidence-settled')",
    )
    parser.add_argument("--block", help="the name of the doc's generated block (see --doc)")
    AddBackendArguments(parser)
    return parser


def main(argv: list[str] | None = None) -> None:
    parser = _Parser()
    args = parser.parse_args(argv)
    module = TorsoModule(args.map, args.torso_levels, args.torso_range, args.settle)
    # (The grid's and settling's settings at their defaults stay out of the jobs, so the
    # batteries run before they were options keep their jobs.)
    changed = {
        field.name: getattr(module, field.name)
        for field in dc.fields(module)
        if field.name == "reach_map" or getattr(module, field.name) != field.default
    }
    block = args.block or "-".join(filter(None, ["torso-reach", module.Label()]))
    try:
        LoadTrainedLearner(args.learner)
    except (OSError, ValueError) as error:
        parser.error(str(error))
    CheckDocBlocks(parser, args.doc, block)
    learner_dir = str(pathlib.Path(args.learner).resolve())
    jobs = [
        Job(
            f"seed{seed}_{targets}_{condition}",
            RunOne,
            dict(
                learner_dir=learner_dir,
                seed=seed,
                targets=targets,
                condition=condition,
                beyond=args.beyond,
                problems=args.problems,
                **changed,
            ),
        )  # fmt: skip
        for seed in range(args.seeds)
        for targets in TARGET_SETS
        for condition in CONDITIONS
    ]
    output = pathlib.Path(args.output)
    results = RunBattery(jobs, output, backend=BackendOf(args), description="torso reach")
    runs = [TorsoReachRun(**r) for r in results.values()]
    command = "mobee-drake experiment torso-reach " + " ".join(argv if argv is not None else [])
    report = Report(runs, args.success, command.strip())
    with OwnedFolder(output, "battery"):
        (output / "report.md").write_text(report + "\n")
    if args.doc:
        WriteGeneratedTable(args.doc, block, command.strip(), report)
    print(report)


if __name__ == "__main__":
    main()
