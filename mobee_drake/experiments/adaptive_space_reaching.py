"""Experiment, ch. 8 part: the reach learner on a fixed and on a self-reshaping space (ch. 9.4.5;
docs/adaptive_space.md).

Each strategy of ch. 8 learns to reach with an arm (``--robots``:
:mod:`~mobee_drake.experiments.arms`, the iCub's right arm and the source's targets, or the
Katana's first four joints, wrist and targets) on the rank-3 lattice for ``--problem-tries``
problem-tries, on the space as it is (``fixed``) and on the same space maintained by the rules of
:mod:`mobee_drake.planning.space_maintenance` (``maintained``, a round every ``--every``
problem-tries; the learner's favoured states, its best reaches, are developed), ``--seeds`` runs
of each, paired by seed. In both conditions the MDP is learned first (5 tries of every
state-action, as ch. 8) and learned further with the reaches (``continued``, ch. 9.4.1): a new
transition starts with Alg. 6's optimistic counts and is learned like the rest, so the two
conditions differ by the maintenance only. With ``--mdp simultaneous`` no MDP is learned first
(the smoke run's setting).

Per run, at the last stage: the evaluations' summed reward (ch. 8.3.3, with the -10 of every
failed transition and without), the robot's simulated hours, the space's size and its changes,
and the penetrating periods. Maintained minus fixed is compared paired by seed, Holm-corrected
over the robots, the strategies and the two measures (reward with penalties, robot hours).
"""

import collections
import dataclasses as dc

import numpy as np

from mobee_drake.experiments.battery import Job, RunFolder, StopRequested
from mobee_drake.experiments.ch8_figures import EvaluationSum
from mobee_drake.experiments.ch8_measures import PENETRATION_HEADER, PenetrationCell
from mobee_drake.experiments.ch8_reaching import MdpJob, MdpName, ReachRun, RunOne, RunSettings
from mobee_drake.experiments.statistics import PairedBySeed, RunMeans
from mobee_drake.planning.space_maintenance import RULES, MaintenanceConfig

STRATEGIES = ("greedy", "intrinsic", "random")
CONDITIONS = ("fixed", "maintained")
MDP_TRIES = 5


@dc.dataclass
class AdaptiveReachRun:
    """One reach-learning run: a strategy, fixed or maintained, a seed (see the module)."""

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


def AdaptiveReachJob(
    run: RunFolder, *, strategy: str, condition: str, seed: int, problem_tries: int,
    stages: list[int], evaluations: int, mdp: str, maintenance: MaintenanceConfig,
    robot: str = "icub",
) -> dict:  # fmt: skip
    """The battery job: one run on ``robot``, an arm of
    :func:`~mobee_drake.experiments.arms.Arms` (see the module)."""
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
            run.path.parent / MdpName(MDP_TRIES, robot=robot) / "model",
            settings,
            progress=run.Progress,
            should_stop=StopRequested,
            maintenance=maintenance if condition == "maintained" else None,
            robot=robot,
        )
    )
    stage = max(result.evaluations)
    sums = [
        RunMeans([[EvaluationSum(e, penalties) for e in result.evaluations[stage]]])[0]
        for penalties in (True, False)
    ]
    space = result.space or dict(
        states=result.num_states, transitions=result.num_transitions, changes={}
    )
    return dc.asdict(
        AdaptiveReachRun(
            robot=robot,
            strategy=strategy,
            condition=condition,
            seed=seed,
            stage=stage,
            reward=float(sums[0]),
            reward_without_penalties=float(sums[1]),
            robot_hours=result.simulated_seconds / 3600,
            states=space["states"],
            transitions=space["transitions"],
            changes={rule: space["changes"].get(rule, 0) for rule in RULES},
            penetrating_steps=result.penetrating_steps,
            appeared_inside=result.appeared_inside,
            other_penetrating_steps=result.other_penetrating_steps,
            wall_seconds=result.wall_seconds,
        )
    )


