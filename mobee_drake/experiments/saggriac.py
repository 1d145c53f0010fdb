"""The experiments of Baranes & Oudeyer (IROS 2010), Sec. IV: four methods on the 15-joint arm,
with the options and readings of issue 23 beside the paper's settings.

Each run (experiment, method, variant, seed, budget) is a job of the battery runner
(:mod:`mobee_drake.experiments.battery`): its result is written atomically as soon as it
finishes, and on restart runs with a result are skipped, so an interrupted battery loses at most
the runs in progress. Then curves (CSV), plots like Fig. 3-5 (PNG), run-level statistics (effect
sizes with confidence intervals and power beside the p-values) and a markdown report are written
from whatever results exist.

A variant (``--variants``) is a named set of settings: ``paper`` (the reference row), the
goal-selection options ``stall``, ``model-error``, ``stall+model-error``, ``weighted-split``
(SAGG methods), the controls of issue 34 (``variance-only``, the window sweep ``window-10``,
``window-40``, ``window-80``) and the drift-free ``set`` reading of the actuator-space methods;
see VARIANTS.

Usage::

    mobee-drake experiment saggriac --experiments 1 2 --seeds 30 --workers 1 --output DIR
    mobee-drake experiment saggriac --experiments 2 --methods SAGG-RIAC --variants paper stall \
        --first-seed 200 --seeds 30 --output DIR
    mobee-drake experiment saggriac --smoke --output /tmp/saggriac_smoke [--ray [ADDRESS]]
"""

from collections.abc import Callable
import dataclasses
import json
import math
import pathlib
import time

import numpy as np
from scipy.spatial import cKDTree

from mobee_drake.experiments.battery import (
    RESULT,
    Backend,
    Job,
    RunBattery,
    RunFolder,
)
from mobee_drake.goal_babbling.baselines import ActuatorRandom, ActuatorRiac, SaggRandom
from mobee_drake.goal_babbling.config import (
    ConfigToDict,
    Experiment1Config,
    Experiment2Config,
    GoalBabblingConfig,
)
from mobee_drake.goal_babbling.evaluation import Evaluator
from mobee_drake.goal_babbling.interest_null import LeafInterests
from mobee_drake.goal_babbling.sagg_riac import SaggRiac

# A battery's size: the paper's budgets (30 seeds where it ran 15), and --smoke's.
FULL = {"seeds": 30, "budget_exp1": 50_000, "budget_exp2": 200_000, "checkpoints": 10}
SMOKE = {"seeds": 2, "budget_exp1": 600, "budget_exp2": 800, "checkpoints": 2}

METHODS = {
    learner.name: learner for learner in (SaggRiac, SaggRandom, ActuatorRandom, ActuatorRiac)
}
SAGG_METHODS = ("SAGG-RIAC", "SAGG-Random")
ACTUATOR_METHODS = ("ACTUATOR-Random", "ACTUATOR-RIAC")
EXPERIMENT_CONFIGS = {1: Experiment1Config, 2: Experiment2Config}
NUM_HISTOGRAM_WINDOWS = 4
# Tips kept per run for the coverage figure (every k-th sample of the memory).
TIP_SAMPLES = 2000
MEASURE_TITLES = {
    "reaching_error": "reaching error, mean over the test goals [units]",
    "reaching_error_median": "reaching error, median over the test goals [units]",
    "reached_share": "share of test goals reached within 1 unit [fraction]",
    "prediction_error": "prediction error, reachable-area postures [units]",
    "prediction_error_near_rest": "prediction error, near-rest postures [units]",
}


def _Stall(config: GoalBabblingConfig) -> None:
    config.low_level.stall_steps = 2


def _ModelError(config: GoalBabblingConfig) -> None:
    config.low_level.exploration_trigger = "model"


def _StallModelError(config: GoalBabblingConfig) -> None:
    _Stall(config)
    _ModelError(config)


def _WeightedSplit(config: GoalBabblingConfig) -> None:
    config.interest.split_criterion = "weighted"


def _Set(config: GoalBabblingConfig) -> None:
    config.actuator.reading = "set"


def _VarianceOnly(config: GoalBabblingConfig) -> None:
    config.interest.region_measure = "variance"


