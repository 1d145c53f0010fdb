"""Experiment: a state-action space that reshapes itself (ch. 9.4.5; docs/adaptive_space.md).

The curious agent of ch. 7 explores an arm (``--robots``: :mod:`~mobee_drake.experiments.arms`,
the iCub's right shoulder and elbow, the Katana's first four joints among its obstacles) for
``--actions`` actions on a fixed space and on the same space maintained by the rules of
:mod:`mobee_drake.planning.space_maintenance`, ``--seeds`` runs of each, paired by seed (the same
generator). The spaces (``--spaces``): ch. 7.3's rank-4 lattice at 12.5-87.5 % (256 states; on
the iCub its corner states beyond the shoulder's cable constraints are never entered), ch. 7.2's
rank-3 lattice (81 states), and ``trm``: a task-relevant roadmap over the valid configurations
themselves (:mod:`mobee_drake.trm.configuration`; ``--trm-spacing``, at most ``--trm-states``
states, the rank-4 lattice's number by default), built once per arm by the battery's job
``<robot>_roadmap``, its vertices the states and its edges the actions both ways. The ch. 8 part
(``--part reaching``) is :mod:`mobee_drake.experiments.adaptive_space_reaching`.

Per run, at the end:

- *coverage*: the share of a fixed sample of the arm's valid configurations (within the joint
  limits, every constraint clause satisfied, no collision; ``arms.VALID_SAMPLES`` of them, drawn
  uniformly in fractions of each joint's range) within ``--radius`` (fractions of range; by
  default half the rank-4 lattice's spacing: at the spacing itself a run of 2000 actions
  leaves no valid configuration uncovered) of a configuration in which one of the run's actions
  ended (:attr:`~mobee_drake.planning.supervisor.AgentRecord.settled`, where the arm was, not
  the state it was counted in): how much of what the arm can do the agent has been near, whatever
  its space and however that space was cut;
- *dispersion*: the mean distance (fractions of range) from those valid configurations to the
  nearest configuration in which an action ended (no threshold);
- *prediction error*: ``--tests`` state-actions of states the robot was in (an action started
  or ended there: as the model shows, and as the maintenance saw it where ``drop`` made the
  model forget; :attr:`~mobee_drake.planning.space_maintenance.Maintenance.entered`), drawn at
  random, run once each on a fresh robot (put in the state's centre first; skipped if it does
  not get there): one minus the probability the learned model gave the outcome (held out: the
  model does not learn from them);
- *state-actions tried*: the share of the space's state-actions tried at least once (ch. 7.2's
  coverage, of the space as it ended);
- the space's states and state-actions at the end, its changes by rule, the robot's simulated
  time per action, the wall time and the penetrating periods.

Maintained minus fixed on each space, and the roadmap, fixed and maintained, minus the fixed
rank-4 lattice, are compared paired by seed in two families, each Holm-corrected over its
comparisons: what was learned (coverage, dispersion, prediction error, state-actions tried, in
percentage points or % of range) and what it cost (robot seconds per action, wall seconds per
run). No round is made at the run's last action count (``MaintenanceConfig.until``): the
measures see the space the agent explored in its last ``--every`` actions, not one just
reshaped. The report names a PNG and, per arm, a Meshcat scene of the first seed's maintained
runs (:mod:`mobee_drake.experiments.adaptive_space_figures`).

Run: ``mobee-drake experiment adaptive-space [--robots icub katana] [--seeds 10] [--actions 2000]
[--output results/adaptive_space] [--doc docs/adaptive_space.md]``.
"""

import collections
import dataclasses as dc
import pathlib
import shlex

import numpy as np
import scipy.spatial

