"""Experiment, ch. 8 part: the reach learner on a fixed and on a self-reshaping space (ch. 9.4.5;
docs/adaptive_space.md).

Each strategy of ch. 8 learns to reach with an arm (``--robots``:
:mod:`~mobee_drake.experiments.arms`, the iCub's right arm and the source's targets, or the
Katana's first four joints, wrist and targets) for ``--problem-tries`` problem-tries, starting
on a space of ``--reach-spaces``: ch. 8's rank-3 lattice (``rank3``) or a task-relevant roadmap
over the arm's valid configurations with at most the lattice's 81 states (``trm``, spacing
``--reach-trm-spacing``, built once per arm by the battery's job ``<robot>_roadmap``). On each,
the space stays as it is (``fixed``) or is maintained by the rules of
:mod:`mobee_drake.planning.space_maintenance` (``maintained``, a round every ``--every``
problem-tries; the learner's favoured states, its best reaches, are developed), ``--seeds`` runs
of each, paired by seed. The MDP of each space is learned first (5 tries of every state-action,
as ch. 8) and learned further with the reaches (``continued``, ch. 9.4.1): a new transition
starts with Alg. 6's optimistic counts and is learned like the rest, so fixed and maintained
differ by the maintenance only. With ``--mdp simultaneous`` no MDP is learned first (the smoke
runs' setting).

Per run, at the last stage: the evaluations' summed reward (ch. 8.3.3, with the -10 of every
failed transition and without), the robot's simulated hours (in all, and of the exploration
alone: an evaluation's walk to its start depends on the space), the space's size and its
changes, and the penetrating periods (:mod:`~mobee_drake.reaching.appearance`'s split).
Maintained minus fixed on each space, and the roadmap, fixed and maintained, minus the fixed
lattice, are compared paired by seed in two families, each Holm-corrected over its comparisons
(the robots, spaces and strategies): what was learned (the summed reward, with the -10s and
without; where the two are the same in every run, the second is not tested again) and what it
cost (the robot hours of the exploration; wall time, made over many sittings, is reported but
not compared)."""

import collections
import dataclasses as dc
import pathlib

import numpy as np

from mobee_drake.experiments.adaptive_space_report import (
    CONDITIONS,
    BySetting,
    ChangesCell,
    NearnessLines,
    SpaceComparisons,
)
from mobee_drake.experiments.arguments import PositiveFloat, PositiveInt
from mobee_drake.experiments.arms import RoadmapFolder, RoadmapJobOf, RoadmapLines
from mobee_drake.experiments.battery import Job, RunFolder, StopRequested
from mobee_drake.experiments.ch8_figures import EvaluationSum
from mobee_drake.experiments.ch8_measures import PENETRATION_HEADER, PenetrationCell
from mobee_drake.experiments.ch8_reaching import (
    LEVELS,
    MdpJob,
    MdpName,
    ReachRun,
    RunOne,
    RunSettings,
)
from mobee_drake.experiments.statistics import RunMeans
from mobee_drake.planning.space_maintenance import RULES, MaintenanceConfig
from mobee_drake.planning.state_space import Lattice

STRATEGIES = ("greedy", "intrinsic", "random")
MDP_TRIES = 5
# The spaces a run starts on: ch. 8's rank-3 lattice, and "trm", a roadmap over the arm's valid
# configurations with at most the lattice's number of states (built by the battery's job
# arms.RoadmapJobName(robot); mobee_drake.trm.configuration).
SPACES = ("rank3", "trm")
TRM_STATES = len(Lattice(LEVELS, 4).centres)


@dc.dataclass
class AdaptiveReachRun:
    """One reach-learning run: an arm, a space, a strategy, fixed or maintained, a seed (see the
    module)."""

    strategy: str
    condition: str
    seed: int
    stage: int
    reward: float
    reward_without_penalties: float
    robot_hours: float
    states: int
    transitions: int
    changes: dict[str, int]
    penetrating_steps: int
    wall_seconds: float
    robot: str = "icub"  # (the battery's first runs were the iCub's, without the field)
    # (see ReachRun; None: a run from before they were counted)
    appeared_inside: int | None = None
    other_penetrating_steps: int | None = None
    space: str = "rank3"  # (the battery's first runs were the lattice's, without the field)
    # The robot hours of the exploration alone, without the evaluations' (None: a run from
    # before they were timed).
    exploring_hours: float | None = None
    # The closest the robot's solids came to each other and the deepest penetration of any
    # pair (m; see ReachRun; None: a run from before they were kept).
    closest_to_itself: float | None = None
    deepest_penetration: float | None = None


