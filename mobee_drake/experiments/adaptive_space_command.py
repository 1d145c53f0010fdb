"""``mobee-drake experiment adaptive-space``: the battery of a state-action space that reshapes
itself (ch. 9.4.5; docs/adaptive_space.md), its two parts' stages, reports and figures.

The exploration part's runs and report are :mod:`mobee_drake.experiments.adaptive_space`, the
reaching part's (``--part reaching``) :mod:`mobee_drake.experiments.adaptive_space_reaching`;
this module builds their jobs, runs them in order (the roadmaps first, then for the reach
learner the MDPs, then the runs), writes the report (``report.md`` in ``--output``, and the
generated block of ``--doc``) and names a PNG and, per arm, a Meshcat scene of the first
finished seed's maintained runs (:mod:`mobee_drake.experiments.adaptive_space_figures`). With
``--fixed-from``, a reaching battery reads its fixed runs from another's folder.
:func:`KeptReport` gives what a kept battery's ``--report-only`` reports now, for the tests
that hold the docs to it.

Run: ``mobee-drake experiment adaptive-space [--robots icub katana] [--seeds 10] [--actions 2000]
[--output results/adaptive_space] [--doc docs/adaptive_space.md]``.
"""

import collections
import dataclasses as dc
import pathlib
import shlex

import numpy as np

from mobee_drake.atomic_files import CurrentGeneration
from mobee_drake.experiments import adaptive_space_reaching as reaching_part
from mobee_drake.experiments.adaptive_space import (
    AGENT,
    LATTICES,
    SETTING,
    SPACES,
    AdaptiveSpaceJob,
    AdaptiveSpaceRun,
    Nearest,
    Report,
)
from mobee_drake.experiments.adaptive_space_figures import History, WriteSpaceFigures
from mobee_drake.experiments.adaptive_space_report import CONDITIONS, BySetting
from mobee_drake.experiments.arguments import CommandParser, PositiveFloat, PositiveInt
from mobee_drake.experiments.arms import (
    Arm,
    Arms,
    ReachTargets,
    RoadmapFolder,
    RoadmapJobName,
    RoadmapJobOf,
    RoadmapSpace,
    TargetGaps,
    ValidConfigurations,
)
from mobee_drake.experiments.battery import (
    AddBackendArguments,
    BackendOf,
    BatteryRefused,
    CopySharedRuns,
    FinishedResults,
    Job,
    RunBattery,
    SharedResults,
)
from mobee_drake.experiments.ch8_reaching import MdpName
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.owned_folders import OwnedFolder
from mobee_drake.planning.space_maintenance import RULES, MaintenanceConfig
from mobee_drake.planning.state_space import Lattice
from mobee_drake.planning.supervisor import SavedMaintenance


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
    maintenance.add_argument(
        "--join-within",
        type=PositiveFloat,
        default=MaintenanceConfig().join_within,
        help="grow, develop: a new state is joined to every state within this share of the "
        "length of the action it grew from (at least 0.5, the action's ends)",
    )