from mobee_drake.atomic_files import CurrentGeneration
from mobee_drake.experiments import adaptive_space_reaching as reaching_part
from mobee_drake.experiments.adaptive_space_figures import History, WriteSpaceFigures
from mobee_drake.experiments.adaptive_space_report import BySetting, ChangesCell, SpaceComparisons
from mobee_drake.experiments.arguments import CommandParser, PositiveFloat, PositiveInt
from mobee_drake.experiments.arms import (
    TARGET_RADIUS,
    Arm,
    Arms,
    ReachTargets,
    RoadmapFolder,
    RoadmapJobName,
    RoadmapJobOf,
    RoadmapLines,
    RoadmapSpace,
    TargetGaps,
    ValidConfigurations,
)
from mobee_drake.experiments.battery import (
    AddBackendArguments,
    BackendOf,
    FinishedResults,
    Job,
    RunBattery,
    RunFolder,
)
from mobee_drake.experiments.ch7_model_learning import ExploreJob, Stop
from mobee_drake.experiments.ch8_reaching import MdpName, ReachRobot
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.experiments.exploration import ExplorationRun
from mobee_drake.owned_folders import OwnedFolder
from mobee_drake.planning.explorers import ExplorerConfig, LoadAgentModel
from mobee_drake.planning.space_maintenance import (
    RULES,
    ChangesByRule,
    MaintenanceConfig,
    VisitedStates,
)
from mobee_drake.planning.state_space import Lattice
from mobee_drake.planning.supervisor import ExploringAgent, SavedMaintenance, SavedSettled

# The lattices compared: their levels (fractions of each joint's range; rank3 is ch. 8's); and
# "trm", a roadmap over the valid configurations (mobee_drake.trm.configuration), built once per
# battery.
LATTICES = {"rank4": [0.125, 0.375, 0.625, 0.875], "rank3": [0.25, 0.5, 0.75]}
SPACES = (*LATTICES, "trm")
CONDITIONS = ("fixed", "maintained")
AGENT = "right_arm"


@dc.dataclass
class AdaptiveSpaceRun:
    """One run: a robot, a space, fixed or maintained, a seed (see the module for the
    measures)."""

    robot: str
    space: str
    condition: str
    seed: int
    actions: int
    coverage: float
    dispersion: float
    prediction_error: float
    tests: int
    tried_share: float
    states: int
    state_actions: int
    changes: dict[str, int]
    robot_seconds_per_action: float
    wall_seconds: float
    penetrating_steps: int