def AdaptiveReachJob(
    run: RunFolder, *, strategy: str, condition: str, seed: int, problem_tries: int,
    stages: list[int], evaluations: int, mdp: str, maintenance: MaintenanceConfig,
    robot: str = "icub", space: str = "rank3",
) -> dict:  # fmt: skip
    """The battery job: one run on ``robot``, an arm of
    :func:`~mobee_drake.experiments.arms.Arms`, starting on ``space`` (see the module)."""
    settings = RunSettings(
        strategy=strategy,
        seed=seed,
        problem_tries=problem_tries,
        stages=stages,
        evaluations=evaluations,
        checkpoint_every=50,
        mdp=mdp,
    )
    result = ReachRun.FromJson(
        RunOne(
            run.path,
            run.path.parent / MdpName(MDP_TRIES, robot=robot, space=space) / "model",
            settings,
            progress=run.Progress,
            should_stop=StopRequested,
            maintenance=maintenance if condition == "maintained" else None,
            robot=robot,
            roadmap=str(RoadmapFolder(run.path.parent, robot)) if space == "trm" else "",
        )
    )
    stage = max(result.evaluations)
    sums = [
        RunMeans([[EvaluationSum(e, penalties) for e in result.evaluations[stage]]])[0]
        for penalties in (True, False)
    ]
    ended = result.space or dict(
        states=result.num_states, transitions=result.num_transitions, changes={}
    )
    return dc.asdict(
        AdaptiveReachRun(
            robot=robot,
            space=space,
            strategy=strategy,
            condition=condition,
            seed=seed,
            stage=stage,
            reward=float(sums[0]),
            reward_without_penalties=float(sums[1]),
            robot_hours=result.simulated_seconds / 3600,
            exploring_hours=None
            if result.evaluation_seconds is None
            else (result.simulated_seconds - result.evaluation_seconds) / 3600,
            states=ended["states"],
            transitions=ended["transitions"],
            changes={rule: ended["changes"].get(rule, 0) for rule in RULES},
            penetrating_steps=result.penetrating_steps,
            appeared_inside=result.appeared_inside,
            other_penetrating_steps=result.other_penetrating_steps,
            closest_to_itself=result.closest_to_itself,
            deepest_penetration=result.deepest_penetration,
            wall_seconds=result.wall_seconds,
        )
    )


def AddArguments(reaching) -> None:
    """The reaching part's options (an argument group of ``adaptive-space``'s parser)."""
    reaching.add_argument("--strategies", nargs="+", choices=STRATEGIES, default=list(STRATEGIES))
    reaching.add_argument("--problem-tries", type=PositiveInt, default=1600, help="per run")
    reaching.add_argument(
        "--reach-spaces",
        nargs="+",
        choices=SPACES,
        default=list(SPACES),
        help="the spaces the runs start on: the rank-3 lattice and a roadmap over the valid "
        f"configurations of at most its {TRM_STATES} states",
    )
    reaching.add_argument(
        "--reach-trm-spacing",
        type=PositiveFloat,
        default=0.7,
        help="the reaching part's trm space: its roadmap's spacing d (fractions of range; 0.7 "
        "grows 80 vertices on either arm unbounded)",
    )
    reaching.add_argument(
        "--stages", type=PositiveInt, nargs="+", default=[100, 400, 1600], help="evaluated at"
    )
    reaching.add_argument("--evaluations", type=PositiveInt, default=5, help="per stage")
    reaching.add_argument(
        "--mdp",
        choices=("continued", "simultaneous"),
        default="continued",
        help="the MDP learned first and further with the reaches, or only with them",
    )
    reaching.add_argument(
        "--fixed-from",
        metavar="FOLDER",
        type=pathlib.Path,
        help="read the fixed runs from this battery's folder (their jobs the same but for the "
        "maintenance settings, which a fixed run does not use) rather than make them again",
    )


def Stages(args, maintenance: MaintenanceConfig) -> list[tuple[str, list[Job]]]:
    """The battery's jobs in the order they must finish, each stage (its description, its
    jobs) before the next begins: the "trm" spaces' roadmaps, the MDPs learned first on each
    space (unless ``--mdp simultaneous``), then the runs, seed by seed (with ``--fixed-from``
    the maintained ones alone: :func:`FixedRuns`). The iCub's lattice jobs keep the names and
    arguments they had before there was a choice of robot or space."""
    roadmaps, mdps, runs = [], [], []
    for robot in args.robots:
        if "trm" in args.reach_spaces:
            roadmaps.append(RoadmapJobOf(robot, args.reach_trm_spacing, TRM_STATES))
        for space in args.reach_spaces:
            if args.mdp != "simultaneous":
                mdp = dict(min_tries=MDP_TRIES) | ({} if robot == "icub" else dict(robot=robot))
                if space != "rank3":
                    mdp["space"] = space
                name = MdpName(MDP_TRIES, robot=robot, space=space)
                mdps.append(Job(name, MdpJob, mdp))
            conditions = ("maintained",) if args.fixed_from else CONDITIONS
            runs += _RunJobs(args, maintenance, robot, space, conditions)
    # Seed-major: a battery stopped early has about as many seeds of every setting.
    runs.sort(key=lambda job: job.kwargs["seed"])
    stages = [("trm spaces", roadmaps), ("the MDPs (actions)", mdps), ("adaptive reaching", runs)]
    return [(description, jobs) for description, jobs in stages if jobs]


