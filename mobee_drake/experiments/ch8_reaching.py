"""The reach-learning battery of dissertation ch. 8.4 (Fig. 8.2, 8.4-8.8) on the kinematic iCub.

1. The MDP (ch. 8.3: the rank-3 lattice of ch. 7.2, equidistant neighbours, 81 states and 432
   state-actions over the right shoulder and elbow): a curious agent explores until every
   state-action was tried ``--mdp-tries`` times (5, as in ch. 7.2), without targets; its
   transition probabilities are then fixed.
2. For every strategy (the source's random, greedy optimistic and intrinsic by default; goal
   babbling, SAGG-RIAC choosing the targets, with ``--strategies``) and seed, a run of
   ``--problem-tries`` exploratory problem-tries (6400 in the source) on the 27 targets, with
   ``--evaluations`` exploitation evaluations (5) when the count reaches each stage (100, 200,
   400, ..., 6400), gamma 0.9. The MDP and the runs are jobs of the battery runner (``--workers``
   local processes, or ``--ray [ADDRESS]``); each run checkpoints (the learner, its evaluations
   and the simulation, atomically) every ``--checkpoint-every`` problem-tries and after every
   stage's evaluations, and resumes from its checkpoint after a kill; a progress bar per run shows
   the problem-tries done.
3. Plots like Fig. 8.2 (cumulative reward of every evaluation per stage), 8.4-8.6 (the reaching
   state-actions chosen in evaluations), 8.7 (exploratory tries per problem and state-action) and
   8.8 (failed transitions per state-action), and ``report.md`` beside the source's claims.

Beyond the source (ch. 9.4.1), ``--mdp simultaneous``: no MDP is learned first; every run starts
from the optimistic initialisation of ch. 6 and learns the MDP with the reaches, telling a model
update from a penalty by whether MoBeE's fields felt the target (see
:mod:`mobee_drake.reaching.learner`); each run keeps its final counts in ``mdp.npz``.
``--reach-force`` sets the reach's force on the palm (the source gives none; 300 N by default),
``--distance-unit`` the unit of eq. 8.1-8.7's distances (none given; metres by default).

Run: ``mobee-drake experiment ch8 --output results/ch8`` (the whole battery), or a reduced one:
``mobee-drake experiment ch8 --problem-tries 400 --seeds 2``; watch one run in Meshcat:
``mobee-drake experiment ch8 --watch --strategies intrinsic``.
"""

import dataclasses as dc
import json
import pathlib
import sys
import time

import numpy as np
from pydrake.geometry import StartMeshcat
from scipy.stats import ttest_ind

from mobee_drake.atomic_files import CurrentGeneration, StrictJson, WriteGeneration
from mobee_drake.experiments.arguments import (
    CommandParser,
    NonNegativeInt,
    PositiveFloat,
    PositiveInt,
)
from mobee_drake.experiments.battery import (
    AddBackendArguments,
    Backend,
    BackendOf,
    Job,
    JobStopped,
    Provenance,
    RunBattery,
    RunFolder,
    StopRequested,
)
from mobee_drake.experiments.exploration import ExplorationScenario, Explore
from mobee_drake.experiments.plots import Figure, SaveFigure, StackedBars, plt
from mobee_drake.mobee.params import Dissertation
from mobee_drake.owned_folders import OwnedFolder
from mobee_drake.planning.explorers import Explorer, ExplorerConfig, LoadAgentModel
from mobee_drake.planning.state_space import Lattice
from mobee_drake.planning.supervisor import ExploringAgent
from mobee_drake.reaching.learner import LOG_COLUMNS, ReachLearner, ReachLearningConfig
from mobee_drake.reaching.predictors import PREDICTORS, PredictorConfig
from mobee_drake.reaching.robot import SimulatedRobot
from mobee_drake.reaching.strategies import REACH_STRATEGIES
from mobee_drake.reaching.targets import LoadTargetGrid
from mobee_drake.robots.icub import RIGHT_SHOULDER_ELBOW_JOINTS, IcubConfig
from mobee_drake.scenario import BuildScenario, Scenario
from mobee_drake.station.executor import ReachForcing, StateActionAttractor

