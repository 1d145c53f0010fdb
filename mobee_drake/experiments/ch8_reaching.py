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
never moves). ``--reach-force`` and ``--distance-unit`` override the preset's; several values of
either make a sweep: one battery on one MDP, a run of every strategy and seed per combination, and a
report that scores each combination against the source's behavioural fingerprints
(:func:`mobee_drake.experiments.ch8_measures.Fingerprints`). ``--tie-break`` chooses how the greedy
policy breaks ties of value (the first state-action by default, or a random one). ``--report-only``
rewrites the plots and report of the finished runs in ``--output`` without running anything.

The source's ambiguities (issue 33) are settings too, swept like the unit and the force:
``--plateau-rule``, ``--eq81``, ``--evaluation-history`` and a stochastic robot,
``--transition-noise`` (:data:`READINGS`; their meaning in :mod:`mobee_drake.reaching.learner`,
:mod:`mobee_drake.reaching.predictors` and :mod:`mobee_drake.planning.actuation_noise`).
``--mdps N`` learns N MDPs independently, seed k's runs on MDP k mod N, so that the report can
pair runs of one seed and treat the MDP as a block (:mod:`mobee_drake.experiments.ch8_claims`).

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
import pathlib
import time

import numpy as np

from mobee_drake.array_files import WriteArrays
from mobee_drake.atomic_files import (
    CurrentGeneration,
    StrictJson,
    WriteGeneration,
)
from mobee_drake.experiments.arms import Arms, ReachTargets, RoadmapFolder, RoadmapSpace
from mobee_drake.experiments.battery import (
    Backend,
    Job,
    JobStopped,
    RunBattery,
    RunFolder,
    StopRequested,
)
from mobee_drake.experiments.exploration import ExplorationScenario, Explore
from mobee_drake.mobee.params import Dissertation
from mobee_drake.planning.explorers import Explorer, ExplorerConfig, LoadAgentModel
from mobee_drake.planning.space_maintenance import MaintenanceConfig
from mobee_drake.planning.state_space import Lattice
from mobee_drake.planning.supervisor import ExploringAgent
from mobee_drake.reaching.appearance import AppearanceCounts, AppearanceWatch
from mobee_drake.reaching.learner import (
    ReachLearner,
    ReachLearningConfig,
)
from mobee_drake.reaching.predictors import (
    PredictorConfig,
)
from mobee_drake.reaching.reshaping import ReachSpaceKeeper
from mobee_drake.reaching.robot import SimulatedRobot
from mobee_drake.reaching.targets import TargetGrid
from mobee_drake.robots.icub import RIGHT_SHOULDER_ELBOW_JOINTS
from mobee_drake.scenario import BuildScenario, Scenario
from mobee_drake.station.executor import ReachForcing, StateActionAttractor
from mobee_drake.station.safety import SELF

RIGHT_ARM = list(RIGHT_SHOULDER_ELBOW_JOINTS)
SOURCE_STAGES = (100, 200, 400, 800, 1600, 3200, 6400)
# Where the MDP comes from: learned first and fixed (ch. 8), or with the reaches (ch. 9.4.1).
# The MDP: learned first and kept (ch. 8), learned with the reaches from the optimistic
# initialisation (ch. 9.4.1), or learned first and learned further with the reaches.
MDPS = ("learned_first", "simultaneous", "continued")
LEVELS = [0.25, 0.5, 0.75]
# The MDP's learning stops after this many actions per state-action and try asked for, whatever
# it has (the iCub's right arm needs about 1.5: 3122 actions for 5 tries of 432).
MDP_ACTIONS_PER_TRY = 10
AGENT = "right_arm"
# Robot hours of the source's five runs per strategy (ch. 8.4).
SOURCE_HOURS = {"random": 207, "greedy": 109, "intrinsic": 113}
SOURCE_STRATEGIES = tuple(SOURCE_HOURS)