def FixedRuns(args, maintenance: MaintenanceConfig) -> list[Job]:
    """The fixed runs that ``--fixed-from`` reads from another battery's folder."""
    return [
        job
        for robot in args.robots
        for space in args.reach_spaces
        for job in _RunJobs(args, maintenance, robot, space, ("fixed",))
    ]


def RunName(robot: str, space: str, strategy: str, condition: str, seed: int) -> str:
    """A run's job (and folder) name: the iCub's and the lattice's are left out of it (the
    battery's first runs were theirs)."""
    parts = ["reach"] + [robot] * (robot != "icub") + [space] * (space != "rank3")
    return "_".join([*parts, strategy, condition, f"seed{seed}"])


def _RunJobs(
    args, maintenance: MaintenanceConfig, robot: str, space: str, conditions: tuple[str, ...]
) -> list[Job]:
    stages = sorted({*args.stages, args.problem_tries})
    named = {} if robot == "icub" else dict(robot=robot)
    if space != "rank3":
        named |= dict(space=space)
    return [
        Job(
            RunName(robot, space, strategy, condition, seed),
            AdaptiveReachJob,
            dict(
                strategy=strategy,
                condition=condition,
                seed=seed,
                problem_tries=args.problem_tries,
                stages=stages,
                evaluations=args.evaluations,
                mdp=args.mdp,
                maintenance=maintenance,
                **named,
            ),
            total=args.problem_tries,
        )
        for seed in range(args.seeds)
        for strategy in args.strategies
        for condition in conditions
    ]


def MissingRuns(jobs: list[Job], results: dict) -> dict[tuple, list[int]]:
    """Per setting (robot, space, strategy, condition), the seeds of ``jobs`` without a
    result in ``results`` (failed, or not finished)."""
    missing = collections.defaultdict(list)
    for job in jobs:
        if job.name not in results:
            kwargs = job.kwargs
            setting = (kwargs.get("robot", "icub"), kwargs.get("space", "rank3"))
            missing[(*setting, kwargs["strategy"], kwargs["condition"])].append(kwargs["seed"])
    return dict(missing)


def _MissingLines(missing: dict[tuple, list[int]]) -> list[str]:
    """Report lines naming the runs without a result, by setting (:func:`MissingRuns`)."""
    if not missing:
        return []
    named = "; ".join(
        f"{' '.join(setting)} seed{'s' * (len(seeds) > 1)} {', '.join(map(str, seeds))}"
        for setting, seeds in sorted(missing.items())
    )
    return [
        "",
        f"Runs without a result ({sum(map(len, missing.values()))}: failed, or not finished; "
        f"the comparisons leave out the pairs they belong to): {named}.",
    ]


def _Mean(values) -> str:
    """A cell: the mean to two places ("-" if a value is missing: runs from before it was
    measured)."""
    values = list(values)
    return "-" if any(v is None for v in values) else f"{np.mean(values):.2f}"


def _ClosestCell(runs) -> str:
    """A cell: the closest the robot came to itself over the runs ("far" if its own pairs never
    came within their fields) and the deepest penetration of any pair (mm); ``-`` where a run
    is from before they were kept."""
    if any(r.deepest_penetration is None for r in runs):
        return "-"
    closest = [r.closest_to_itself for r in runs if r.closest_to_itself is not None]
    near = f"{1000 * min(closest):+.1f}" if closest else "far"
    return f"{near} / {1000 * max(r.deepest_penetration for r in runs):.1f}"


def _GapsText(space: str, gaps: np.ndarray, ended: dict[str, list[np.ndarray]]) -> str:
    """How near a space's valid states put the marker to the targets' centres (``gaps``, m, per
    target) and, if any ran, how near the spaces the maintained runs ended with did (``ended``,
    per strategy, per run): the median over the runs of each run's median."""
    text = f"{space}, a median {100 * np.median(gaps):.1f} cm (at most {100 * gaps.max():.1f} cm)"
    if ended:
        medians = ", ".join(
            f"{strategy} {100 * np.median([np.median(g) for g in runs]):.1f} cm "
            f"({len(runs)} run{'s' * (len(runs) != 1)})"
            for strategy, runs in ended.items()
        )
        farthest = max(g.max() for runs in ended.values() for g in runs)
        text += (
            f", and on the spaces the maintained runs ended with, the median of the runs' "
            f"medians {medians} (at most {100 * farthest:.1f} cm)"
        )
    return text