RIGHT_ARM = list(RIGHT_SHOULDER_ELBOW_JOINTS)
SOURCE_STAGES = (100, 200, 400, 800, 1600, 3200, 6400)
# Where the MDP comes from: learned first and fixed (ch. 8), or with the reaches (ch. 9.4.1).
MDPS = ("learned_first", "simultaneous")
LEVELS = [0.25, 0.5, 0.75]
AGENT = "right_arm"
# Robot hours of the source's five runs per strategy (ch. 8.4).
SOURCE_HOURS = {"random": 207, "greedy": 109, "intrinsic": 113}
SOURCE_STRATEGIES = tuple(SOURCE_HOURS)


def _Robot() -> IcubConfig:
    return IcubConfig(controlled_joints=RIGHT_ARM)


def TrainMdp(folder: pathlib.Path, min_tries: int, seed: int = 0, progress=None, should_stop=None):
    """The curious agent's model of the rank-3 lattice, learned once (checkpointed in ``folder``
    as it learns, resumed from there after a kill); ``progress(n)``, if given, is told the
    actions done as the agent learns."""
    agent = ExploringAgent(name=AGENT, joints=RIGHT_ARM, levels=LEVELS)
    Explore(
        ExplorationScenario([agent], robot=_Robot(), random_seed=seed),
        chunk=5.0,
        checkpoint=folder,
        stop=lambda records: records[0].explorer.tries.min() >= min_tries,
        progress=progress,
        should_stop=should_stop,
    )
    return LoadAgentModel(str(folder), AGENT, ExplorerConfig())


def MdpJob(run: RunFolder, min_tries: int) -> dict:
    """The battery job that learns the MDP (in ``run.path / "model"``)."""
    model = TrainMdp(
        run.path / "model", min_tries, progress=run.Progress, should_stop=StopRequested
    )
    return dict(min_tries=int(model.tries.min()), actions=int(model.tries.sum()))


@dc.dataclass
class RunSettings:
    strategy: str
    seed: int
    problem_tries: int
    stages: list[int]
    evaluations: int
    checkpoint_every: int
    # "weighted" (eq. 8.1-8.7) or "gaussian_process".
    predictor: str = "weighted"
    # One of MDPS.
    mdp: str = "learned_first"
    # The reach's force on the palm (N; ch. 8.2 gives none). Weaker reaches leave the palm
    # farther from targets it starts far from, so the pre-reach state matters more.
    reach_force: float = ReachForcing().force
    # The length (m) that counts as 1 in eq. 8.1-8.7 (the source gives no unit).
    distance_unit: float = PredictorConfig().distance_unit


def ReachScenario(reach_force: float = ReachForcing().force) -> Scenario:
    """The reach learner's headless kinematic iCub: MoBeE on the right shoulder and elbow,
    reaching with ``reach_force`` on the palm."""
    scenario = Scenario()
    scenario.robot = _Robot()
    scenario.attractor = StateActionAttractor()
    scenario.attractor.forcing.force = reach_force
    scenario.time_step = 0.02
    scenario.mobee = Dissertation()  # (ch. 8 with the source's constants)
    scenario.data_log.enabled = False  # (The battery keeps its own data.)
    return scenario


def ReachRobot(
    space, target_radius: float, reach_force: float = ReachForcing().force, meshcat=None
) -> SimulatedRobot:
    """The reach learner's robot on the station of :func:`ReachScenario` (shown in real time in
    ``meshcat``, if given)."""
    station = BuildScenario(ReachScenario(reach_force), meshcat)
    return SimulatedRobot(station, RIGHT_ARM, space, target_radius, realtime=meshcat is not None)


def _Checkpoint(
    folder: pathlib.Path, robot: SimulatedRobot, learner: ReachLearner, data: dict
) -> None:
    """Saves the simulation, the learner and ``data`` (evaluations, wall time) as the newest
    generation of ``folder``."""

    def Write(staging: pathlib.Path) -> None:
        (staging / "simulation").mkdir()
        robot.Save(staging / "simulation")
        arrays, learner_data = learner.ToArrays()
        np.savez(staging / "learner.npz", **arrays)
        (staging / "learner.json").write_text(StrictJson(dict(learner=learner_data, **data)))

    WriteGeneration(folder, Write)