def Nearest(settled: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """Per configuration of ``valid``, its distance to the nearest configuration in which an
    action ended (``settled``, both in fractions of range; inf: none)."""
    if not len(settled):
        return np.full(len(valid), np.inf)
    return scipy.spatial.cKDTree(settled).query(valid)[0]


def PredictionError(
    robot: str, explorer, visited: np.ndarray, tests: int, seed: int
) -> tuple[float, int]:
    """(the mean of one minus the model's probability of each held-out test's outcome, the
    tests run): see the module. The tests are actions of the states the robot was in
    (``visited``, per state) and run on a fresh robot of the arm ``robot``, the reach learner's
    (its state-action executor)."""
    space = explorer.space
    visited = np.flatnonzero(visited)
    candidates = np.flatnonzero(np.isin(space.action_state, visited))
    rng = np.random.default_rng(seed)
    chosen = rng.choice(candidates, size=min(tests, len(candidates)), replace=False)
    fresh = ReachRobot(space, TARGET_RADIUS, robot=robot)
    T = explorer.transitions.Probabilities()
    errors = []
    for sa in chosen:
        state = int(space.action_state[sa])
        if fresh.Transition(state) != state:
            continue  # (the robot could not be put there)
        outcome = fresh.Transition(int(space.action_goal[sa]))
        errors.append(1.0 - T[sa, outcome])
    return (float(np.mean(errors)) if errors else float("nan")), len(errors)


def AdaptiveSpaceJob(
    run: RunFolder, *, robot: str, space: str, condition: str, seed: int, actions: int,
    tests: int, radius: float, maintenance: MaintenanceConfig,
) -> dict:  # fmt: skip
    """The battery job: one run (see the module)."""
    arm = Arms()[robot]
    agent = ExploringAgent(
        name=AGENT,
        joints=list(arm.joints),
        maintenance=dc.replace(maintenance, until=actions) if condition == "maintained" else None,
    )
    if space in LATTICES:
        agent.levels = LATTICES[space]
    else:
        agent.roadmap = str(RoadmapFolder(run.path.parent, robot))
    explored = ExplorationRun.FromJson(
        ExploreJob(
            run,
            agents=[agent],
            stop=Stop(actions=actions),
            labels=dict(robot=robot, space=space, condition=condition, seed=seed),
            objects=arm.objects,
            random_seed=seed,
            chunk=5.0,
            keep_model=True,
            robot=None if robot == "icub" else arm.robot,  # (the iCub's upper body, as ch. 7)
        )
    )
    folder = str(run.path / "model")
    explorer = LoadAgentModel(folder, AGENT, ExplorerConfig())
    maintenance = SavedMaintenance(folder, AGENT, MaintenanceConfig())
    visited = VisitedStates(explorer)  # (and those the model forgot when `drop` removed all
    if maintenance is not None:  # of a state's tried transitions)
        visited |= maintenance.entered
    error, tested = PredictionError(robot, explorer, visited, tests, seed)
    done = explored.actions[0]
    nearest = Nearest(SavedSettled(folder, AGENT), ValidConfigurations(arm))
    return dc.asdict(
        AdaptiveSpaceRun(
            robot=robot,
            space=space,
            condition=condition,
            seed=seed,
            actions=done,
            coverage=float(np.mean(nearest <= radius)),
            dispersion=float(np.mean(nearest)),
            prediction_error=error,
            tests=tested,
            tried_share=float(np.mean(explorer.tries > 0)),
            states=explorer.space.num_states,
            state_actions=explorer.space.num_state_actions,
            changes=ChangesByRule(c.rule for c in (maintenance.changes if maintenance else ())),
            robot_seconds_per_action=explored.simulated_seconds / max(done, 1),
            wall_seconds=explored.wall_seconds,
            penetrating_steps=explored.penetrating_steps,
        )
    )


# What a run learned, and what it cost: each a family of comparisons of its own. The shares'
# differences in percentage points; dispersion's (a distance in the joints' fractions of range,
# the table's unit) in hundredths of it.
_MEASURES = {
    "coverage (percentage points)": lambda r: 100 * r.coverage,
    "dispersion (hundredths of range)": lambda r: 100 * r.dispersion,
    "prediction error (percentage points)": lambda r: 100 * r.prediction_error,
    "state-actions tried (percentage points)": lambda r: 100 * r.tried_share,
}
_COSTS = {
    "robot s per action": lambda r: r.robot_seconds_per_action,
    "wall s per run": lambda r: r.wall_seconds,
}


# A run's setting, its condition last.
_SETTING = ("robot", "space", "condition")


def _Row(key: tuple, rs: list[AdaptiveSpaceRun]) -> str:
    return (
        f"| {' | '.join(key)} | {len(rs)} | {np.mean([r.actions for r in rs]):.0f} | "
        f"{100 * np.mean([r.coverage for r in rs]):.1f} % | "
        f"{np.mean([r.dispersion for r in rs]):.3f} | "
        f"{np.nanmean([r.prediction_error for r in rs]):.3f} "
        f"({np.mean([r.tests for r in rs]):.0f}) | "
        f"{100 * np.mean([r.tried_share for r in rs]):.0f} % | "
        f"{np.mean([r.states for r in rs]):.0f} | "
        f"{np.mean([r.state_actions for r in rs]):.0f} | {ChangesCell(rs)} | "
        f"{np.mean([r.robot_seconds_per_action for r in rs]):.2f} | "
        f"{sum(r.penetrating_steps for r in rs)} | "
        f"{np.mean([r.wall_seconds for r in rs]):.0f} |"
    )


def Report(runs: list[AdaptiveSpaceRun], roadmaps: dict[str, dict], command: str) -> str:
    """The report's table, the trm spaces' roadmaps (``roadmaps``: per robot, its roadmap
    job's result) and the paired comparisons (markdown)."""
    group = BySetting(runs, _SETTING)
    lines = [
        "| robot | space | condition | runs | actions | coverage | dispersion "
        "| prediction error (tests) | state-actions tried | states | state-actions "
        f"| changes ({'/'.join(RULES)}) | robot s per action | penetrating periods "
        "| wall s per run |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|",
        *(_Row(key, rs) for key, rs in group.items()),
    ]
    lines += RoadmapLines(roadmaps)
    lines += SpaceComparisons(group, "rank4", _MEASURES, "what was learned")
    lines += SpaceComparisons(group, "rank4", _COSTS, "what it cost")
    return "\n".join(lines) + f"\n\nCommand: `{command}`."


def _AddMaintenanceArguments(maintenance) -> None:
    """The maintenance's options (an argument group)."""
    maintenance.add_argument(
        "--every",
        type=PositiveInt,
        default=MaintenanceConfig().every,
        help="actions (exploration) or problem-tries (reaching) between rounds",
    )
    maintenance.add_argument(
        "--rules",
        nargs="+",
        choices=RULES,
        help=f"the rules (exploration: {' '.join(MaintenanceConfig().rules)}; reaching: all)",
    )
    maintenance.add_argument(
        "--prune-after",
        type=PositiveInt,
        default=MaintenanceConfig().prune_after,
        help="tries into a state, none arriving, before it is pruned",
    )
    maintenance.add_argument(
        "--develop-min-targets",
        type=PositiveInt,
        default=MaintenanceConfig().develop_min_targets,
        help="develop: the different targets a state's reach needs records of to be favoured",
    )
    maintenance.add_argument(
        "--max-states",
        type=PositiveInt,
        default=None,
        help="the space grows while it has fewer states than this (default: no limit)",
    )


def _Parser() -> CommandParser:
    parser = CommandParser(
        prog="mobee-drake experiment adaptive-space", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument(
        "--part",
        choices=("exploration", "reaching"),
        default="exploration",
        help="the curious agent of ch. 7 (this module) or the reach learner of ch. 8 "
        "(mobee_drake.experiments.adaptive_space_reaching)",
    )
    parser.add_argument("--seeds", type=PositiveInt, default=10, help="runs per setting")
    parser.add_argument(
        "--robots",
        nargs="+",
        choices=tuple(Arms()),
        default=["icub"],
        help="the arms (mobee_drake.experiments.arms)",
    )
    exploration = parser.add_argument_group("exploration (ch. 7)")
    exploration.add_argument("--spaces", nargs="+", choices=SPACES, default=list(SPACES))
    exploration.add_argument(
        "--trm-spacing",
        type=PositiveFloat,
        default=0.45,
        help="the trm space: its roadmap's spacing d (fractions of range; 0.45 grows 285 "
        "vertices on the iCub's arm unbounded)",
    )
    exploration.add_argument(
        "--trm-states",
        type=PositiveInt,
        default=len(Lattice(LATTICES["rank4"], 4).centres),  # (both arms move 4 joints)
        help="the trm space: at most this many states (the rank-4 lattice's number, by default)",
    )
    exploration.add_argument("--actions", type=PositiveInt, default=2000, help="per run")
    exploration.add_argument("--tests", type=PositiveInt, default=60, help="held-out, per run")
    exploration.add_argument(
        "--radius",
        type=PositiveFloat,
        default=0.125,
        help="coverage: a valid configuration this near (fractions of range) a configuration "
        "in which an action ended counts as covered",
    )
    reaching_part.AddArguments(parser.add_argument_group("reaching (ch. 8)"))
    _AddMaintenanceArguments(parser.add_argument_group("maintenance"))
    parser.add_argument(
        "--output", help="the battery folder (results/adaptive_space[_reaching] by default)"
    )
    parser.add_argument(
        "--doc",
        help="a doc whose generated block 'adaptive-space' ('adaptive-space-reaching') gets "
        "the report",
    )
    parser.add_argument(
        "--report-only",
        action="store_true",
        help="run nothing: the report of the runs in --output that have finished",
    )
    AddBackendArguments(parser)
    return parser


def _InitialCentres(arm: Arm, robot: str, space: str, output: pathlib.Path) -> np.ndarray:
    """The centres a run's space began with (fractions of range)."""
    if space in LATTICES:
        return Lattice(LATTICES[space], len(arm.joints)).centres
    return RoadmapSpace(arm, RoadmapFolder(output / "runs", robot)).centres


def SpaceHistories(runs: list[AdaptiveSpaceRun], output: pathlib.Path) -> dict[str, list]:
    """Per robot, the history of its first seed's maintained run on each space."""
    arms, histories = Arms(), collections.defaultdict(list)
    for (robot, space, condition), rs in BySetting(runs, _SETTING).items():
        if condition != "maintained":
            continue
        run = output / "runs" / f"{robot}_{space}_maintained_seed{rs[0].seed}" / "model"
        changes = SpaceChanges(run, AGENT)
        initial = _InitialCentres(arms[robot], robot, space, output)
        histories[robot].append(History(f"{robot}, {space}", arms[robot], initial, changes))
    return dict(histories)


def SpaceChanges(checkpoint: pathlib.Path, name: str) -> list[dict]:
    """A maintained run's changes of its space (as dicts): the maintenance saved in the newest
    generation of its ``checkpoint`` folder (or the folder itself) as ``name``.json/.npz."""
    maintenance = SavedMaintenance(str(checkpoint), name, MaintenanceConfig())
    return [dc.asdict(c) for c in maintenance.changes] if maintenance else []


def _Results(
    args, jobs: list[Job], output: pathlib.Path, description: str, kept: bool
) -> dict[str, dict]:
    """The jobs' results: those missing run first, or with ``--report-only`` the finished ones
    alone; ``kept``: the finished ones read without the folder's lock (see :func:`KeptReport`)."""
    if kept:
        return FinishedResults(jobs, output)
    if not args.report_only:
        return RunBattery(jobs, output, backend=BackendOf(args), description=description)
    with OwnedFolder(output, "battery"):
        return FinishedResults(jobs, output)


def _ExplorationReport(
    args, maintenance: MaintenanceConfig, output: pathlib.Path, command: str, kept: bool = False
):
    """Runs the exploration part's battery; its report (``kept``: :func:`KeptReport`'s)."""
    built = {}
    if "trm" in args.spaces:  # (the roadmaps first: the trm runs read them)
        roadmaps = [RoadmapJobOf(r, args.trm_spacing, args.trm_states) for r in args.robots]
        built = _Results(args, roadmaps, output, "trm spaces", kept)
        built = {r: built[RoadmapJobName(r)] for r in args.robots if RoadmapJobName(r) in built}
    jobs = [
        Job(
            f"{robot}_{space}_{condition}_seed{seed}",
            AdaptiveSpaceJob,
            dict(
                robot=robot,
                space=space,
                condition=condition,
                seed=seed,
                actions=args.actions,
                tests=args.tests,
                radius=args.radius,
                maintenance=maintenance,
            ),
            total=args.actions,
        )
        for seed in range(args.seeds)
        for robot in args.robots
        for space in args.spaces
        for condition in CONDITIONS
    ]
    results = _Results(args, jobs, output, "adaptive space", kept)
    runs = [AdaptiveSpaceRun(**r) for r in results.values()]
    report = Report(runs, built, command)
    if kept:
        return report
    with OwnedFolder(output, "battery"):
        figures = WriteSpaceFigures(SpaceHistories(runs, output), output, "adaptive_space")
    if figures:
        report += f"\n\nFigures (the first seed's maintained runs): {', '.join(figures)}."
    return report


def _ReachingReport(
    args, maintenance: MaintenanceConfig, output: pathlib.Path, command: str, kept: bool = False
):
    """Runs the reaching part's battery, stage by stage; its report (``kept``:
    :func:`KeptReport`'s)."""
    results = {}
    for description, jobs in reaching_part.Stages(args, maintenance):
        results.update(_Results(args, jobs, output, description, kept))
    runs = [
        reaching_part.AdaptiveReachRun(**r) for n, r in results.items() if n.startswith("reach_")
    ]
    roadmaps = {r: results[RoadmapJobName(r)] for r in args.robots if RoadmapJobName(r) in results}
    mdps = {
        f"{robot} {space}": results[name]
        for robot in args.robots
        for space in args.reach_spaces
        if (name := MdpName(reaching_part.MDP_TRIES, robot=robot, space=space)) in results
    }
    arms, targets = Arms(), {}
    for robot in args.robots:
        targets[robot] = (ReachTargets(arms[robot]), {}, {})
        for space in args.reach_spaces:
            centres = _ReachCentres(arms[robot], robot, space, output)
            if centres is not None:
                targets[robot][1][space] = TargetGaps(arms[robot], centres)
            targets[robot][2][space] = [
                TargetGaps(arms[robot], ended) for ended in EndedSpaces(runs, output, robot, space)
            ]
    report = reaching_part.Report(runs, command, targets, roadmaps, mdps)
    if kept:
        return report
    with OwnedFolder(output, "battery"):
        histories = ReachSpaceHistories(runs, output)
        figures = WriteSpaceFigures(histories, output, "adaptive_space_reaching")
    if figures:
        report += (
            "\n\nFigures (each space's first seed's maintained run, of the intrinsic strategy "
            f"where it ran): {', '.join(figures)}."
        )
    return report


def EndedSpaces(runs: list, output: pathlib.Path, robot: str, space: str) -> list[np.ndarray]:
    """The centres of the space each maintained run of ``robot`` that began on ``space`` ended
    with (its checkpoint's; fractions of range)."""
    ended = []
    for r in runs:
        if (r.robot, r.space, r.condition) == (robot, space, "maintained"):
            name = reaching_part.RunName(robot, space, r.strategy, "maintained", r.seed)
            generation = CurrentGeneration(output / "runs" / name / "checkpoint")
            with np.load(generation / "learner.npz") as saved:
                ended.append(saved["space_centres"])
    return ended


def ReachSpaceHistories(runs: list, output: pathlib.Path) -> dict[str, list]:
    """Per robot, the history of each space's first seed's maintained run of the intrinsic
    strategy (where it ran; of the first strategy else), with the arm's targets."""
    arms, histories = Arms(), collections.defaultdict(list)
    maintained = collections.defaultdict(list)
    for r in runs:
        if r.condition == "maintained":
            maintained[(r.robot, r.space)].append(r)
    for (robot, space), rs in sorted(maintained.items()):
        strategies = sorted({r.strategy for r in rs})
        strategy = "intrinsic" if "intrinsic" in strategies else strategies[0]
        seed = min(r.seed for r in rs if r.strategy == strategy)
        name = reaching_part.RunName(robot, space, strategy, "maintained", seed)
        initial = _ReachCentres(arms[robot], robot, space, output)
        if initial is None:  # (its roadmap is not there: nothing to draw it from)
            continue
        changes = SpaceChanges(output / "runs" / name / "checkpoint", "learner")
        title = f"{robot}, {space}, {strategy}"
        histories[robot].append(
            History(title, arms[robot], initial, changes, ReachTargets(arms[robot]))
        )
    return dict(histories)


def _ReachCentres(arm: Arm, robot: str, space: str, output: pathlib.Path):
    """The centres the reaching part's ``space`` begins with (fractions of range; its rank-3
    lattice is ch. 8's); None for a roadmap not yet built."""
    built = RoadmapFolder(output / "runs", robot).is_dir()
    return _InitialCentres(arm, robot, space, output) if space in LATTICES or built else None


_BLOCKS = {"exploration": "adaptive-space", "reaching": "adaptive-space-reaching"}
_REPORTS = {"exploration": _ExplorationReport, "reaching": _ReachingReport}


def _Maintenance(parser, args) -> MaintenanceConfig:
    """The rounds' configuration the arguments give (the rules by default each part's)."""
    exploring = args.part == "exploration"
    rules = args.rules or (MaintenanceConfig().rules if exploring else list(RULES))
    if exploring and "develop" in rules:
        parser.error(
            "--rules develop: the exploration part's agent favours no states "
            "(the rule is the reach learner's: --part reaching)"
        )
    return MaintenanceConfig(
        every=args.every,
        rules=list(rules),
        prune_after=args.prune_after,
        develop_min_targets=args.develop_min_targets,
        max_states=args.max_states or 0,
    )


def _Output(args) -> pathlib.Path:
    default = "results/adaptive_space" + ("" if args.part == "exploration" else "_reaching")
    return pathlib.Path(args.output or default)


def KeptReport(command: str, root: pathlib.Path) -> str:
    """The report that ``command`` (a ``--report-only`` command as a doc's generated block
    names it, its paths relative to ``root``) gives from the runs finished in its folder now,
    without its figures' line: read without the folder's lock, writing nothing
    (tests/test_doc_results.py holds the docs to it)."""
    parser = _Parser()
    args = parser.parse_args(shlex.split(command)[3:])  # (after "mobee-drake experiment ...")
    output = root / _Output(args)
    return _REPORTS[args.part](args, _Maintenance(parser, args), output, command, kept=True)


def main(argv: list[str] | None = None) -> None:
    parser = _Parser()
    args = parser.parse_args(argv)
    block = _BLOCKS[args.part]
    CheckDocBlocks(parser, args.doc, block)
    maintenance = _Maintenance(parser, args)
    output = _Output(args)
    if args.report_only and not any(output.glob("runs/*/result.json")):
        parser.error(f"--report-only: no finished runs in {output / 'runs'}")
    command = ("mobee-drake experiment adaptive-space " + shlex.join(argv or [])).strip()
    report = _REPORTS[args.part](args, maintenance, output, command)
    with OwnedFolder(output, "battery"):
        (output / "report.md").write_text(report + "\n")
    if args.doc:
        WriteGeneratedTable(args.doc, block, command, report)
    print(report)


if __name__ == "__main__":
    main()
