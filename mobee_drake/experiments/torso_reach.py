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
[--beyond 0.1] [--output results/torso_reach] [--doc docs/behaviours.md]``.
"""

import dataclasses as dc
import pathlib
import time

import numpy as np

from mobee_drake.behaviours.torso import REACH_MAPS, PlaceTorso, ReachMap
from mobee_drake.experiments.arguments import CommandParser, PositiveFloat, PositiveInt
from mobee_drake.experiments.battery import (
    AddBackendArguments,
    BackendOf,
    Job,
    RunBattery,
    RunFolder,
)
from mobee_drake.experiments.ch8_reaching import RIGHT_ARM, LoadTrainedLearner, ReachScenario
from mobee_drake.experiments.doc_tables import GeneratedTable, WriteGeneratedTable
from mobee_drake.experiments.statistics import ComparePaired, FiniteMean, Holm
from mobee_drake.owned_folders import OwnedFolder
from mobee_drake.reaching.robot import SimulatedRobot
from mobee_drake.reaching.targets import TARGET_NAME, TargetObject
from mobee_drake.robots.icub import TORSO_JOINTS, IcubConfig
from mobee_drake.scenario import BuildScenario
from mobee_drake.station.builder import MakeMobeeStation
from mobee_drake.station.composition import Behaviour, ComposeBehaviours
from mobee_drake.station.safety import Penetrations

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


def TorsoReachRobot(
    learner, radius: float, torso: bool, reach_map: str = "prediction"
) -> SimulatedRobot:
    """The reach learner's robot with the torso's joints controlled, and, with ``torso``, the
    torso module (its map of the kind ``reach_map``) beside the state-action executor."""
    scenario = ReachScenario()
    scenario.robot = IcubConfig(controlled_joints=list(TORSO_JOINTS) + RIGHT_ARM)
    scenario.objects = [TargetObject(_PARKED, radius)]  # SetProblem moves it
    if not torso:
        return SimulatedRobot(BuildScenario(scenario), RIGHT_ARM, learner.space, radius)
    placement = PlaceTorso(reach_map=ReachMap(learner, reach_map), target=TARGET_NAME)
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


class AppearanceWatch:
    """The robot, watched for targets that appear inside it (see TorsoReachRun)."""

    def __init__(self, robot: SimulatedRobot):
        self.robot, self.appeared_inside, self.other = robot, 0, 0
        self._inside, self._start = True, 0

    def __getattr__(self, name):  # (the rest of the Robot protocol, unwatched)
        return getattr(self.robot, name)

    def Close(self) -> None:
        """Ends the current problem's count."""
        if not self._inside:
            self.other += self.robot.Safety().penetrating_steps - self._start

    def SetProblem(self, target: np.ndarray) -> None:
        self.Close()
        self.robot.SetProblem(target)
        self._inside = bool(Penetrations(self.robot.station.diagram, self.robot.context))
        self.appeared_inside += self._inside
        self._start = self.robot.Safety().penetrating_steps


def RunOne(
    run: RunFolder, learner_dir: str, seed: int, targets: str, condition: str, beyond: float,
    problems: int, reach_map: str = "prediction",
) -> dict:  # fmt: skip
    """The battery job: one evaluation of the trained learner."""
    learner, grid = LoadTrainedLearner(learner_dir)
    robot = TorsoReachRobot(learner, grid.radius, torso=condition == "on", reach_map=reach_map)
    chosen = grid.Centres()[:problems]
    if targets == "outside":
        chosen = Beyond(robot, chosen, beyond)
    began, start = time.perf_counter(), robot.context.get_time()
    watched = AppearanceWatch(robot)
    results = learner.Evaluate(watched, seed, chosen)
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
            appeared_inside=watched.appeared_inside,
            other_penetrating_steps=watched.other,
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
    compared = {}
    for targets in TARGET_SETS:
        on, off = group[(targets, "on")], group[(targets, "off")]
        seeds = sorted({r.seed for r in on} & {r.seed for r in off})
        if len(seeds) < 2:
            continue
        on, off = ([r for r in rs if r.seed in seeds] for rs in (on, off))
        for name, f in measures.items():
            compared[f"{targets} targets, {name}"] = ComparePaired(
                [f(r) for r in on], [f(r) for r in off], [0] * len(seeds)
            )
    if compared:
        adjusted = Holm([c.t_p for c in compared.values()])
        lines += ["", f"On minus off, paired by seed (Holm over the {len(compared)}):", ""]
        lines += [f"- {name}: {c.Text(p)}" for (name, c), p in zip(compared.items(), adjusted)]
    return "\n".join(lines) + f"\n\nCommand: `{command}`."


def main(argv: list[str] | None = None) -> None:
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
    parser.add_argument("--output", default="results/torso_reach", help="the battery folder")
    parser.add_argument(
        "--doc",
        help="a doc whose generated block 'torso-reach' (with --map evidence, "
        "'torso-reach-evidence') gets the report",
    )
    AddBackendArguments(parser)
    args = parser.parse_args(argv)
    block = "torso-reach" if args.map == "prediction" else f"torso-reach-{args.map}"
    try:
        LoadTrainedLearner(args.learner)
        if args.doc:
            GeneratedTable(args.doc, block)
    except (OSError, ValueError) as error:
        parser.error(str(error))
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
                reach_map=args.map,
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