def RunOne(
    run_dir: pathlib.Path,
    mdp_dir: pathlib.Path,
    settings: RunSettings,
    meshcat=None,
    progress=None,
    should_stop=None,
) -> dict:
    """One run of the battery (resumes from ``run_dir/checkpoint``); returns its result. With
    ``meshcat``, the run is shown there in real time; ``progress(n)``, if given, is told the
    problem-tries done at every checkpoint; ``should_stop()``, if given, is asked after every
    problem-try, and when True the run saves its checkpoint and raises JobStopped."""
    run_dir.mkdir(parents=True, exist_ok=True)
    simultaneous = settings.mdp == "simultaneous"
    # The optimistic initial model of the MDP's lattice, or the model learned first.
    model = (
        Explorer(Lattice(LEVELS, len(RIGHT_ARM)))
        if simultaneous
        else LoadAgentModel(str(mdp_dir), AGENT, ExplorerConfig())
    )
    grid = LoadTargetGrid()
    learner = ReachLearner(
        model.space,
        model.transitions.counts,
        grid.Centres(),
        ReachLearningConfig(
            strategy=settings.strategy,
            seed=settings.seed,
            predictor=PredictorConfig(settings.predictor, distance_unit=settings.distance_unit),
            learn_mdp=simultaneous,
        ),
    )
    robot = ReachRobot(model.space, grid.radius, settings.reach_force, meshcat)
    checkpoint = run_dir / "checkpoint"
    data = dict(evaluations={}, wall_seconds=0.0, target=None)
    generation = CurrentGeneration(checkpoint)
    if generation is not None:
        saved = json.loads((generation / "learner.json").read_text())
        learner.LoadArrays(np.load(generation / "learner.npz"), saved.pop("learner"))
        robot.Load(generation / "simulation")
        data = saved
        if data["target"] is not None:
            robot.SetProblem(np.array(data["target"]))
    started = time.perf_counter() - data["wall_seconds"]

    def Save():
        data["wall_seconds"] = time.perf_counter() - started
        data["target"] = None if robot.target is None else robot.target.tolist()
        _Checkpoint(checkpoint, robot, learner, data)
        if progress is not None:
            progress(int(learner.problem_tries.sum()))

    while True:
        done = int(learner.problem_tries.sum())
        if done in settings.stages and str(done) not in data["evaluations"]:
            data["evaluations"][str(done)] = [
                [dc.asdict(r) for r in learner.Evaluate(robot, seed=(settings.seed, done, e))]
                for e in range(settings.evaluations)
            ]
            Save()
        if done >= settings.problem_tries:
            break
        learner.Explore(robot)
        if (done + 1) % settings.checkpoint_every == 0:
            Save()
        if should_stop is not None and should_stop():
            Save()
            raise JobStopped(f"{run_dir.name}: stopped after {done + 1} problem-tries")
    Save()
    arrays, _ = learner.ToArrays()
    extra = {}
    if simultaneous:
        counts = learner.model.counts
        np.savez(run_dir / "mdp.npz", counts=counts)
        # The state-actions the model learned about, and their learned chance of success.
        updated = np.flatnonzero(np.any(counts != model.transitions.counts, axis=1))
        success = learner.model.Probabilities()[updated, model.space.action_goal[updated]]
        extra = dict(
            mdp=dict(
                updated_state_actions=len(updated),
                success_probability=float(success.mean()) if len(updated) else None,
            )
        )
    result = dict(
        settings=dc.asdict(settings),
        evaluations=data["evaluations"],
        log=arrays["log"].tolist(),
        simulated_seconds=robot.simulated_seconds,
        wall_seconds=data["wall_seconds"],
        penetrating_steps=robot.PenetratingSteps(),
        num_transitions=learner.num_transitions,
        num_states=learner.space.num_states,
        **extra,
    )
    return result