def _Window(window: int) -> Callable[[GoalBabblingConfig], None]:
    def Apply(config: GoalBabblingConfig) -> None:
        config.interest.window = window  # (min_child_goals stays 10: splits stay possible)

    return Apply


# The window sweep of issue 34 (zeta; the reference is 20).
SWEPT_WINDOWS = (10, 40, 80)


@dataclasses.dataclass(frozen=True)
class Variant:
    """A named set of settings applied to the experiment's configuration.

    Attributes:
        description: For the help and the report.
        methods: The methods it applies to (runs of other methods are not made).
        Apply: Changes a configuration in place.
    """

    description: str
    methods: tuple[str, ...]
    Apply: Callable[[GoalBabblingConfig], None]


VARIANTS = {
    "paper": Variant("the paper's settings and our reading (the reference)", tuple(METHODS), None),
    "stall": Variant(
        "an attempt ends after 2 reaching steps in a row without 0.05 units of progress",
        SAGG_METHODS,
        _Stall,
    ),
    "model-error": Variant(
        "exploration only when the local model mispredicts the step (not when the step is "
        "impossible)",
        SAGG_METHODS,
        _ModelError,
    ),
    "stall+model-error": Variant("both options above", SAGG_METHODS, _StallModelError),
    "weighted-split": Variant(
        "explauto's split criterion |L| |G| |delta interest|", ("SAGG-RIAC",), _WeightedSplit
    ),
    "set": Variant(
        "actuator methods put the arm in a drawn posture each step (no drift)",
        ACTUATOR_METHODS,
        _Set,
    ),
    "variance-only": Variant(
        "eq. 3 draws regions by the spread of their last zeta competences, not by eq. 2",
        ("SAGG-RIAC",),
        _VarianceOnly,
    ),
    **{
        f"window-{window}": Variant(
            f"zeta = {window} (eq. 2's window; the reference 20)", ("SAGG-RIAC",), _Window(window)
        )
        for window in SWEPT_WINDOWS
    },
}


@dataclasses.dataclass(frozen=True)
class RunSpec:
    """One learning run.

    Attributes:
        experiment: 1 or 2 (Sec. IV-B-1 or IV-B-2).
        method: A key of METHODS.
        seed: Learner seed.
        budget: Micro-actions.
        num_checkpoints: Evaluations after step 0.
        variant: A key of VARIANTS.
    """

    experiment: int
    method: str
    seed: int
    budget: int
    num_checkpoints: int
    variant: str = "paper"

    def Name(self) -> str:
        """Name of the run (its folder in the battery's runs)."""
        suffix = "" if self.variant == "paper" else f"_{self.variant.replace('+', '-and-')}"
        return f"exp{self.experiment}_{self.method}{suffix}_seed{self.seed:02d}_budget{self.budget}"

    def Label(self) -> str:
        """The group of the run in tables and plots: 'METHOD', or 'METHOD [variant]' unless the
        variant is paper."""
        return self.method if self.variant == "paper" else f"{self.method} [{self.variant}]"


# The columns of BabblingRun.goal_log's rows.
GOAL_LOG_COLUMNS = ("time_step", "x", "y", "competence", "mode", "attempt", "tree_points")