def TrainMdp(
    folder: pathlib.Path,
    min_tries: int,
    seed: int = 0,
    progress=None,
    should_stop=None,
    transition_noise: float = 0.0,
    robot: str = "icub",
    roadmap: str = "",
):
    """The curious agent's model of the rank-3 lattice (or of the space of the roadmap saved in
    ``roadmap``, :func:`~mobee_drake.planning.supervisor.RoadmapStateSpace`), learned once
    (checkpointed in ``folder`` as it learns, resumed from there after a kill) on a robot with
    ``transition_noise`` (``robot``: an arm of :func:`~mobee_drake.experiments.arms.Arms`, the
    iCub's right arm by default); ``progress(n)``, if given, is told the actions done as the
    agent learns. It stops when every state-action has ``min_tries`` tries, or after
    :data:`MDP_ACTIONS_PER_TRY` actions per state-action and try (a state the arm cannot enter
    would otherwise never let it stop; the result's ``min_tries`` says which)."""
    arm = Arms()[robot]
    agent = ExploringAgent(name=AGENT, joints=list(arm.joints), levels=LEVELS, roadmap=roadmap)
    scenario = ExplorationScenario([agent], arm.objects, robot=arm.robot, random_seed=seed)
    scenario.attractor.transition_noise = transition_noise
    Explore(
        scenario,
        chunk=5.0,
        checkpoint=folder,
        stop=lambda records: _Learned(records[0].explorer, min_tries),
        progress=progress,
        should_stop=should_stop,
    )
    return LoadAgentModel(str(folder), AGENT, ExplorerConfig())


def _Learned(explorer: Explorer, min_tries: int) -> bool:
    tries = explorer.tries
    return tries.min() >= min_tries or tries.sum() >= MDP_ACTIONS_PER_TRY * min_tries * tries.size


def MdpJob(
    run: RunFolder,
    min_tries: int,
    seed: int = 0,
    transition_noise: float = 0.0,
    robot: str = "icub",
    space: str = "rank3",
) -> dict:
    """The battery job that learns the MDP (in ``run.path / "model"``) of the rank-3 lattice or,
    with ``space="trm"``, of the space of the battery's roadmap of ``robot`` (where
    ``arms.RoadmapFolder`` puts it)."""
    roadmap = str(RoadmapFolder(run.path.parent, robot)) if space == "trm" else ""
    model = TrainMdp(
        run.path / "model",
        min_tries,
        seed,
        progress=run.Progress,
        should_stop=StopRequested,
        transition_noise=transition_noise,
        robot=robot,
        roadmap=roadmap,
    )
    return dict(min_tries=int(model.tries.min()), actions=int(model.tries.sum()))


def MdpName(
    min_tries: int,
    seed: int = 0,
    transition_noise: float = 0.0,
    robot: str = "icub",
    space: str = "rank3",
) -> str:
    """The battery's job (and folder) of an MDP: ``mdp_tries<t>``, with ``_seed<m>`` and
    ``_noise<sd>`` for another seed and a stochastic robot, ``<robot>_`` before it for another
    robot than the iCub, and ``_<space>`` after it for another space than the rank-3 lattice."""
    seed_part = f"_seed{seed}" if seed else ""
    noise_part = f"_noise{transition_noise:g}" if transition_noise else ""
    robot_part = "" if robot == "icub" else f"{robot}_"
    space_part = "" if space == "rank3" else f"_{space}"
    return f"{robot_part}mdp_tries{min_tries}{seed_part}{noise_part}{space_part}"


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
    # The readings of issue 33 (see mobee_drake.reaching.learner and .predictors): when a
    # transition fails, eq. 8.1 as printed or as its prose reads, and what an evaluation keeps.
    plateau_rule: str = ReachLearningConfig().plateau_rule
    eq81: str = PredictorConfig().eq81
    evaluation_history: str = ReachLearningConfig().evaluation_history
    # A stochastic robot: the actuation noise's standard deviation (fractions of each joint's
    # range; mobee_drake.planning.actuation_noise), for the MDP and the reaches alike.
    transition_noise: float = 0.0
    # The seed of the run's MDP (independently learned MDPs, issue 33).
    mdp_seed: int = 0

    def Readings(self) -> dict[str, object]:
        """The readings of the source's ambiguities that differ from the reference ones."""
        return {n: getattr(self, n) for n, ref in READINGS.items() if getattr(self, n) != ref}