def ReachJob(run: RunFolder, mdp: str, settings: dict) -> dict:
    """The battery job of one reach-learning run (``settings``: a :class:`RunSettings`) on the
    MDP learned by the battery's job ``mdp``."""
    mdp_dir = run.path.parent / mdp / "model"
    return RunOne(
        run.path,
        mdp_dir,
        RunSettings(**settings),
        progress=run.Progress,
        should_stop=StopRequested,
    )


def RunReachBattery(
    output: pathlib.Path,
    strategies,
    seeds: int,
    settings: RunSettings,
    mdp_tries: int,
    backend: Backend,
) -> list[dict]:
    """The MDP (unless learned with the reaches), then a run of ``settings`` for every strategy
    and seed, on ``backend`` (see :mod:`mobee_drake.experiments.battery`)."""
    mdp = f"mdp_tries{mdp_tries}"
    if settings.mdp == "learned_first":
        RunBattery(
            [Job(mdp, MdpJob, dict(min_tries=mdp_tries))],
            output,
            backend=backend,
            description="the MDP (actions)",
        )
    jobs = [
        Job(
            f"{strategy}_seed{seed}",
            ReachJob,
            dict(
                mdp=mdp,
                settings=dc.asdict(dc.replace(settings, strategy=strategy, seed=seed)),
            ),
            total=settings.problem_tries,
        )
        for strategy in strategies
        for seed in range(seeds)
    ]
    return list(RunBattery(jobs, output, backend=backend, description="reach learning").values())


def _Cumulative(evaluation: list[dict]) -> float:
    """The reward summed over an evaluation's problem-tries (reaches only; a timeout gets 0)."""
    return sum(r["reward"] or 0.0 for r in evaluation)


def _Log(run: dict) -> np.ndarray:
    """A run's log of actions, one row per action (columns: LOG_COLUMNS)."""
    return np.array(run["log"]).reshape(-1, len(LOG_COLUMNS))


def _Cumulatives(runs: list[dict], stages: list[int]) -> np.ndarray:
    """The cumulative reward of every evaluation: runs x stages x evaluations."""
    return np.array(
        [[[_Cumulative(e) for e in r["evaluations"][str(stage)]] for stage in stages] for r in runs]
    )


def _Seeds(runs: list[dict], repeat: int = 1) -> list[str]:
    """Legend labels of the runs' seeds, each ``repeat`` times (one per stacked row)."""
    return [f"seed {r['settings']['seed']}" for r in runs for _ in range(repeat)]


def CumulativeRewardFigure(by_strategy: dict[str, list[dict]], stages: list[int]) -> Figure:
    """Fig. 8.2: the cumulative reward of every evaluation, stacked per stage, one colour per
    seed (its evaluations split by white edges)."""
    figure, axes = plt.subplots(
        1, len(by_strategy), figsize=(6.5 * len(by_strategy), 4.5), squeeze=False, sharey=True
    )
    for axis, (strategy, runs) in zip(axes[0], by_strategy.items()):
        table = _Cumulatives(runs, stages)
        evaluations = table.shape[2]
        StackedBars(
            axis,
            table.transpose(0, 2, 1).reshape(-1, len(stages)),
            _Seeds(runs, evaluations),
            x=np.arange(len(stages)),
            width=0.6,
        )
        axis.set_xticks(np.arange(len(stages)), [str(s) for s in stages])
        axis.set(
            xlabel="exploratory problem-tries [count]",
            ylabel="cumulative reward [sum of eq. 8.4\nover the problems], evaluations stacked",
            title=f"{strategy}: {len(runs)} seeds x {evaluations} evaluations per stage",
        )
        axis.yaxis.set_tick_params(labelleft=True)
    figure.suptitle(
        "Fig. 8.2 on the kinematic iCub: cumulative reward of the exploitation evaluations"
    )
    return figure