def Jobs(args, maintenance: MaintenanceConfig) -> list[Job]:
    """The battery's jobs: per robot, the MDP learned first (unless ``--mdp simultaneous``),
    then every strategy's runs; the iCub's jobs keep the names and arguments they had before
    there was a choice of robot."""
    jobs = []
    for robot in args.robots:
        if args.mdp != "simultaneous":
            mdp = dict(min_tries=MDP_TRIES) | ({} if robot == "icub" else dict(robot=robot))
            jobs.append(Job(MdpName(MDP_TRIES, robot=robot), MdpJob, mdp))
        jobs += _RobotJobs(args, maintenance, robot)
    return jobs


def _RobotJobs(args, maintenance: MaintenanceConfig, robot: str) -> list[Job]:
    stages = sorted({*args.stages, args.problem_tries})
    prefix, named = ("reach", {}) if robot == "icub" else (f"reach_{robot}", dict(robot=robot))
    return [
        Job(
            f"{prefix}_{strategy}_{condition}_seed{seed}",
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
        for condition in CONDITIONS
    ]


def MaintainedMinusFixed(group: dict, keys: list[tuple], measures: dict) -> list[str]:
    """Report lines: for each key (``group``'s keys are a key and a condition), maintained
    minus fixed on each of ``measures`` (run -> value), paired by seed, Holm over them all."""
    families = {
        " ".join(key): (group.get((*key, "maintained"), []), group.get((*key, "fixed"), []))
        for key in keys
    }
    return PairedBySeed(families, measures, "Maintained minus fixed")


def Report(runs: list[AdaptiveReachRun], command: str, targets: dict | None = None) -> str:
    """The report's table, the paired comparisons and, with ``targets`` (per robot, its
    :class:`~mobee_drake.reaching.targets.TargetGrid` and each target's distance to the nearest
    state's marker, :func:`~mobee_drake.experiments.arms.TargetGaps`), the targets and how near
    the lattice comes to them (markdown)."""
    group = collections.defaultdict(list)
    for r in sorted(runs, key=lambda r: r.seed):
        group[(r.robot, r.strategy, r.condition)].append(r)
    lines = [
        "| robot | strategy | condition | runs | problem-tries | summed reward | without the -10s "
        f"| robot hours | states | transitions | changes ({'/'.join(RULES)}) "
        f"| {PENETRATION_HEADER} | wall s per run |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|",
    ]
    for (robot, strategy, condition), rs in sorted(group.items()):
        changes = "/".join(f"{np.mean([r.changes.get(c, 0) for r in rs]):.0f}" for c in RULES)
        lines.append(
            f"| {robot} | {strategy} | {condition} | {len(rs)} | {rs[0].stage} | "
            f"{np.mean([r.reward for r in rs]):.2f} | "
            f"{np.mean([r.reward_without_penalties for r in rs]):.2f} | "
            f"{np.mean([r.robot_hours for r in rs]):.2f} | "
            f"{np.mean([r.states for r in rs]):.0f} | "
            f"{np.mean([r.transitions for r in rs]):.0f} | {changes} | "
            f"{PenetrationCell(rs)} | "
            f"{np.mean([r.wall_seconds for r in rs]):.0f} |"
        )
    measures = {"summed reward": lambda r: r.reward, "robot hours": lambda r: r.robot_hours}
    keys = sorted({(r.robot, r.strategy) for r in runs})
    lines += MaintainedMinusFixed(group, keys, measures)
    for robot, (grid, gaps) in (targets or {}).items():
        levels = ", ".join(f"{axis} {'/'.join(f'{v:.2f}' for v in getattr(grid, axis))}"
                           for axis in "xyz")  # fmt: skip
        lines += ["", f"{robot}: targets of radius {grid.radius:g} m at {levels} m; the "
                  "lattice's valid state nearest each puts the marker a median "
                  f"{100 * np.median(gaps):.1f} cm (at most {100 * gaps.max():.1f} cm) from it "
                  "before the reach."]  # fmt: skip
    return "\n".join(lines) + f"\n\nCommand: `{command}`."