def Report(
    runs: list[AdaptiveReachRun],
    command: str,
    targets: dict | None = None,
    roadmaps: dict | None = None,
    mdps: dict | None = None,
    nearness: dict | None = None,
    missing: dict | None = None,
    fixed_from: pathlib.Path | None = None,
) -> str:
    """The report's table, the "trm" spaces' roadmaps (``roadmaps``: per robot, its roadmap
    job's result), how near each space's states lie to the valid configurations
    (``nearness``, see :func:`~mobee_drake.experiments.adaptive_space_report.NearnessLines`),
    the MDPs learned first (``mdps``: per robot and space, its job's result),
    the paired comparisons and, with ``targets`` (per robot, its
    :class:`~mobee_drake.reaching.targets.TargetGrid`; per space, each target's distance to the
    nearest state's marker, :func:`~mobee_drake.experiments.arms.TargetGaps`; and per space,
    the same on the space each maintained run ended with), the targets and how near each space
    comes to them, and the runs without a result (``missing``, :func:`MissingRuns`'s); with
    ``fixed_from``, the fixed runs were read from that battery's folder, made in its sittings
    (markdown). Wall time is not compared: runs of many sittings need not share a load."""
    group = BySetting(runs, ("robot", "space", "strategy", "condition"))
    lines = [
        "| robot | space | strategy | condition | runs | problem-tries | summed reward | without "
        "the -10s | robot hours in all (exploring alone) | states | transitions | changes "
        f"({'/'.join(RULES)}) | {PENETRATION_HEADER} | closest to itself / deepest penetration "
        "of any pair (mm) | wall s per run |",
        "|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|",
    ]
    for (robot, space, strategy, condition), rs in group.items():
        lines.append(
            f"| {robot} | {space} | {strategy} | {condition} | {len(rs)} | {rs[0].stage} | "
            f"{np.mean([r.reward for r in rs]):.2f} | "
            f"{np.mean([r.reward_without_penalties for r in rs]):.2f} | "
            f"{np.mean([r.robot_hours for r in rs]):.2f} "
            f"({_Mean(r.exploring_hours for r in rs)}) | "
            f"{np.mean([r.states for r in rs]):.0f} | "
            f"{np.mean([r.transitions for r in rs]):.0f} | {ChangesCell(rs)} | "
            f"{PenetrationCell(rs)} | {_ClosestCell(rs)} | "
            f"{np.mean([r.wall_seconds for r in rs]):.0f} |"
        )
    costs = {
        "robot hours exploring": lambda r: (
            np.nan if r.exploring_hours is None else r.exploring_hours
        ),
    }
    lines += [
        "",
        "Wall time is in the table but not compared: a battery's runs are made over many "
        "sittings, beside other work and on the machine each sitting had (`sessions.jsonl`), so "
        "a pair's two runs need not have run under the same load.",
    ]
    if fixed_from:
        lines += [
            "",
            f"The fixed runs are read from {fixed_from}, not made again: made in that battery's "
            "sittings, with its code.",
        ]
    lines += _MissingLines(missing or {})
    lines += RoadmapLines(roadmaps or {}) + NearnessLines(nearness or {})
    if mdps:
        actions = "; ".join(f"{setting}, {r['actions']} actions" for setting, r in mdps.items())
        lines += [
            "",
            f"The MDPs learned first ({MDP_TRIES} tries of every state-action): {actions}.",
        ]
    # The sum without the -10s too: dropping transitions that often fail spares penalties.
    learned = {
        "summed reward": lambda r: r.reward,
        "without the -10s": lambda r: r.reward_without_penalties,
    }
    lines += SpaceComparisons(group, "rank3", learned, "what was learned")
    lines += SpaceComparisons(group, "rank3", costs, "what it cost")
    for robot, (grid, gaps, ended) in (targets or {}).items():
        levels = ", ".join(f"{axis} {'/'.join(f'{v:.2f}' for v in getattr(grid, axis))}"
                           for axis in "xyz")  # fmt: skip
        nearest = "; ".join(_GapsText(space, g, ended.get(space, {})) for space, g in gaps.items())
        lines += ["", f"{robot}: targets of radius {grid.radius:g} m at {levels} m. From each "
                  f"target's centre to the marker at the valid state nearest it (where a reach "
                  f"starts): {nearest}."]  # fmt: skip
    return "\n".join(lines) + f"\n\nCommand: `{command}`."