def ReachesFigure(strategy: str, runs: list[dict], stages: list[int], k: int, m: int) -> Figure:
    """Fig. 8.4-8.6: the reaching state-actions chosen in evaluations, per stage, seeds
    stacked (``k`` transitions, ``m`` states)."""
    figure, axes = plt.subplots(len(stages), 1, figsize=(12, 2.6 * len(stages)), squeeze=False)
    for axis, stage in zip(axes[:, 0], stages):
        counts = np.array(
            [
                np.bincount(
                    [
                        t["reach"] - k
                        for e in r["evaluations"][str(stage)]
                        for t in e
                        if t["reach"] >= 0
                    ],
                    minlength=m,
                )
                for r in runs
            ]
        )
        StackedBars(axis, counts, _Seeds(runs))
        axis.set(
            xlabel=f"reaching state-action - {k} = the state it reaches from [index]",
            ylabel="reaches [count]",
            title=f"{strategy}, after {stage} problem-tries: reaches chosen in the "
            "evaluations, seeds stacked",
        )
    return figure


def ProblemTriesFigure(
    by_strategy: dict[str, list[dict]], stages: list[int], k: int, m: int
) -> Figure:
    """Fig. 8.7: exploratory tries per problem (row) and state-action (column) before each
    stage, mean over seeds, one column of images per strategy."""
    figure, axes = plt.subplots(
        len(stages),
        len(by_strategy),
        figsize=(6.5 * len(by_strategy), 2.6 * len(stages)),
        squeeze=False,
    )
    num_problems = len(next(iter(by_strategy.values()))[0]["evaluations"][str(stages[0])][0])
    for column, (strategy, runs) in enumerate(by_strategy.items()):
        for row, stage in enumerate(stages):
            image = np.zeros((num_problems, k + m))
            for r in runs:
                log = _Log(r)
                log = log[log[:, 0] < stage]
                np.add.at(image, (log[:, 1].astype(int), log[:, 2].astype(int)), 1.0)
            axis = axes[row, column]
            shown = axis.imshow(
                image / len(runs), aspect="auto", cmap="jet", interpolation="nearest"
            )
            figure.colorbar(shown, ax=axis, label=f"tries [count,\nmean of {len(runs)} seeds]")
            axis.set(
                xlabel=f"state-action [index; reaches from {k}]",
                ylabel="problem [index]",
                title=f"{strategy}: tries in the first {stage} problem-tries",
            )
    return figure


def FailedTransitionsFigure(by_strategy: dict[str, list[dict]], k: int) -> Figure:
    """Fig. 8.8: failed transitions (reward -10) per transition state-action, seeds stacked."""
    figure, axes = plt.subplots(
        len(by_strategy), 1, figsize=(12, 3.2 * len(by_strategy)), squeeze=False
    )
    for axis, (strategy, runs) in zip(axes[:, 0], by_strategy.items()):
        counts = []
        for r in runs:
            log = _Log(r)
            counts.append(np.bincount(log[log[:, 6] < 0, 2].astype(int), minlength=k)[:k])
        StackedBars(axis, np.array(counts), _Seeds(runs))
        axis.set(
            xlabel="transition state-action [index]",
            ylabel="failed transitions [count]",
            title=f"{strategy}: failed transitions (reward -10) in "
            f"{runs[0]['settings']['problem_tries']} problem-tries per seed, seeds stacked",
        )
    return figure