def _Parser() -> CommandParser:
    parser = CommandParser(
        prog="mobee-drake experiment adaptive-space", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument(
        "--part",
        choices=("exploration", "reaching"),
        default="exploration",
        help="the curious agent of ch. 7 (mobee_drake.experiments.adaptive_space) or the reach "
        "learner of ch. 8 "
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
    parser.add_argument("--doc", help="a doc whose generated block (--doc-table) gets the report")
    parser.add_argument(
        "--doc-table",
        help="the name of --doc's generated block (by default 'adaptive-space', with --part "
        "reaching 'adaptive-space-reaching'; another for a side battery's report)",
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
    for (robot, space, condition), rs in BySetting(runs, SETTING).items():
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
    report = Report(runs, built, command, _Nearness(args.robots, args.spaces, output))
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
    """Runs the reaching part's battery, stage by stage (with ``--fixed-from``, the fixed runs
    read from that battery's folder: :func:`_SharedRuns`); its report (``kept``:
    :func:`KeptReport`'s)."""
    stages = reaching_part.Stages(args, maintenance)
    fixed = reaching_part.FixedRuns(args, maintenance) if args.fixed_from else []
    results = _SharedRuns(args, stages, fixed, output, kept) if fixed else {}
    for description, jobs in stages:
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
            centres = _BuiltCentres(arms[robot], robot, space, output)
            if centres is not None:
                targets[robot][1][space] = TargetGaps(arms[robot], centres)
            targets[robot][2][space] = {
                strategy: [TargetGaps(arms[robot], centres) for centres in ended]
                for strategy, ended in EndedSpaces(runs, output, robot, space).items()
            }
    nearness = _Nearness(args.robots, args.reach_spaces, output)
    run_jobs = [job for _, jobs in stages for job in jobs if job.name.startswith("reach_")]
    run_jobs += fixed
    missing = reaching_part.MissingRuns(run_jobs, results)
    report = reaching_part.Report(
        runs, command, targets, roadmaps, mdps, nearness, missing, args.fixed_from
    )
    if kept:
        return report
    with OwnedFolder(output, "battery"):
        histories = ReachSpaceHistories(runs, output)
        figures = WriteSpaceFigures(histories, output, "adaptive_space_reaching")
    if figures:
        report += (
            "\n\nFigures (each space's first finished seed's maintained run, of the intrinsic "
            f"strategy where it ran): {', '.join(figures)}."
        )
    return report


def _SharedRuns(args, stages: list, fixed: list[Job], output: pathlib.Path, kept: bool) -> dict:
    """The results of the ``fixed`` runs finished in ``--fixed-from``'s folder, read before
    anything runs (a folder of other arguments, or of none of them, is refused); unless only
    reporting, the roadmaps and MDPs made there are copied here first (where this battery has
    none of its own), so that its maintained runs read the very files the fixed ones did."""
    source = args.fixed_from_folder
    shared = SharedResults(fixed, source, "maintenance")
    if not shared:
        raise BatteryRefused(
            f"{source}: none of the {len(fixed)} fixed runs is finished there (--fixed-from)"
        )
    if not (kept or args.report_only):
        support = [job for _, jobs in stages for job in jobs if not job.name.startswith("reach_")]
        with OwnedFolder(output, "battery"):
            CopySharedRuns(support, source, output)
    return shared


def EndedSpaces(
    runs: list, output: pathlib.Path, robot: str, space: str
) -> dict[str, list[np.ndarray]]:
    """Per strategy, the centres of the space each maintained run of ``robot`` that began on
    ``space`` ended with (its checkpoint's; fractions of range), by seed."""
    ended = collections.defaultdict(list)
    for r in sorted(runs, key=lambda r: (r.strategy, r.seed)):
        if (r.robot, r.space, r.condition) == (robot, space, "maintained"):
            name = reaching_part.RunName(robot, space, r.strategy, "maintained", r.seed)
            generation = CurrentGeneration(output / "runs" / name / "checkpoint")
            with np.load(generation / "learner.npz") as saved:
                ended[r.strategy].append(saved["space_centres"])
    return dict(ended)


def ReachSpaceHistories(runs: list, output: pathlib.Path) -> dict[str, list]:
    """Per robot, the history of each space's first finished seed's maintained run of the
    intrinsic strategy (where it ran; of the first strategy else), with the arm's targets."""
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
        initial = _BuiltCentres(arms[robot], robot, space, output)
        if initial is None:  # (its roadmap is not there: nothing to draw it from)
            continue
        changes = SpaceChanges(output / "runs" / name / "checkpoint", "learner")
        title = f"{robot}, {space}, {strategy}, seed {seed}"
        histories[robot].append(
            History(title, arms[robot], initial, changes, ReachTargets(arms[robot]))
        )
    return dict(histories)


def _BuiltCentres(arm: Arm, robot: str, space: str, output: pathlib.Path):
    """The centres ``space`` begins with (fractions of range; the rank-3 lattice is ch. 8's);
    None for a roadmap not yet built."""
    built = RoadmapFolder(output / "runs", robot).is_dir()
    return _InitialCentres(arm, robot, space, output) if space in LATTICES or built else None


def _Nearness(robots: list[str], spaces: list[str], output: pathlib.Path) -> dict:
    """Per robot and space (those built), the mean distance from the arm's valid
    configurations to the nearest of the space's initial states (fractions of range)."""
    arms, nearness = Arms(), {}
    for robot in robots:
        valid = ValidConfigurations(arms[robot])
        for space in spaces:
            centres = _BuiltCentres(arms[robot], robot, space, output)
            if centres is not None:
                nearness.setdefault(robot, {})[space] = float(np.mean(Nearest(centres, valid)))
    return nearness


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
    config = MaintenanceConfig(
        every=args.every,
        rules=list(rules),
        prune_after=args.prune_after,
        develop_min_targets=args.develop_min_targets,
        max_states=args.max_states or 0,
        join_within=args.join_within,
    )
    for error in config.Errors():
        parser.error(f"maintenance: {error}")
    return config


def _Output(args) -> pathlib.Path:
    default = "results/adaptive_space" + ("" if args.part == "exploration" else "_reaching")
    return pathlib.Path(args.output or default)


def _CheckFixedFrom(parser, args, output: pathlib.Path) -> None:
    """Refuses a ``--fixed-from`` that cannot give this battery its fixed runs."""
    if args.part != "reaching":
        parser.error("--fixed-from: only with --part reaching")
    if not (args.fixed_from / "runs").is_dir():
        parser.error(f"--fixed-from: no battery's runs in {args.fixed_from}")
    if args.fixed_from.resolve() == output.resolve():
        parser.error(f"--fixed-from: {args.fixed_from} is this battery's own folder (--output)")


def KeptReport(command: str, root: pathlib.Path) -> str:
    """The report that ``command`` (a ``--report-only`` command as a doc's generated block
    names it, its paths relative to ``root``) gives from the runs finished in its folder now,
    without its figures' line: read without the folder's lock, writing nothing
    (tests/test_doc_results.py holds the docs to it)."""
    parser = _Parser()
    args = parser.parse_args(shlex.split(command)[3:])  # (after "mobee-drake experiment ...")
    output = root / _Output(args)
    args.fixed_from_folder = args.fixed_from and root / args.fixed_from
    return _REPORTS[args.part](args, _Maintenance(parser, args), output, command, kept=True)


def main(argv: list[str] | None = None) -> None:
    parser = _Parser()
    args = parser.parse_args(argv)
    if args.doc_table and not args.doc:
        parser.error("--doc-table: no --doc to write it in")
    block = args.doc_table or _BLOCKS[args.part]
    CheckDocBlocks(parser, args.doc, block)
    maintenance = _Maintenance(parser, args)
    output = _Output(args)
    args.fixed_from_folder = args.fixed_from  # (KeptReport's is under its root)
    if args.fixed_from:
        _CheckFixedFrom(parser, args, output)
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
