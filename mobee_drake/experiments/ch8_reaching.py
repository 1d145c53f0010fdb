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
The source gives neither the reach's force on the palm nor the unit of eq. 8.1-8.7's distances;
``--preset`` names a pair (:data:`REACH_PRESETS`): ``calibrated`` (the default, chosen in issue 23
by the source's behavioural fingerprints) or ``metres`` (the first reading, in which exploitation
never moves). ``--reach-force`` and ``--distance-unit`` override the preset's; several
values of either make a sweep: one battery on one MDP, a run of every strategy and seed per
combination, and a report that scores each combination against the source's behavioural
fingerprints (:func:`Fingerprints`). ``--tie-break`` chooses how the greedy policy breaks ties
of value (the first state-action by default, or a random one). ``--report-only`` rewrites the
plots and report of the finished runs in ``--output`` without running anything.

The report sums every evaluation as the source does (the reaches' rewards and the -10 of every
failed transition, ch. 8.3.1 and 8.3.3) and also without the penalties, and tests the source's
claims at run level (:mod:`mobee_drake.experiments.statistics`: one value per run and stage, the
mean of the run's evaluations, never a pool of them; effect sizes beside the p-values).

Run: ``mobee-drake experiment ch8 --output results/ch8`` (the whole battery), or a reduced one:
``mobee-drake experiment ch8 --problem-tries 400 --seeds 2``; watch one run in Meshcat:
``mobee-drake experiment ch8 --watch --strategies intrinsic``.
"""

import dataclasses as dc
import json
import math
import pathlib
import sys
import time

import numpy as np
from pydrake.geometry import StartMeshcat

from mobee_drake.atomic_files import (
    CurrentGeneration,
    StrictJson,
    WriteGeneration,
    WriteTextAtomically,
)
from mobee_drake.experiments.arguments import (
    CommandParser,
    InRange,
    NonNegativeInt,
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
from mobee_drake.experiments.statistics import CompareRuns, CompareToZero, RunMeans, Trend
from mobee_drake.mobee.params import Dissertation
from mobee_drake.owned_folders import ClaimFolder, OwnedFolder
from mobee_drake.planning.explorers import Explorer, ExplorerConfig, LoadAgentModel
from mobee_drake.planning.state_space import Lattice
from mobee_drake.planning.supervisor import ExploringAgent
from mobee_drake.reaching.learner import (
    LOG_COLUMNS,
    TIE_BREAKS,
    ReachLearner,
    ReachLearningConfig,
)
from mobee_drake.reaching.predictors import (
    FAILED_TRANSITION_REWARD,
    PREDICTORS,
    PredictorConfig,
)
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
    # How the greedy policy breaks ties of value (one of TIE_BREAKS; the source is silent).
    tie_break: str = ReachLearningConfig().tie_break


@dc.dataclass(frozen=True)
class ReachPreset:
    """The reach learner's two constants that the source does not give (ch. 8.2, eq. 8.1-8.7)."""

    # The length (m) that counts as 1 in eq. 8.1-8.7.
    distance_unit: float
    # The reach's force on the palm (N).
    reach_force: float


# The ranges of the sweepable constants outside which a run means nothing: MoBeE's work-space
# squashing (m = 20) saturates far below the largest force, and a unit of 0.1 mm or 100 m
# makes every reward of eq. 8.4 either huge or nil over the iCub's reach.
REACH_FORCE_RANGE = (1e-3, 1e5)  # (N)
DISTANCE_UNIT_RANGE = (1e-4, 100.0)  # (m)

REACH_PRESETS = {
    # Issue 23, point 6: the setting of the sweep whose behaviour matches the source's
    # fingerprints best (docs/reaching.md, "Calibration against the source's behaviour").
    "calibrated": ReachPreset(distance_unit=0.03, reach_force=300.0),
    # The first reading: SI units and the full reach, in which exploitation never moves.
    "metres": ReachPreset(PredictorConfig().distance_unit, ReachForcing().force),
}


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


def _NewLearner(settings: RunSettings, mdp_dir: pathlib.Path):
    """(the MDP's model, a new reach learner on it, the target grid): the model is the
    optimistic initial one of the lattice, learned with the reaches, or the one learned first."""
    simultaneous = settings.mdp == "simultaneous"
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
            tie_break=settings.tie_break,
        ),
    )
    return model, learner, grid