@dataclasses.dataclass
class BabblingRun:
    """What one learner's run produced (a battery job's result, :func:`RunOne`).

    Attributes:
        spec: The run.
        config: Its configuration (``ConfigToDict``).
        wall_time_s: Wall time of the run.
        time_steps: Micro-actions taken.
        curve: One evaluation per checkpoint: ``time_step`` and every measure of
            ``goal_babbling.evaluation.MEASURES``.
        final_reaching_errors: The last evaluation's error per test goal (units).
        diagnostics: :func:`Diagnostics` of the run.
        tip_sample: Every k-th stored hand tip (TIP_SAMPLES of them at most).
        goal_log: Goal-space methods: one row per goal or subgoal (GOAL_LOG_COLUMNS).
        region_snapshots: SAGG-RIAC: the regions at the end of each goal window (Fig. 3).
        num_regions: RIAC methods: the leaves of the region tree at the end.
        leaf_interests: SAGG methods: every final leaf's interest against its permutation null
            (:class:`mobee_drake.goal_babbling.interest_null.LeafInterest` as a dict).
    """

    spec: RunSpec
    config: dict
    wall_time_s: float
    time_steps: int
    curve: list[dict[str, float]]
    final_reaching_errors: list[float]
    diagnostics: dict[str, float]
    tip_sample: list[list[float]]
    goal_log: list[list[float]] | None = None
    region_snapshots: list[dict] | None = None
    num_regions: int | None = None
    leaf_interests: list[dict] | None = None

    @property
    def label(self) -> str:
        """The run's group in tables and plots (RunSpec.Label)."""
        return self.spec.Label()

    def ToJson(self) -> dict:
        """The result as written to the run's folder."""
        return dataclasses.asdict(self)

    def Goals(self) -> np.ndarray:
        """The goal log's rows of goals (subgoals excluded), columns GOAL_LOG_COLUMNS."""
        log = np.array(self.goal_log, dtype=float).reshape(-1, len(GOAL_LOG_COLUMNS))
        return log[log[:, GOAL_LOG_COLUMNS.index("mode")] > 0]

    @classmethod
    def FromJson(cls, data: dict) -> "BabblingRun":
        """A result as read back from a run's folder."""
        # Results written before BabblingRun also hold the goal log's column names.
        data = {key: value for key, value in data.items() if key != "goal_log_columns"}
        return cls(**dict(data, spec=RunSpec(**data["spec"])))


def MakeConfig(spec: RunSpec) -> GoalBabblingConfig:
    """The configuration of a run: the experiment's preset, its seed and budget, its variant."""
    config = EXPERIMENT_CONFIGS[spec.experiment](seed=spec.seed, budget=spec.budget)
    config.evaluation.num_checkpoints = spec.num_checkpoints
    variant = VARIANTS[spec.variant]
    if variant.Apply is not None:
        variant.Apply(config)
    return config


def _RegionSnapshots(learner: SaggRiac) -> list[dict]:
    """Goal windows (quarters of the goals, subgoals excluded) and the regions at the end of each
    (Fig. 3).
    """
    log = np.array(learner.goal_log, dtype=float).reshape(-1, 7)
    goal_rows = np.flatnonzero(log[:, 4] > 0)
    snapshots = []
    for window in range(NUM_HISTOGRAM_WINDOWS):
        begin = len(goal_rows) * window // NUM_HISTOGRAM_WINDOWS
        end = len(goal_rows) * (window + 1) // NUM_HISTOGRAM_WINDOWS
        tree_points = int(log[goal_rows[end - 1], 6]) if end > begin else 0
        boxes = [
            [*region.low.tolist(), *region.high.tolist()]
            for region in learner.tree.LeavesAt(tree_points)
        ]
        snapshots.append({"first_goal": begin, "end_goal": end, "regions": boxes})
    return snapshots