# The readings of the source's ambiguities (issue 33): each setting's reference value, and its
# short name in job names.
READINGS = {
    "plateau_rule": ReachLearningConfig().plateau_rule,
    "eq81": PredictorConfig().eq81,
    "evaluation_history": ReachLearningConfig().evaluation_history,
    "transition_noise": 0.0,
}
READING_LABELS = {
    "plateau_rule": "rule-",
    "eq81": "eq81-",
    "evaluation_history": "history-",
    "transition_noise": "noise",
}


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
    # fingerprints best (docs/reaching_history.md, "Calibration against the source's behaviour").
    "calibrated": ReachPreset(distance_unit=0.03, reach_force=300.0),
    # The first reading: SI units and the full reach, in which exploitation never moves.
    "metres": ReachPreset(PredictorConfig().distance_unit, ReachForcing().force),
}


@dc.dataclass
class ReachRun:
    """What one reach-learning run produced (:func:`RunOne`; a battery job's result).

    Attributes:
        settings: The run's settings.
        evaluations: Per stage (problem-tries done), its evaluations, each a list of the
            problem-tries' :class:`~mobee_drake.reaching.learner.TryResult` as dicts.
        log: The learner's log of actions (columns: ``reaching.learner.LOG_COLUMNS``).
        simulated_seconds: Robot time, evaluations included.
        evaluation_seconds: The robot time of the evaluations alone (None: a run from before it
            was counted); the exploration's is the difference.
        wall_seconds: Wall time of the run (over its resumptions).
        penetrating_steps: Control periods in which two solids penetrated.
        appeared_inside: Problems (tries and evaluations) set aside as the draw's: their target
            appeared inside the robot (:mod:`~mobee_drake.reaching.appearance` says when; runs
            before 1949f90 counted any penetration at the target's appearance; None: a run
            from before they were counted).
        other_penetrating_steps: The penetrating periods of the other problems (None: as
            ``appeared_inside``).
        num_transitions: The MDP's transition state-actions (the reaches follow them).
        num_states: The MDP's states.
        barrier_periods: Periods the safety barrier acted (None: a run from before it was
            counted).
        closest_to_itself: The closest the robot's solids came to each other (m; negative:
            inside each other), over the whole run (None: a run from before it was kept, or
            one whose own pairs never came within their fields).
        deepest_penetration: The deepest penetration of any pair (m; None: a run from before
            it was kept).
        mdp: ``--mdp simultaneous``: the MDP learned with the reaches (see ``_LearnedMdp``).
        space: A space that reshaped itself: its size at the end and its changes by rule
            (:meth:`~mobee_drake.reaching.reshaping.ReachSpaceKeeper.Summary`).
    """

    settings: RunSettings
    evaluations: dict[int, list[list[dict]]]
    log: list[list[float]]
    simulated_seconds: float
    wall_seconds: float
    penetrating_steps: int
    num_transitions: int
    num_states: int
    barrier_periods: int | None = None
    mdp: dict | None = None
    space: dict | None = None
    appeared_inside: int | None = None
    other_penetrating_steps: int | None = None
    evaluation_seconds: float | None = None
    closest_to_itself: float | None = None
    deepest_penetration: float | None = None

    @property
    def strategy(self) -> str:
        return self.settings.strategy

    @property
    def stages(self) -> list[int]:
        """The stages the run was evaluated at, in order."""
        return sorted(self.evaluations)

    def ToJson(self) -> dict:
        """The result as written to the run's folder (stages as JSON's string keys)."""
        data = dc.asdict(self)
        data["evaluations"] = {str(stage): e for stage, e in self.evaluations.items()}
        return data

    @classmethod
    def FromJson(cls, data: dict) -> "ReachRun":
        """A result as read back (runs of earlier versions too: before the tie-break option,
        ties were drawn at random)."""
        settings = dict(data["settings"])
        settings.setdefault("tie_break", "random")
        fields = {f.name for f in dc.fields(cls)}
        return cls(
            **{key: value for key, value in data.items() if key in fields}
            | dict(
                settings=RunSettings(**settings),
                evaluations={int(stage): e for stage, e in data["evaluations"].items()},
            )
        )