def Report(output: pathlib.Path, results: list[dict]) -> str:
    """Plots like Fig. 8.2, 8.4-8.8 and a markdown report; returns the report."""
    strategies = [
        s for s in REACH_STRATEGIES if any(r["settings"]["strategy"] == s for r in results)
    ]
    by_strategy = {s: [r for r in results if r["settings"]["strategy"] == s] for s in strategies}
    stages = sorted({int(k) for r in results for k in r["evaluations"]})
    k, m = results[0]["num_transitions"], results[0]["num_states"]
    SaveFigure(CumulativeRewardFigure(by_strategy, stages), output / "8.2_cumulative_reward.png")
    for strategy in strategies:
        SaveFigure(
            ReachesFigure(strategy, by_strategy[strategy], stages, k, m),
            output / f"8.4-8.6_reaches_{strategy}.png",
        )
    SaveFigure(ProblemTriesFigure(by_strategy, stages, k, m), output / "8.7_problem_tries.png")
    SaveFigure(FailedTransitionsFigure(by_strategy, k), output / "8.8_failed_transitions.png")
    lines = [
        "## Cumulative reward of the exploitation evaluations (Fig. 8.2)",
        "",
        "Sum of the reaches' rewards (eq. 8.4) over the 27 problems of one evaluation (a "
        "problem-try that timed out adds 0); mean and standard deviation over all "
        "evaluations of all seeds.",
        "",
        "| strategy | " + " | ".join(str(s) for s in stages) + " |",
        "|---|" + "---:|" * len(stages),
    ]
    means = {}
    for strategy in strategies:
        table = _Cumulatives(by_strategy[strategy], stages)
        means[strategy] = table.mean(axis=(0, 2))
        lines.append(
            f"| {strategy} | "
            + " | ".join(
                f"{mu:.2f} ± {sd:.2f}" for mu, sd in zip(means[strategy], table.std(axis=(0, 2)))
            )
            + " |"
        )
    lines += [
        "",
        "## Robot time, failed transitions and reaches",
        "",
        "| strategy | runs | robot hours (all runs) | source's robot hours (5 runs of 6400) "
        "| actions per problem-try | failed transitions per problem-try | timed-out "
        "problem-tries | wall hours (all runs) | penetrating control periods |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    hours = {}
    for strategy in strategies:
        actions, failed, timeouts, tries = 0, 0, 0, 0
        for r in by_strategy[strategy]:
            log = _Log(r)
            actions += len(log)
            failed += int(np.sum(log[:, 6] < 0))
            tries += r["settings"]["problem_tries"]
            reaches = log[log[:, 2] >= k]
            timeouts += r["settings"]["problem_tries"] - len(reaches)
        hours[strategy] = sum(r["simulated_seconds"] for r in by_strategy[strategy]) / 3600
        lines.append(
            f"| {strategy} | {len(by_strategy[strategy])} | {hours[strategy]:.1f} | "
            f"{SOURCE_HOURS.get(strategy, '-')} | {actions / tries:.2f} | {failed / tries:.2f} | "
            f"{timeouts} | {sum(r['wall_seconds'] for r in by_strategy[strategy]) / 3600:.2f} | "
            f"{sum(r['penetrating_steps'] for r in by_strategy[strategy])} |"
        )

    if all("mdp" in r for r in results):
        lines += [
            "",
            "## The MDP learned with the reaches (ch. 9.4.1)",
            "",
            f"State-actions (of {k}) whose model was updated (tried without the fields "
            "feeling the target), and their learned probability of reaching their goal "
            "state (the optimistic initialisation says 0.5), mean over seeds.",
            "",
            "| strategy | state-actions updated | P(goal) |",
            "|---|---:|---:|",
        ]
        for strategy in strategies:
            runs = [r["mdp"] for r in by_strategy[strategy]]
            success = [
                r["success_probability"] for r in runs if r["success_probability"] is not None
            ]
            lines.append(
                f"| {strategy} | "
                f"{np.mean([r['updated_state_actions'] for r in runs]):.0f} | "
                + (f"{np.mean(success):.2f} |" if success else "- |")
            )

    lines += [
        "",
        "## The source's claims (ch. 8.4)",
        "",
        "Differences of the mean cumulative reward, with Welch's t-test over the "
        "evaluations (a claim about an order holds only with p < 0.05).",
        "",
    ]
    if {"intrinsic", "random", "greedy"} <= set(means):

        def Rewards(strategy, stage):
            return [
                _Cumulative(e) for r in by_strategy[strategy] for e in r["evaluations"][str(stage)]
            ]

        for i, stage in enumerate(stages):
            mine = Rewards("intrinsic", stage)
            comparisons = []
            for other in [s for s in strategies if s != "intrinsic"]:
                test = ttest_ind(mine, Rewards(other, stage), equal_var=False)
                comparisons.append(
                    f"{other} {means['intrinsic'][i] - means[other][i]:+.2f} "
                    f"(p = {test.pvalue:.2g})"
                )
            lines.append(
                f"- after {stage} problem-tries, intrinsic minus " + ", ".join(comparisons) + ";"
            )
        ratio = hours["random"] / np.mean([hours["greedy"], hours["intrinsic"]])
        lines += [
            "- the source: intrinsic motivation is the least competent after 100 problem-tries, "
            "improves steadily and is clearly the best from about 800 on;",
            f"- random exploration took {ratio:.2f} times the robot time of the other two "
            f"(source: 207 h against 109 and 113 h, 1.86 times).",
        ]
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = CommandParser(
        prog="mobee-drake experiment ch8",
        description=__doc__,
    )
    parser.add_argument(
        "--output", default="results/ch8", help="the battery folder (runs, plots, report)"
    )
    parser.add_argument(
        "--strategies",
        nargs="+",
        choices=list(REACH_STRATEGIES),
        default=list(SOURCE_STRATEGIES),
        help="exploration strategies, one run per seed each",
    )
    parser.add_argument("--seeds", type=PositiveInt, default=5, help="seeds per strategy")
    parser.add_argument(
        "--problem-tries", type=PositiveInt, default=6400, help="exploratory problem-tries per run"
    )
    parser.add_argument(
        "--stages",
        type=NonNegativeInt,
        nargs="+",
        default=None,
        help="when to evaluate (default: the source's 100, 200, ..., 6400 up to --problem-tries)",
    )
    parser.add_argument(
        "--evaluations", type=PositiveInt, default=5, help="exploitation evaluations at each stage"
    )
    parser.add_argument(
        "--mdp-tries",
        type=PositiveInt,
        default=5,
        help="the MDP is learned until every state-action was tried this often",
    )
    parser.add_argument(
        "--checkpoint-every",
        type=PositiveInt,
        default=50,
        help="problem-tries between two checkpoints of a run",
    )
    parser.add_argument(
        "--watch",
        action="store_true",
        help="run only the first strategy's seed 0, in this process, shown in "
        "Meshcat in real time (the address is printed)",
    )
    parser.add_argument(
        "--predictor",
        choices=PREDICTORS,
        default="weighted",
        help="the reward predictor: the source's weighted averages (eq. 8.1-8.7) "
        "or a Gaussian process (use another --output)",
    )
    parser.add_argument(
        "--mdp",
        choices=MDPS,
        default="learned_first",
        help="learn the MDP first and keep it (ch. 8), or learn it with the "
        "reaches (ch. 9.4.1; use another --output)",
    )
    parser.add_argument(
        "--reach-force",
        type=PositiveFloat,
        default=ReachForcing().force,
        help="the reach's force on the palm in N (use another --output)",
    )
    parser.add_argument(
        "--distance-unit",
        type=PositiveFloat,
        default=PredictorConfig().distance_unit,
        help="the length in m that counts as 1 in the rewards and predictions "
        "of eq. 8.1-8.7, e.g. 0.01 for centimetres (use another --output)",
    )
    AddBackendArguments(parser, workers=2)
    argv = sys.argv[1:] if argv is None else argv
    args = parser.parse_args(argv)
    stages = args.stages or [s for s in SOURCE_STAGES if s <= args.problem_tries]
    if any(s < 0 or s > args.problem_tries for s in stages):
        parser.error(f"--stages must lie in 0..{args.problem_tries}")
    output = pathlib.Path(args.output)
    output.mkdir(parents=True, exist_ok=True)
    settings = RunSettings(
        args.strategies[0],
        0,
        args.problem_tries,
        stages,
        args.evaluations,
        args.checkpoint_every,
        args.predictor,
        args.mdp,
        args.reach_force,
        args.distance_unit,
    )
    if args.watch:  # In the battery's folder, beside its runs.
        watch = output / "watch"
        with OwnedFolder(output, "battery"):
            mdp_dir = watch / f"mdp_tries{args.mdp_tries}"
            if settings.mdp == "learned_first":
                TrainMdp(mdp_dir, args.mdp_tries)
            RunOne(watch / settings.strategy, mdp_dir, settings, StartMeshcat())
        return
    results = RunReachBattery(
        output, args.strategies, args.seeds, settings, args.mdp_tries, BackendOf(args)
    )
    report = output / "report.md"
    report.write_text(
        f"# Reach learning (ch. 8.4)\n\n`mobee-drake experiment ch8 "
        f"{' '.join(argv)}` ({Provenance(output)})\n\n" + Report(output, results) + "\n"
    )
    print(report.read_text())


if __name__ == "__main__":
    main()