def Diagnostics(learner, evaluator: Evaluator) -> dict:
    """What a run did, beside how well it learnt (issue 23).

    All methods: ``tip_coverage``, the share of the test goals with a stored tip within
    EvaluationConfig.reached_distance (how much of the reachable area the memory covers), and
    ``tip_spread``, the root mean square distance of the stored tips from the rest tip. Actuator
    methods: ``drift_ratio``, over windows of the reset period, the mean norm of the summed joint
    changes divided by that of an unbiased random walk of the exploration box (sqrt(period n /
    3) times the box half-width): about 1 for ACTUATOR-Random, larger when the actions are biased
    (in the "walk" reading the arm then drifts). Goal-space methods: ``exploration_share``
    (micro-actions in exploration phases), ``unreachable_share`` (micro-actions spent on (sub)goals
    farther than the arm's length from the base), ``stalled_share`` (attempts ended by the stall
    option), ``attempts``.

    Args:
        learner: A learner after its run.
        evaluator: Its evaluator (for the test goals).

    Returns:
        {name: value}.
    """
    config, memory = learner.config, learner.memory
    tips = memory.positions[: memory.size]
    reached = config.evaluation.reached_distance
    nearest, _ = cKDTree(tips).query(evaluator.test_set.goals, k=1)
    result = {
        "tip_coverage": float(np.mean(nearest <= reached)),
        "tip_spread": float(np.sqrt(np.mean(np.sum((tips - learner.rest_position) ** 2, axis=1)))),
    }
    if isinstance(learner, (ActuatorRandom, ActuatorRiac)):
        # Runs shorter than a period (smoke runs) make one shorter window.
        period = max(1, min(config.ActuatorResetPeriod(), memory.size))
        windows = memory.size // period
        sums = memory.joint_steps[: windows * period].reshape(windows, period, -1).sum(axis=1)
        unbiased = config.low_level.exploration_joint_step * math.sqrt(
            period * config.arm.num_joints / 3.0
        )
        result["drift_ratio"] = float(np.mean(np.linalg.norm(sums, axis=1)) / unbiased)
    if isinstance(learner, SaggRiac):
        log = np.array(learner.goal_log, dtype=float).reshape(-1, 7)
        actions = np.diff(log[:, 0], prepend=0.0)
        far = np.hypot(log[:, 1], log[:, 2]) > config.arm.total_length
        steps = max(learner.time_steps, 1)
        result["exploration_share"] = learner.exploration_steps / steps
        result["unreachable_share"] = float(actions[far].sum() / steps)
        result["stalled_share"] = learner.stalled_attempts / max(learner.num_attempts, 1)
        result["attempts"] = learner.num_attempts
    return result


class _ReportingEvaluator:
    """The run's evaluator, telling the battery's display at each checkpoint how many
    micro-actions are done."""

    def __init__(self, evaluator: Evaluator, run: RunFolder):
        self._evaluator, self._run = evaluator, run

    def __call__(self, memory, rest_position) -> dict:
        self._run.Progress(memory.size)
        return self._evaluator(memory, rest_position)


def RunOne(run: RunFolder, spec: dict) -> dict:
    """Runs one learner (a battery job; ``spec`` a :class:`RunSpec` as a dict) and returns its
    :class:`BabblingRun` as written."""
    spec = RunSpec(**spec)
    config = MakeConfig(spec)
    evaluator = Evaluator(config)
    started = time.perf_counter()
    learner = METHODS[spec.method](config, _ReportingEvaluator(evaluator, run)).Run()
    stride = max(1, learner.memory.size // TIP_SAMPLES)
    result = BabblingRun(
        spec=spec,
        config=ConfigToDict(config),
        wall_time_s=time.perf_counter() - started,
        time_steps=learner.time_steps,
        curve=learner.curve,
        final_reaching_errors=[float(error) for error in evaluator.reaching_errors],
        diagnostics=Diagnostics(learner, evaluator),
        tip_sample=learner.memory.positions[: learner.memory.size : stride].round(3).tolist(),
    )
    if isinstance(learner, SaggRiac):
        result.goal_log = [list(map(float, row)) for row in learner.goal_log]
        result.region_snapshots = _RegionSnapshots(learner)
        result.leaf_interests = [
            dataclasses.asdict(leaf) for leaf in LeafInterests(learner.tree, spec.seed)
        ]
    if isinstance(learner, (SaggRiac, ActuatorRiac)):
        result.num_regions = len(learner.tree.leaves)
    return result.ToJson()


def RunAll(specs: list[RunSpec], output: pathlib.Path, backend: Backend) -> list[BabblingRun]:
    """Runs the missing runs on ``backend`` (see :mod:`mobee_drake.experiments.battery`) and
    returns every run's result."""
    jobs = [
        Job(spec.Name(), RunOne, {"spec": dataclasses.asdict(spec)}, total=spec.budget)
        for spec in specs
    ]
    results = RunBattery(jobs, output, backend=backend, description="SAGG-RIAC")
    return [BabblingRun.FromJson(result) for result in results.values()]


def LoadRuns(specs: list[RunSpec], output: pathlib.Path) -> list[BabblingRun]:
    """Results of the given runs that exist on disk."""
    paths = [output / "runs" / spec.Name() / RESULT for spec in specs]
    return [BabblingRun.FromJson(json.loads(path.read_text())) for path in paths if path.exists()]