def ReachScenario(reach_force: float = ReachForcing().force, robot: str = "icub") -> Scenario:
    """The reach learner's headless kinematic robot: by default the iCub, MoBeE on the right
    shoulder and elbow, reaching with ``reach_force`` on the palm (``robot``: an arm of
    :func:`~mobee_drake.experiments.arms.Arms`, with its objects and reaching marker)."""
    arm = Arms()[robot]
    scenario = Scenario()
    scenario.robot = arm.robot
    scenario.objects = list(arm.objects)
    scenario.attractor = StateActionAttractor()
    scenario.attractor.forcing.force = reach_force
    scenario.attractor.forcing.marker = arm.marker
    if robot != "icub":
        scenario.visualization.trail_marker = ""  # (the default marker is the iCub's)
    scenario.time_step = 0.02
    scenario.mobee = Dissertation()  # (ch. 8 with the source's constants)
    scenario.data_log.enabled = False  # (The battery keeps its own data.)
    return scenario


def ReachRobot(
    space,
    target_radius: float,
    reach_force: float = ReachForcing().force,
    meshcat=None,
    transition_noise: float = 0.0,
    noise_seed: int = 0,
    robot: str = "icub",
) -> SimulatedRobot:
    """The reach learner's robot on the station of :func:`ReachScenario` (shown in real time in
    ``meshcat``, if given), with ``transition_noise`` drawn from ``noise_seed``."""
    station = BuildScenario(ReachScenario(reach_force, robot), meshcat)
    return SimulatedRobot(
        station,
        list(Arms()[robot].joints),
        space,
        target_radius,
        realtime=meshcat is not None,
        transition_noise=transition_noise,
        noise_seed=noise_seed,
    )


def _Checkpoint(
    folder: pathlib.Path,
    robot: SimulatedRobot,
    learner: ReachLearner,
    data: dict,
    keeper: ReachSpaceKeeper | None = None,
) -> None:
    """Saves the simulation, the learner (and the ``keeper``'s space) and ``data``
    (evaluations, wall time) as the newest generation of ``folder``."""

    def Write(staging: pathlib.Path) -> None:
        (staging / "simulation").mkdir()
        robot.Save(staging / "simulation")
        arrays, learner_data = learner.ToArrays()
        saved = dict(learner=learner_data, **data)
        if keeper is not None:
            space_arrays, saved["maintenance"] = keeper.ToArrays(learner)
            arrays.update(space_arrays)
        WriteArrays(staging / "learner.npz", **arrays)
        (staging / "learner.json").write_text(StrictJson(saved))

    WriteGeneration(folder, Write)


def _NewLearner(
    settings: RunSettings, mdp_dir: pathlib.Path, robot: str = "icub", roadmap: str = ""
):
    """(the MDP's model, a new reach learner on it, the target grid): the model is the
    optimistic initial one of the lattice (or of the space of the roadmap saved in
    ``roadmap``), learned with the reaches, or the one learned first (with its own space)."""
    simultaneous = settings.mdp == "simultaneous"
    arm = Arms()[robot]
    model = (
        Explorer(RoadmapSpace(arm, roadmap) if roadmap else Lattice(LEVELS, len(arm.joints)))
        if simultaneous
        else LoadAgentModel(str(mdp_dir), AGENT, ExplorerConfig())
    )
    grid = ReachTargets(arm)
    learner = ReachLearner(
        model.space,
        model.transitions.counts,
        grid.Centres(),
        ReachLearningConfig(
            strategy=settings.strategy,
            seed=settings.seed,
            predictor=PredictorConfig(
                settings.predictor, distance_unit=settings.distance_unit, eq81=settings.eq81
            ),
            learn_mdp=settings.mdp != "learned_first",
            tie_break=settings.tie_break,
            plateau_rule=settings.plateau_rule,
            evaluation_history=settings.evaluation_history,
        ),
    )
    return model, learner, grid