def _LearnedMdp(run_dir: pathlib.Path, learner: ReachLearner, model: Explorer) -> dict:
    """Saves the MDP learned with the reaches (``mdp.npz``); the state-actions it learned about
    and their learned chance of reaching their goal."""
    counts = learner.model.counts
    np.savez(run_dir / "mdp.npz", counts=counts)
    updated = np.flatnonzero(np.any(counts != model.transitions.counts, axis=1))
    success = learner.model.Probabilities()[updated, model.space.action_goal[updated]]
    return dict(
        updated_state_actions=len(updated),
        success_probability=float(success.mean()) if len(updated) else None,
    )


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
    model, learner, grid = _NewLearner(settings, mdp_dir)
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
    if settings.mdp == "simultaneous":
        extra = dict(mdp=_LearnedMdp(run_dir, learner, model))
    safety = robot.Safety()
    result = dict(
        settings=dc.asdict(settings),
        evaluations=data["evaluations"],
        log=arrays["log"].tolist(),
        simulated_seconds=robot.simulated_seconds,
        wall_seconds=data["wall_seconds"],
        penetrating_steps=safety.penetrating_steps,
        barrier_periods=safety.barrier_periods,
        num_transitions=learner.num_transitions,
        num_states=learner.space.num_states,
        **extra,
    )
    return result


def _BarrierPeriods(results: list[dict]) -> str:
    """The periods the safety barrier acted in ``results`` (n/a for runs from before it was
    counted)."""
    if not all("barrier_periods" in r for r in results):
        return "n/a"
    return str(sum(r["barrier_periods"] for r in results))


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


def SettingLabel(settings: RunSettings) -> str:
    """A sweep's name for a run's distance unit and reach force (job names, report sections)."""
    return f"unit{settings.distance_unit:g}_force{settings.reach_force:g}"


def RunReachBattery(
    output: pathlib.Path,
    strategies,
    seeds: range,
    settings: RunSettings | list[RunSettings],
    mdp_tries: int,
    backend: Backend,
) -> list[dict]:
    """The MDP (unless learned with the reaches), then a run of ``settings`` for every strategy
    and seed, on ``backend`` (see :mod:`mobee_drake.experiments.battery`). A list of settings is
    a sweep: every setting's runs share the MDP and are named ``<strategy>_<SettingLabel>_seed<k>``
    (a single setting's ``<strategy>_seed<k>``)."""
    variants = [settings] if isinstance(settings, RunSettings) else list(settings)
    if not variants:
        raise ValueError("a reach-learning battery needs at least one setting")
    if len({v.mdp for v in variants}) > 1:
        raise ValueError("a sweep's settings must share --mdp")
    labels = [SettingLabel(v) for v in variants]
    if len(set(labels)) < len(labels):
        raise ValueError(f"a sweep's settings repeat: {sorted(labels)}")
    sweep = len(variants) > 1
    mdp = f"mdp_tries{mdp_tries}"
    if variants[0].mdp == "learned_first":
        RunBattery(
            [Job(mdp, MdpJob, dict(min_tries=mdp_tries))],
            output,
            backend=backend,
            description="the MDP (actions)",
        )
    jobs = [
        Job(
            f"{strategy}_{SettingLabel(variant)}_seed{seed}" if sweep else f"{strategy}_seed{seed}",
            ReachJob,
            dict(
                mdp=mdp,
                settings=dc.asdict(dc.replace(variant, strategy=strategy, seed=seed)),
            ),
            total=variant.problem_tries,
        )
        for variant in variants
        for strategy in strategies
        for seed in seeds
    ]
    return list(RunBattery(jobs, output, backend=backend, description="reach learning").values())


def EvaluationSum(evaluation: list[dict], penalties: bool = True) -> float:
    """The reward summed over an evaluation's problem-tries: the reaches' rewards (eq. 8.4; a
    try that timed out has none) and, with ``penalties`` (the source's definition, ch. 8.3.1 and
    8.3.3), the -10 of every failed transition."""
    reaches = sum(r["reward"] or 0.0 for r in evaluation)
    if not penalties:
        return reaches
    if any("failed_transitions" not in r for r in evaluation):
        return math.nan  # A result file written before the count was kept: unknown.
    return reaches + FAILED_TRANSITION_REWARD * sum(r["failed_transitions"] for r in evaluation)