def _LearnedMdp(run_dir: pathlib.Path, learner: ReachLearner, model: Explorer) -> dict:
    """Saves the MDP learned with the reaches (``mdp.npz``); the state-actions it learned about
    and their learned chance of reaching their goal."""
    counts = learner.model.counts
    WriteArrays(run_dir / "mdp.npz", counts=counts)
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
    maintenance: MaintenanceConfig | None = None,
    robot: str = "icub",
    roadmap: str = "",
) -> dict:
    """One run of the battery (resumes from ``run_dir/checkpoint``); returns its result. With
    ``meshcat``, the run is shown there in real time; ``progress(n)``, if given, is told the
    problem-tries done at every checkpoint; ``should_stop()``, if given, is asked after every
    problem-try, and when True the run saves its checkpoint and raises JobStopped. With
    ``maintenance``, the learner's space reshapes itself (ch. 9.4.5,
    :class:`~mobee_drake.reaching.reshaping.ReachSpaceKeeper`). ``robot``: an arm of
    :func:`~mobee_drake.experiments.arms.Arms` (its MDP in ``mdp_dir``), the iCub's by default.
    ``roadmap``: with ``mdp="simultaneous"``, a saved roadmap whose space the learner starts on
    instead of the lattice (an MDP learned first has its own space)."""
    run_dir.mkdir(parents=True, exist_ok=True)
    model, learner, grid = _NewLearner(settings, mdp_dir, robot, roadmap)
    keeper = None
    if maintenance is not None:
        keeper = ReachSpaceKeeper(maintenance, learner.space.num_states)
    robot = ReachRobot(
        model.space,
        grid.radius,
        settings.reach_force,
        meshcat,
        transition_noise=settings.transition_noise,
        noise_seed=settings.seed,
        robot=robot,
    )
    checkpoint = run_dir / "checkpoint"
    data = _Resume(checkpoint, robot, learner, keeper)
    started = time.perf_counter() - data["wall_seconds"]
    if data["appearance"] is not None:  # (None: resumed from a checkpoint without the counts)
        robot = AppearanceWatch(robot, AppearanceCounts(**data["appearance"]))

    def Save():
        data["wall_seconds"] = time.perf_counter() - started
        data["target"] = None if robot.target is None else robot.target.tolist()
        if data["appearance"] is not None:
            data["appearance"] = dc.asdict(robot.counts)
        _Checkpoint(checkpoint, robot, learner, data, keeper)
        if progress is not None:
            progress(int(learner.problem_tries.sum()))

    while True:
        done = int(learner.problem_tries.sum())
        if done in settings.stages and str(done) not in data["evaluations"]:
            _EvaluateStage(settings, learner, robot, data, done)
            Save()
        if done >= settings.problem_tries:
            break
        if keeper is not None:  # (after the stage's evaluation; resumed, the round is redone)
            keeper.Maintain(learner, robot, done)
        since = len(learner.log)
        learner.Explore(robot)
        if keeper is not None:
            keeper.Observe(learner, since)
        if (done + 1) % settings.checkpoint_every == 0:
            Save()
        if should_stop is not None and should_stop():
            Save()
            raise JobStopped(f"{run_dir.name}: stopped after {done + 1} problem-tries")
    if data["appearance"] is not None:
        robot.Close()
    Save()
    extra = {}
    if keeper is not None:  # (the MDP's space changed: its summary instead)
        extra["space"] = keeper.Summary(learner)
    elif settings.mdp == "simultaneous":
        extra = dict(mdp=_LearnedMdp(run_dir, learner, model))
    return _Result(settings, learner, robot, data, extra).ToJson()


def _EvaluateStage(settings: RunSettings, learner, robot, data: dict, done: int) -> None:
    """The exploitation evaluations of the stage at ``done`` problem-tries (ch. 8.3.3), each
    problem's records, into ``data``, and their robot time (when the run times them)."""
    began = robot.simulated_seconds
    data["evaluations"][str(done)] = [
        [dc.asdict(r) for r in learner.Evaluate(robot, seed=(settings.seed, done, e))]
        for e in range(settings.evaluations)
    ]
    if data["evaluation_seconds"] is not None:
        data["evaluation_seconds"] += robot.simulated_seconds - began


def _Resume(checkpoint: pathlib.Path, robot, learner, keeper) -> dict:
    """Puts ``robot``, ``learner`` (and the ``keeper``'s space) where the newest generation of
    ``checkpoint`` left them; the run's data (evaluations, wall time, the problem's target, the
    :class:`AppearanceWatch`'s counts), empty for a new run."""
    generation = CurrentGeneration(checkpoint)
    if generation is None:
        return dict(
            evaluations={}, wall_seconds=0.0, target=None, appearance={}, evaluation_seconds=0.0
        )
    saved = json.loads((generation / "learner.json").read_text())
    saved.setdefault("appearance", None)  # (a checkpoint from before the count)
    saved.setdefault("evaluation_seconds", None)  # (and before the evaluations were timed)
    arrays = np.load(generation / "learner.npz")
    if keeper is not None:
        keeper.Restore(learner, robot, arrays, saved.pop("maintenance"))
    learner.LoadArrays(arrays, saved.pop("learner"))
    robot.Load(generation / "simulation")
    if saved["target"] is not None:
        robot.SetProblem(np.array(saved["target"]))
    return saved


def _Result(settings: RunSettings, learner, robot, data: dict, extra: dict) -> ReachRun:
    """A finished run's result (``robot`` watched for targets appearing inside it, unless the
    run began before that was counted)."""
    safety = robot.Safety()
    counts = robot.counts if isinstance(robot, AppearanceWatch) else None
    return ReachRun(
        settings=settings,
        evaluations={int(stage): e for stage, e in data["evaluations"].items()},
        log=learner.ToArrays()[0]["log"].tolist(),
        simulated_seconds=robot.simulated_seconds,
        wall_seconds=data["wall_seconds"],
        penetrating_steps=safety.penetrating_steps,
        barrier_periods=safety.barrier_periods,
        closest_to_itself=safety.closest_approach[SELF],
        deepest_penetration=safety.deepest_penetration,
        num_transitions=learner.num_transitions,
        num_states=learner.space.num_states,
        appeared_inside=None if counts is None else counts.appeared_inside,
        other_penetrating_steps=None if counts is None else counts.other_penetrating_steps,
        evaluation_seconds=data["evaluation_seconds"],
        **extra,
    )


def LoadTrainedLearner(run_dir: str | pathlib.Path) -> tuple[ReachLearner, TargetGrid]:
    """The learner of a run of the battery as its newest checkpoint holds it, and its targets.

    Raises:
        ValueError: naming the folder, if it is not a run of the battery with a checkpoint.
    """
    run_dir = pathlib.Path(run_dir)
    try:
        job = json.loads((run_dir / "job.json").read_text())
        settings = RunSettings(**job["settings"])
    except (OSError, ValueError, KeyError, TypeError):
        raise ValueError(f"{run_dir}: not a run of `mobee-drake experiment ch8`") from None
    generation = CurrentGeneration(run_dir / "checkpoint")
    if generation is None:
        raise ValueError(f"{run_dir}: the run has no checkpoint yet")
    _, learner, grid = _NewLearner(settings, run_dir.parent / job["mdp"] / "model")
    saved = json.loads((generation / "learner.json").read_text())
    learner.LoadArrays(np.load(generation / "learner.npz"), saved["learner"])
    return learner, grid


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
    """A sweep's name for a run's distance unit and reach force, and its readings that are not
    the reference ones (job names, report sections): e.g. ``unit0.03_force300_rule-arrival``."""
    readings = "".join(
        f"_{READING_LABELS[name]}{value:g}" if isinstance(value, float) else
        f"_{READING_LABELS[name]}{value}"
        for name, value in settings.Readings().items()
    )  # fmt: skip
    return f"unit{settings.distance_unit:g}_force{settings.reach_force:g}{readings}"