def _Log(run: dict) -> np.ndarray:
    """A run's log of actions, one row per action (columns: LOG_COLUMNS)."""
    return np.array(run["log"]).reshape(-1, len(LOG_COLUMNS))


def _Cumulatives(runs: list[dict], stages: list[int], penalties: bool = True) -> np.ndarray:
    """The summed reward of every evaluation (:func:`EvaluationSum`): runs x stages x
    evaluations."""
    return np.array(
        [
            [
                [EvaluationSum(e, penalties) for e in r["evaluations"][str(stage)]]
                for stage in stages
            ]
            for r in runs
        ]
    )


def _Seeds(runs: list[dict], repeat: int = 1) -> list[str]:
    """Legend labels of the runs' seeds, each ``repeat`` times (one per stacked row)."""
    return [f"seed {r['settings']['seed']}" for r in runs for _ in range(repeat)]


def CumulativeRewardFigure(by_strategy: dict[str, list[dict]], stages: list[int]) -> Figure:
    """Fig. 8.2: the cumulative reward of every evaluation, stacked per stage, one colour per
    seed (its evaluations split by white edges): the reaches' rewards as bars, and a black tick
    where the stack ends with the failed transitions' penalties counted (the source's sum)."""
    figure, axes = plt.subplots(
        1, len(by_strategy), figsize=(6.5 * len(by_strategy), 4.5), squeeze=False, sharey=True
    )
    for axis, (strategy, runs) in zip(axes[0], by_strategy.items()):
        table = _Cumulatives(runs, stages, penalties=False)
        evaluations = table.shape[2]
        StackedBars(
            axis,
            table.transpose(0, 2, 1).reshape(-1, len(stages)),
            _Seeds(runs, evaluations),
            x=np.arange(len(stages)),
            width=0.6,
        )
        axis.hlines(
            _Cumulatives(runs, stages).sum(axis=(0, 2)),
            np.arange(len(stages)) - 0.35,
            np.arange(len(stages)) + 0.35,
            colors="black",
            label="with the -10 penalties",
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


# The reaches a run's favourites (Fig. 8.4) and a window's vertical lines (Fig. 8.7) count.
FAVOURITES = 2
# Where the source's fingerprints are read (ch. 8.4.3): greedy and intrinsic alike up to about
# 800 problem-tries; the intrinsic agent's coverage by 3200.
ALIKE_UNTIL, COVERAGE_AT = 800, 3200


def _TopShare(counts: np.ndarray) -> float:
    """The share of ``counts`` in its FAVOURITES largest entries (nan when empty)."""
    total = counts.sum()
    return float(np.sort(counts)[::-1][:FAVOURITES].sum() / total) if total else math.nan


def Fingerprints(run: dict) -> dict:
    """One run's values of the behaviour the source describes (ch. 8.4.2-8.4.4).

    - ``favourite_share``: at the run's last stage, the share of its evaluations' reaches made
      from its FAVOURITES most used states (the source's intrinsic agent settles on a few, Fig.
      8.4; its favourites 489 and 509); ``favourite_reaches``: those reaching state-actions;
      ``reach_states``: how many states the evaluations reached from; ``evaluation_actions``:
      actions per evaluation problem-try (1.00: exploitation never moves);
    - ``line_share``: per window of exploratory problem-tries between consecutive stages (keyed
      by the window's end), the share of the window's reaches that went to its FAVOURITES most
      tried reaching state-actions: Fig. 8.7's vertical lines (a few reaches tried on every
      problem) make it large;
    - ``coverage``: per stage, the share of the (reach state, problem) pairs tried in the
      exploratory problem-tries before it (the source's intrinsic agent: almost all 81 x 27 by
      3200);
    - ``robot_hours``: the run's simulated time, evaluations included.
    """
    k, m = run["num_transitions"], run["num_states"]
    stages = sorted(int(s) for s in run["evaluations"])
    last = run["evaluations"][str(stages[-1])]
    tries = [t for e in last for t in e]
    counts = np.bincount([t["reach"] - k for t in tries if t["reach"] >= 0], minlength=m)
    log = _Log(run)
    reaches = log[log[:, 2] >= k]
    line_share, coverage = {}, {}
    for start, end in zip([0] + stages[:-1], stages):
        window = reaches[(reaches[:, 0] >= start) & (reaches[:, 0] < end), 2].astype(int) - k
        if end > start:
            line_share[end] = _TopShare(np.bincount(window, minlength=m))
        before = reaches[reaches[:, 0] < end]
        pairs = {(int(p), int(sa)) for p, sa in zip(before[:, 1], before[:, 2])}
        coverage[end] = len(pairs) / (len(last[0]) * m)
    return dict(
        favourite_share=_TopShare(counts),
        favourite_reaches=[
            int(k + s) for s in np.argsort(-counts, kind="stable")[:FAVOURITES] if counts[s]
        ],
        reach_states=int(np.count_nonzero(counts)),
        evaluation_actions=float(np.mean([t["actions"] for t in tries])),
        line_share=line_share,
        coverage=coverage,
        robot_hours=run["simulated_seconds"] / 3600,
    )


def _CompareToZero(values) -> str:
    """:func:`CompareToZero` of run values as report text (nan values dropped)."""
    values = [v for v in values if not math.isnan(v)]
    if len(values) < 2:
        return f"n/a ({len(values)} run; at least 2)"
    return CompareToZero(values).Text()


def _Compare(a, b) -> str:
    """:func:`CompareRuns` of two lists of run values as report text (nan values dropped)."""
    a, b = [v for v in a if not math.isnan(v)], [v for v in b if not math.isnan(v)]
    if len(a) < 2 or len(b) < 2:
        return f"n/a ({len(a)} vs {len(b)} runs; at least 2 a side)"
    return CompareRuns(a, b).Text()


def _IntrinsicMinusOthers(run_values: dict[str, list[float]]) -> str:
    """Report text: :func:`_Compare` of the intrinsic runs' values with each other strategy's."""
    return "; ".join(
        f"{other} {_Compare(run_values['intrinsic'], values)}"
        for other, values in run_values.items()
        if other != "intrinsic"
    )


def _MeanSd(values) -> str:
    values = [v for v in values if not math.isnan(v)]
    if not values:
        return "-"
    return f"{np.mean(values):.2f} ± {np.std(values, ddof=1) if len(values) > 1 else 0.0:.2f}"


def _RunSums(runs: list[dict], stage: int, penalties: bool) -> np.ndarray:
    """One value per run: the mean of its evaluations' sums at ``stage``."""
    return RunMeans(
        [[EvaluationSum(e, penalties) for e in r["evaluations"][str(stage)]] for r in runs]
    )


def _RunTrends(runs: list[dict], stages: list[int], penalties: bool) -> list[float]:
    """One value per run: the trend (:func:`Trend`) of its evaluations' mean sums over
    ``stages``."""
    sums = np.array([_RunSums(runs, stage, penalties) for stage in stages])  # stages x runs
    return [Trend(stages, sums[:, i]) for i in range(len(runs))]


def _RobotTimeRatio(by_strategy: dict[str, list[dict]]) -> float:
    """Random's mean robot time over that of greedy and intrinsic (the source: 1.86)."""
    hours = {s: np.mean([r["simulated_seconds"] for r in by_strategy[s]]) for s in by_strategy}
    return hours["random"] / np.mean([hours["greedy"], hours["intrinsic"]])


def _WindowAtOrBefore(windows, end: int) -> int | None:
    ends = [w for w in windows if w <= end]
    return max(ends) if ends else None


def _Group(results: list[dict]) -> dict[str, list[dict]]:
    strategies = [
        s for s in REACH_STRATEGIES if any(r["settings"]["strategy"] == s for r in results)
    ]
    return {s: [r for r in results if r["settings"]["strategy"] == s] for s in strategies}


def _SweepRow(label: str, results: list[dict]) -> str:
    """A row of the sweep's fingerprint table for one setting's runs."""
    by_strategy = _Group(results)
    prints = {s: [Fingerprints(r) for r in runs] for s, runs in by_strategy.items()}
    cells = [label]
    cells.append(f"{np.mean([f['evaluation_actions'] for p in prints.values() for f in p]):.2f}")
    intrinsic = prints.get("intrinsic", [])
    cells.append(_MeanSd([f["favourite_share"] for f in intrinsic]) if intrinsic else "-")
    if intrinsic and "greedy" in prints:
        windows = sorted(intrinsic[0]["line_share"])
        for end in (_WindowAtOrBefore(windows, ALIKE_UNTIL), windows[-1]):
            if end is None:
                cells.append("-")
                continue
            g = [f["line_share"][end] for f in prints["greedy"]]
            i = [f["line_share"][end] for f in intrinsic]
            cells.append(f"{np.nanmean(g) - np.nanmean(i):+.2f} (to {end})")
    else:
        cells += ["-", "-"]
    if intrinsic:
        stage = _WindowAtOrBefore(sorted(intrinsic[0]["coverage"]), COVERAGE_AT)
        cells.append(
            f"{np.mean([f['coverage'][stage] for f in intrinsic]):.2f} (at {stage})"
            if stage is not None
            else "-"
        )
    else:
        cells.append("-")
    cells.append(
        f"{_RobotTimeRatio(by_strategy):.2f}"
        if {"random", "greedy", "intrinsic"} <= set(by_strategy)
        else "-"
    )
    return "| " + " | ".join(cells) + " |"


def Report(output: pathlib.Path, results: list[dict]) -> str:
    """Plots like Fig. 8.2, 8.4-8.8 and a markdown report; returns the report. Results of
    several settings (a sweep: distance unit, reach force) get a fingerprint table across the
    settings, then a section each, their figures in ``output/<SettingLabel>/``."""
    groups: dict[str, list[dict]] = {}
    for r in results:
        groups.setdefault(SettingLabel(RunSettings(**r["settings"])), []).append(r)
    if len(groups) == 1:
        return _SettingReport(output, results)
    lines = [
        "## The source's behavioural fingerprints across the settings (issue 23, point 6)",
        "",
        "Per setting: evaluation actions per problem-try (all strategies; 1.00 means "
        "exploitation never moves); the intrinsic agent's favourite-reach share at the last "
        f"stage (its evaluations' reaches from its {FAVOURITES} most used states; the source: "
        "a few favourites); greedy minus intrinsic line share (exploratory reaches on a "
        f"window's {FAVOURITES} most tried reaching state-actions) in the window up to "
        f"{ALIKE_UNTIL} and in the last window (the source: about 0 up to {ALIKE_UNTIL}, "
        "greedy's vertical lines after); the intrinsic agent's coverage of the "
        f"(reach state, problem) pairs by {COVERAGE_AT} (the source: almost all of "
        "81 x 27); random's robot time over the other two's (the source: 1.86). Run-level "
        "statistics in each setting's section.",
        "",
        "| setting | evaluation actions per try | intrinsic favourite share | greedy - "
        f"intrinsic line share, to {ALIKE_UNTIL} | the same, last window | intrinsic "
        "coverage | random's robot time ratio |",
        "|---|---:|---:|---:|---:|---:|---:|",
    ]
    lines += [_SweepRow(label, runs) for label, runs in groups.items()]
    for label, runs in groups.items():
        folder = output / label
        folder.mkdir(exist_ok=True)
        lines += ["", f"# {label}", "", f"Figures in `{label}/`.", "", _SettingReport(folder, runs)]
    return "\n".join(lines)


def StoredResults(output: pathlib.Path) -> list[dict]:
    """The results of the finished reach-learning runs in a battery folder, in name order."""
    results = []
    for path in sorted(pathlib.Path(output).glob("runs/*/result.json")):
        result = json.loads(path.read_text())
        if "evaluations" in result:  # (Not the MDP's.)
            results.append(result)
    return results


def _SettingReport(output: pathlib.Path, results: list[dict]) -> str:
    """Plots and the report of one setting's runs."""
    by_strategy = _Group(results)
    stages = sorted({int(k) for r in results for k in r["evaluations"]})
    k, m = results[0]["num_transitions"], results[0]["num_states"]
    _SaveSettingFigures(output, by_strategy, stages, k, m)
    prints = {s: [Fingerprints(r) for r in runs] for s, runs in by_strategy.items()}
    sections = (
        _RewardSection(results, by_strategy, stages),
        _EffortSection(by_strategy, k),
        _MdpSection(results, by_strategy, k),
        _FingerprintSection(results, prints, stages, m),
        _ClaimsSection(by_strategy, prints, stages),
    )
    return "\n".join(line for section in sections for line in section)


def _SaveSettingFigures(output: pathlib.Path, by_strategy: dict, stages, k: int, m: int) -> None:
    """Fig. 8.2, 8.4-8.6 (per strategy), 8.7 and 8.8 of one setting's runs."""
    SaveFigure(CumulativeRewardFigure(by_strategy, stages), output / "8.2_cumulative_reward.png")
    for strategy in by_strategy:
        SaveFigure(
            ReachesFigure(strategy, by_strategy[strategy], stages, k, m),
            output / f"8.4-8.6_reaches_{strategy}.png",
        )
    SaveFigure(ProblemTriesFigure(by_strategy, stages, k, m), output / "8.7_problem_tries.png")
    SaveFigure(FailedTransitionsFigure(by_strategy, k), output / "8.8_failed_transitions.png")


def _RewardSection(results: list[dict], by_strategy: dict, stages) -> list[str]:
    """Fig. 8.2's cumulative reward per strategy and stage, with and without the penalties."""
    strategies = list(by_strategy)
    lines = [
        "## Cumulative reward of the exploitation evaluations (Fig. 8.2)",
        "",
        "The summed reward of one evaluation over the 27 problems, as the source defines it "
        "(ch. 8.3.1, 8.3.3): the reaches' rewards (eq. 8.4; a problem-try that timed out has "
        "none) and the -10 of every failed transition; then the reaches' rewards alone. One "
        "value per run (the mean of its evaluations at the stage), mean ± sd over the runs.",
        "Ties of value broken by: "
        + ", ".join(
            sorted(
                {
                    r["settings"].get("tie_break", "random (a run made before the option)")
                    for r in results
                }
            )
        )
        + ".",
    ]
    for penalties, title in ((True, "with the penalties"), (False, "reaches only")):
        lines += [
            "",
            f"| strategy ({title}) | runs | " + " | ".join(str(s) for s in stages) + " |",
            "|---|---:|" + "---:|" * len(stages),
        ]
        for strategy in strategies:
            runs = by_strategy[strategy]
            lines.append(
                f"| {strategy} | {len(runs)} | "
                + " | ".join(_MeanSd(_RunSums(runs, s, penalties)) for s in stages)
                + " |"
            )
    return lines


def _EffortSection(by_strategy: dict, k: int) -> list[str]:
    """Robot time, failed transitions, timed-out problem-tries and safety per strategy."""
    strategies = list(by_strategy)
    lines = [
        "",
        "## Robot time, failed transitions and reaches",
        "",
        "| strategy | runs | robot hours (all runs) | source's robot hours (5 runs of 6400) "
        "| actions per problem-try | failed transitions per problem-try | timed-out "
        "problem-tries | wall hours (all runs) | penetrating control periods | periods the "
        "safety barrier acted |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for strategy in strategies:
        actions, failed, timeouts, tries = 0, 0, 0, 0
        for r in by_strategy[strategy]:
            log = _Log(r)
            actions += len(log)
            failed += int(np.sum(log[:, 6] < 0))
            tries += r["settings"]["problem_tries"]
            reaches = log[log[:, 2] >= k]
            timeouts += r["settings"]["problem_tries"] - len(reaches)
        hours = sum(r["simulated_seconds"] for r in by_strategy[strategy]) / 3600
        lines.append(
            f"| {strategy} | {len(by_strategy[strategy])} | {hours:.1f} | "
            f"{SOURCE_HOURS.get(strategy, '-')} | {actions / tries:.2f} | {failed / tries:.2f} | "
            f"{timeouts} | {sum(r['wall_seconds'] for r in by_strategy[strategy]) / 3600:.2f} | "
            f"{sum(r['penetrating_steps'] for r in by_strategy[strategy])} | "
            f"{_BarrierPeriods(by_strategy[strategy])} |"
        )

    return lines


def _MdpSection(results: list[dict], by_strategy: dict, k: int) -> list[str]:
    """The MDP learned with the reaches (ch. 9.4.1), when the runs recorded it."""
    if not all("mdp" in r for r in results):
        return []
    lines = [
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
    for strategy, strategy_runs in by_strategy.items():
        runs = [r["mdp"] for r in strategy_runs]
        success = [r["success_probability"] for r in runs if r["success_probability"] is not None]
        lines.append(
            f"| {strategy} | "
            f"{np.mean([r['updated_state_actions'] for r in runs]):.0f} | "
            + (f"{np.mean(success):.2f} |" if success else "- |")
        )
    return lines


def _FingerprintSection(results: list[dict], prints: dict, stages, m: int) -> list[str]:
    """The behavioural fingerprints of ch. 8.4.2-8.4.4 per strategy."""
    strategies = list(prints)
    lines = [
        "",
        "## Behavioural fingerprints (ch. 8.4.2-8.4.4), mean ± sd over runs",
        "",
        f"Favourite share: the last stage's evaluation reaches from the run's {FAVOURITES} "
        "most used states; line share: exploratory reaches on the window's "
        f"{FAVOURITES} most tried reaching state-actions, per window of problem-tries; "
        "coverage: (reach state, problem) pairs tried, of "
        f"{m} x {len(next(iter(results))['evaluations'][str(stages[0])][0])}.",
        "",
        "| strategy | evaluation actions per try | states reached from | favourite share | "
        "favourite reaches (per run) | "
        + " | ".join(f"line share to {s}" for s in stages if s > 0)
        + " | "
        + " | ".join(f"coverage at {s}" for s in stages)
        + " |",
        "|---|---:|---:|---:|---|" + "---:|" * (len([s for s in stages if s > 0]) + len(stages)),
    ]
    for strategy in strategies:
        p = prints[strategy]
        lines.append(
            f"| {strategy} | {_MeanSd([f['evaluation_actions'] for f in p])} | "
            f"{_MeanSd([f['reach_states'] for f in p])} | "
            f"{_MeanSd([f['favourite_share'] for f in p])} | "
            + ", ".join("/".join(str(a) for a in f["favourite_reaches"]) for f in p)
            + " | "
            + " | ".join(_MeanSd([f["line_share"][s] for f in p]) for s in stages if s > 0)
            + " | "
            + " | ".join(_MeanSd([f["coverage"][s] for f in p]) for s in stages)
            + " |"
        )
    if {"greedy", "intrinsic"} <= set(prints):
        lines += ["", "Greedy minus intrinsic line share, per window (run level):", ""]
        for s in stages:
            if s > 0:
                g = [f["line_share"][s] for f in prints["greedy"]]
                i = [f["line_share"][s] for f in prints["intrinsic"]]
                lines.append(f"- problem-tries up to {s}: {_Compare(g, i)}")

    return lines


def _ClaimsSection(by_strategy: dict, prints: dict, stages) -> list[str]:
    """Intrinsic motivation against the other strategies: the source's claims (ch. 8.4)."""
    strategies = list(by_strategy)
    lines = [
        "",
        "## The source's claims (ch. 8.4)",
        "",
        "Intrinsic minus each other strategy, one value per run and stage (the mean of the "
        "run's evaluations; evaluations of one run share its learner and are never pooled): "
        "the difference of means, Hedges' g, Welch's t-test, the probability that an "
        "intrinsic run beats the other's and Mann-Whitney's test over the runs (a claim about "
        "an order holds only with p < 0.05).",
        "",
    ]
    if {"intrinsic", "random", "greedy"} <= set(strategies):
        trended = [s for s in stages if s > 0]
        for penalties, title in ((True, "the source's sum"), (False, "reaches only")):
            for stage in stages:
                sums = {s: _RunSums(by_strategy[s], stage, penalties) for s in strategies}
                lines.append(
                    f"- {title}, after {stage} problem-tries, intrinsic minus "
                    + _IntrinsicMinusOthers(sums)
                )
            if len(trended) >= 2:
                trends = {s: _RunTrends(by_strategy[s], trended, penalties) for s in strategies}
                lines.append(
                    f"- {title}, change per doubling of the problem-tries (per run, the slope of "
                    f"its stage means over log2 of {trended[0]}...{trended[-1]}): intrinsic "
                    + _CompareToZero(trends["intrinsic"])
                    + "; intrinsic minus "
                    + _IntrinsicMinusOthers(trends)
                )
        hours = {s: [f["robot_hours"] for f in prints[s]] for s in strategies}
        lines += [
            "- the source: intrinsic motivation is the least competent after 100 problem-tries, "
            "improves steadily and is clearly the best from about 800 on;",
            f"- random exploration took {_RobotTimeRatio(by_strategy):.2f} times the robot time "
            "of the other two (source: 207 h against 109 and 113 h, 1.86 times); robot hours per "
            "run, random minus the other two's runs: "
            + _Compare(hours["random"], hours["greedy"] + hours["intrinsic"])
            + ".",
        ]
    return lines


def _Parser() -> CommandParser:
    """The command line of ``mobee-drake experiment ch8``."""
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
        "--first-seed",
        type=NonNegativeInt,
        default=0,
        help="the first seed (fresh seeds test a setting chosen on others)",
    )
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
    _AddSettingArguments(parser)
    parser.add_argument(
        "--report-only",
        action="store_true",
        help="run nothing: write the plots and report.md of the finished runs in --output "
        "(runs/*/result.json; batteries of earlier versions too)",
    )
    AddBackendArguments(parser, workers=2)
    return parser


def _AddSettingArguments(parser: CommandParser) -> None:
    """The reach learner's settings: its predictor, its MDP, the distance unit and reach force
    (a preset or swept values) and how the greedy policy breaks ties."""
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
        "--preset",
        choices=list(REACH_PRESETS),
        default="calibrated",
        help="the distance unit and reach force: calibrated against the source's behaviour "
        "(issue 23) or metres with the full reach (the first reading; use another --output)",
    )
    parser.add_argument(
        "--reach-force",
        type=InRange(*REACH_FORCE_RANGE),
        nargs="+",
        default=None,
        help="the reach's force on the palm in N (default: the preset's; use another "
        "--output); several values sweep them (with every --distance-unit)",
    )
    parser.add_argument(
        "--distance-unit",
        type=InRange(*DISTANCE_UNIT_RANGE),
        nargs="+",
        default=None,
        help="the length in m that counts as 1 in the rewards and predictions of eq. 8.1-8.7 "
        "(default: the preset's; use another --output); several values sweep them: one "
        "battery, one MDP, the runs named <strategy>_unit<u>_force<F>_seed<k>",
    )
    parser.add_argument(
        "--tie-break",
        choices=TIE_BREAKS,
        default=ReachLearningConfig().tie_break,
        help="how the greedy policy picks among state-actions of equal value: the first "
        "(transitions before the reach) or a random one (use another --output)",
    )


def main(argv=None) -> None:
    parser = _Parser()
    argv = sys.argv[1:] if argv is None else argv
    args = parser.parse_args(argv)
    stages = args.stages or [s for s in SOURCE_STAGES if s <= args.problem_tries]
    if any(s < 0 or s > args.problem_tries for s in stages):
        parser.error(f"--stages must lie in 0..{args.problem_tries}")
    if len(set(stages)) != len(stages):
        parser.error(f"--stages must differ from each other, got {stages}")
    output = pathlib.Path(args.output)
    if args.report_only and not output.is_dir():  # (checked before a folder is made)
        parser.error(f"--report-only: {output} is not a folder of reach-learning runs")
    ClaimFolder(output, "battery")  # (a file, or a folder of the user's, refused in one line)
    preset = REACH_PRESETS[args.preset]
    variants = [
        RunSettings(
            args.strategies[0],
            0,
            args.problem_tries,
            stages,
            args.evaluations,
            args.checkpoint_every,
            args.predictor,
            args.mdp,
            force,
            unit,
            args.tie_break,
        )
        for unit in dict.fromkeys(args.distance_unit or [preset.distance_unit])
        for force in dict.fromkeys(args.reach_force or [preset.reach_force])
    ]
    settings = variants[0]
    if args.watch:  # In the battery's folder, beside its runs.
        watch = output / "watch"
        with OwnedFolder(output, "battery"):
            mdp_dir = watch / f"mdp_tries{args.mdp_tries}"
            if settings.mdp == "learned_first":
                TrainMdp(mdp_dir, args.mdp_tries)
            RunOne(watch / settings.strategy, mdp_dir, settings, StartMeshcat())
        return
    if args.report_only:
        with OwnedFolder(output, "battery"):
            results = StoredResults(output)
        if not results:
            parser.error(f"--report-only: no finished reach-learning runs in {output / 'runs'}")
    else:
        results = RunReachBattery(
            output,
            args.strategies,
            range(args.first_seed, args.first_seed + args.seeds),
            variants if len(variants) > 1 else settings,
            args.mdp_tries,
            BackendOf(args),
        )
    text = (
        f"# Reach learning (ch. 8.4)\n\n`mobee-drake experiment ch8 "
        f"{' '.join(argv)}` ({Provenance(output)})\n\n" + Report(output, results) + "\n"
    )
    WriteTextAtomically(output / "report.md", text)
    print(text)


if __name__ == "__main__":
    main()