def RunReachBattery(
    output: pathlib.Path,
    strategies,
    seeds: range,
    settings: RunSettings | list[RunSettings],
    mdp_tries: int,
    backend: Backend,
    mdps: int = 1,
) -> list["ReachRun"]:
    """The MDPs (unless learned with the reaches), then a run of ``settings`` for every strategy
    and seed, on ``backend`` (see :mod:`mobee_drake.experiments.battery`). A list of settings is
    a sweep, its runs named ``<strategy>_<SettingLabel>_seed<k>`` (a single setting's
    ``<strategy>_seed<k>``). ``mdps`` MDPs are learned independently (seeds 0 ... mdps - 1, on a
    robot with each setting's transition noise); seed k's runs use MDP k mod ``mdps``, so the
    runs of one seed share their MDP and their evaluation seeds (paired across strategies and
    settings)."""
    variants = [settings] if isinstance(settings, RunSettings) else list(settings)
    if not variants:
        raise ValueError("a reach-learning battery needs at least one setting")
    if len({v.mdp for v in variants}) > 1:
        raise ValueError("a sweep's settings must share --mdp")
    labels = [SettingLabel(v) for v in variants]
    if len(set(labels)) < len(labels):
        raise ValueError(f"a sweep's settings repeat: {sorted(labels)}")
    if variants[0].mdp == "simultaneous" and mdps > 1:
        raise ValueError("--mdps: runs that learn the MDP with the reaches share none")
    sweep = len(variants) > 1
    noises = sorted({v.transition_noise for v in variants})
    used = sorted({seed % mdps for seed in seeds})  # (fewer seeds than MDPs: only theirs)
    if variants[0].mdp == "learned_first":
        mdp_jobs = [
            Job(
                MdpName(mdp_tries, m, noise),
                MdpJob,
                dict(min_tries=mdp_tries, seed=m, transition_noise=noise),
            )
            for noise in noises
            for m in used
        ]
        RunBattery(mdp_jobs, output, backend=backend, description="the MDPs (actions)")
    jobs = [
        Job(
            f"{strategy}_{SettingLabel(variant)}_seed{seed}" if sweep else f"{strategy}_seed{seed}",
            ReachJob,
            dict(
                mdp=MdpName(mdp_tries, seed % mdps, variant.transition_noise),
                settings=dc.asdict(
                    dc.replace(variant, strategy=strategy, seed=seed, mdp_seed=seed % mdps)
                ),
            ),
            total=variant.problem_tries,
        )
        # Seed by seed: a battery stopped part-way leaves whole pairs (every setting and strategy
        # of its first seeds).
        for seed in seeds
        for variant in variants
        for strategy in strategies
    ]
    results = RunBattery(jobs, output, backend=backend, description="reach learning")
    return [ReachRun.FromJson(result) for result in results.values()]


def StoredResults(output: pathlib.Path) -> list[ReachRun]:
    """The results of the finished reach-learning runs in a battery folder, in name order."""
    results = []
    for path in sorted(pathlib.Path(output).glob("runs/*/result.json")):
        result = json.loads(path.read_text())
        if "evaluations" in result:  # (Not the MDP's.)
            results.append(ReachRun.FromJson(result))
    return results
