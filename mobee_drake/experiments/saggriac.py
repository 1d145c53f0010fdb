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
(SAGG methods) and the drift-free ``set`` reading of the actuator-space methods; see VARIANTS.

Usage::

    mobee-drake experiment saggriac --experiments 1 2 --seeds 30 --workers 1 --output DIR
    mobee-drake experiment saggriac --experiments 2 --methods SAGG-RIAC --variants paper stall \
        --first-seed 200 --seeds 30 --output DIR
    mobee-drake experiment saggriac --smoke --output /tmp/saggriac_smoke [--ray [ADDRESS]]
"""

import argparse
from collections.abc import Callable
import csv
import dataclasses
import json
import math
import pathlib
import sys
import time

import numpy as np
from scipy import stats
from scipy.spatial import cKDTree

from mobee_drake.atomic_files import StrictJson, WriteTextAtomically
from mobee_drake.experiments.arguments import CommandParser, NonNegativeInt, PositiveInt
from mobee_drake.experiments.battery import (
    RESULT,
    AddBackendArguments,
    Backend,
    BackendOf,
    Job,
    Provenance,
    RunBattery,
    RunFolder,
)
from mobee_drake.experiments.plots import Figure, SaveFigure, plt
from mobee_drake.experiments.statistics import CompareRuns
from mobee_drake.goal_babbling.baselines import ActuatorRandom, ActuatorRiac, SaggRandom
from mobee_drake.goal_babbling.config import (
    ConfigFromDict,
    ConfigToDict,
    Experiment1Config,
    Experiment2Config,
    GoalBabblingConfig,
)
from mobee_drake.goal_babbling.evaluation import MEASURES, Evaluator, MakeTestSet
from mobee_drake.goal_babbling.sagg_riac import SaggRiac
from mobee_drake.owned_folders import OwnedFolder

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
        """The group of the run in tables and plots: the method, and the variant unless paper."""
        return Label(dataclasses.asdict(self))


def Label(spec: dict) -> str:
    """The group of a run (its spec as a dict): 'METHOD' or 'METHOD [variant]'."""
    variant = spec.get("variant", "paper")
    return spec["method"] if variant == "paper" else f"{spec['method']} [{variant}]"


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


def RunOne(run: RunFolder, spec: dict) -> dict:
    """Runs one learner (a battery job; ``spec`` a :class:`RunSpec` as a dict) and returns its
    result.
    """
    spec = RunSpec(**spec)
    config = MakeConfig(spec)
    evaluator = Evaluator(config)
    started = time.perf_counter()
    learner = METHODS[spec.method](config, evaluator).Run()
    stride = max(1, learner.memory.size // TIP_SAMPLES)
    result = {
        "spec": dataclasses.asdict(spec),
        "config": ConfigToDict(config),
        "wall_time_s": time.perf_counter() - started,
        "time_steps": learner.time_steps,
        "curve": learner.curve,
        "final_reaching_errors": [float(error) for error in evaluator.reaching_errors],
        "diagnostics": Diagnostics(learner, evaluator),
        "tip_sample": learner.memory.positions[: learner.memory.size : stride].round(3).tolist(),
    }
    if isinstance(learner, SaggRiac):
        result["goal_log"] = [list(map(float, row)) for row in learner.goal_log]
        result["goal_log_columns"] = [
            "time_step",
            "x",
            "y",
            "competence",
            "mode",
            "attempt",
            "tree_points",
        ]
        result["num_regions"] = len(learner.tree.leaves)
        result["region_snapshots"] = _RegionSnapshots(learner)
    if isinstance(learner, ActuatorRiac):
        result["num_regions"] = len(learner.tree.leaves)
    return result


def RunAll(specs: list[RunSpec], output: pathlib.Path, backend: Backend) -> list[dict]:
    """Runs the missing runs on ``backend`` (see :mod:`mobee_drake.experiments.battery`) and
    returns every run's result."""
    jobs = [Job(spec.Name(), RunOne, {"spec": dataclasses.asdict(spec)}) for spec in specs]
    return list(RunBattery(jobs, output, backend=backend, description="SAGG-RIAC").values())


def LoadRuns(specs: list[RunSpec], output: pathlib.Path) -> list[dict]:
    """Results of the given runs that exist on disk."""
    paths = [output / "runs" / spec.Name() / RESULT for spec in specs]
    return [json.loads(path.read_text()) for path in paths if path.exists()]


def _Final(runs: list[dict], group: str, measure: str) -> np.ndarray:
    return np.array([run["curve"][-1][measure] for run in runs if Label(run["spec"]) == group])


# The comparisons behind the paper's claims (Sec. IV-B): (first group, second group, claim).
CLAIM_PAIRS = (
    ("SAGG-RIAC", "ACTUATOR-Random", "1"),
    ("SAGG-Random", "ACTUATOR-Random", "1"),
    ("SAGG-RIAC", "ACTUATOR-Random [set]", "1"),
    ("SAGG-Random", "ACTUATOR-Random [set]", "1"),
    ("ACTUATOR-RIAC", "ACTUATOR-Random", "2"),
    ("ACTUATOR-RIAC [set]", "ACTUATOR-Random [set]", "2"),
    ("SAGG-RIAC", "SAGG-Random", "3"),
)


def Pairs(groups: list[str]) -> list[tuple[str, str, str]]:
    """The comparisons to test among the groups present: the claims' pairs, and each option of a
    goal-space method against the same method with the paper's settings."""
    pairs = [pair for pair in CLAIM_PAIRS if pair[0] in groups and pair[1] in groups]
    for group in groups:
        method, _, variant = group.partition(" [")
        if variant and method in SAGG_METHODS and method in groups:
            pairs.append((group, method, "option"))
    return pairs


def Statistics(runs: list[dict], groups: list[str]) -> list[dict]:
    """Run-level tests at the end of the runs, per measure: a one-way ANOVA over the paper's four
    methods, and each pair of Pairs() with effect sizes, intervals and power (see
    :func:`mobee_drake.experiments.statistics.CompareRuns`).

    Args:
        runs: Results of one experiment.
        groups: Groups (labels) present.

    Returns:
        Rows {measure, test, groups, claim, p_value, ...}; a pair's row carries every field of
        :class:`mobee_drake.experiments.statistics.Comparison`.
    """
    rows = []
    for measure in MEASURES:
        samples = {group: _Final(runs, group, measure) for group in groups}
        present = [g for g in groups if g in METHODS and samples[g].size >= 2]
        if len(present) >= 2:
            constant = all(np.ptp(samples[g]) == 0 for g in present)
            result = None if constant else stats.f_oneway(*(samples[g] for g in present))
            rows.append(
                {
                    "measure": measure,
                    "test": "one-way ANOVA",
                    "groups": " / ".join(present),
                    "claim": "",
                    "p_value": math.nan if result is None else float(result.pvalue),
                    "means": [float(samples[g].mean()) for g in present],
                }
            )
        for first, second, claim in Pairs(groups):
            if samples[first].size < 2 or samples[second].size < 2:
                continue
            comparison = dataclasses.asdict(CompareRuns(samples[first], samples[second]))
            rows.append(
                {
                    "measure": measure,
                    "test": "pair",
                    "groups": f"{first} vs {second}",
                    "claim": claim,
                    "p_value": comparison["anova_p"],
                    **comparison,
                }
            )
    return rows


def WriteCurves(runs: list[dict], path: pathlib.Path) -> None:
    """CSV with one row per (method, variant, seed, checkpoint)."""
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(["experiment", "method", "variant", "seed", "time_step", *MEASURES])
        for run in runs:
            spec = run["spec"]
            for point in run["curve"]:
                writer.writerow(
                    [
                        spec["experiment"],
                        spec["method"],
                        spec.get("variant", "paper"),
                        spec["seed"],
                        point["time_step"],
                        *(f"{point[measure]:.6g}" for measure in MEASURES),
                    ]
                )


def CurvesFigure(
    runs: list[dict], groups: list[str], experiment: int, measures: list[str] | None = None
) -> Figure:
    """Mean and standard deviation over seeds of each measure against time steps (Fig. 4-5).

    Args:
        runs: Results.
        groups: Labels of the groups drawn (see Label), in order.
        experiment: For the title.
        measures: Measures drawn, one panel each (default: those of MEASURE_TITLES in the runs).
    """
    if measures is None:
        present = runs[0]["curve"][0]
        measures = [measure for measure in MEASURE_TITLES if measure in present]
        measures += [m for m in present if m != "time_step" and m not in measures]
    columns = min(len(measures), 3)
    rows = math.ceil(len(measures) / columns)
    figure, axes = plt.subplots(rows, columns, figsize=(6 * columns, 4.5 * rows), squeeze=False)
    for axis in axes.flat[len(measures) :]:
        axis.remove()
    for offset, group in enumerate(groups):
        group_runs = [run for run in runs if Label(run["spec"]) == group]
        if not group_runs:
            continue
        steps = np.array([point["time_step"] for point in group_runs[0]["curve"]]) / 1000
        for axis, measure in zip(axes.flat, measures, strict=False):
            values = np.array([[point[measure] for point in run["curve"]] for run in group_runs])
            mean, spread = values.mean(axis=0), values.std(axis=0)
            (line,) = axis.plot(steps, mean, label=f"{group} ({len(group_runs)} seeds)")
            # Error bars shifted per group for readability, as in the paper's figures.
            shift = (offset - (len(groups) - 1) / 2) * 0.01 * steps[-1]
            axis.errorbar(
                steps[1:] + shift,
                mean[1:],
                yerr=spread[1:],
                fmt="none",
                color=line.get_color(),
                capsize=2,
                alpha=0.7,
            )
    for axis, measure in zip(axes.flat, measures, strict=False):
        title = MEASURE_TITLES.get(measure, measure.replace("_", " "))
        axis.set(
            xlabel="time steps [thousands of micro-actions]",
            ylabel=title[0].upper() + title[1:],
            title=title.split(" [")[0],
        )
        axis.grid(alpha=0.3)
        axis.legend(fontsize=7, title="group (mean ± std over seeds)", title_fontsize=7)
    figure.suptitle(
        f"Experiment {experiment}: the learnt models' test measures, mean ± std over seeds "
        "(cf. the paper's Fig. 4-5)"
    )
    figure.tight_layout()
    return figure


def EffectsFigure(statistics: list[dict], experiment: int, measures: list[str]) -> Figure:
    """Forest plot: each pair's Cohen's d with its 95 % interval, one panel per measure.

    Args:
        statistics: Rows of Statistics().
        experiment: For the title.
        measures: The measures drawn.
    """
    num_rows = max(
        1, len([r for r in statistics if r["measure"] == measures[0] and r["test"] == "pair"])
    )
    figure, axes = plt.subplots(
        1,
        len(measures),
        figsize=(3.0 + 4.5 * len(measures), 2.4 + 0.4 * num_rows),
        squeeze=False,
        sharey=True,
    )
    colours = {"1": "C0", "2": "C3", "3": "C2", "option": "C4"}
    names = {
        "1": "claim 1 (goal vs actuator space)",
        "2": "claim 2 (ACTUATOR-RIAC vs -Random)",
        "3": "claim 3 (SAGG-RIAC vs SAGG-Random)",
        "option": "option vs paper settings",
    }
    for axis, measure in zip(axes[0], measures, strict=True):
        rows = [r for r in statistics if r["measure"] == measure and r["test"] == "pair"]
        shown = set()
        for y, row in enumerate(rows):
            if row["cohens_d"] is None or not np.isfinite(row["cohens_d"]):
                continue
            claim = row["claim"]
            axis.hlines(-y, row["d_low"], row["d_high"], color=colours[claim], linewidth=1.5)
            axis.plot(
                row["cohens_d"],
                -y,
                "o",
                color=colours[claim],
                label=None if claim in shown else names[claim],
            )
            shown.add(claim)
        axis.axvline(0.0, color="black", linewidth=0.8)
        axis.set_yticks([-y for y in range(len(rows))], [r["groups"] for r in rows], fontsize=7)
        title = MEASURE_TITLES[measure].split(" [")[0].replace(", ", ",\n", 1)
        axis.set(
            xlabel="Cohen's d, first - second\n[pooled sd], 95 % CI",
            ylabel="comparison (first vs second group)",
            title=title,
        )
        axis.title.set_fontsize(9)
        axis.grid(alpha=0.3, axis="x")
        axis.legend(fontsize=7, loc="best")
    figure.suptitle(f"Experiment {experiment}: effect sizes at the end of the runs")
    figure.tight_layout()
    return figure


def TipsFigure(runs: list[dict], groups: list[str]) -> Figure:
    """Where each group's memory lies: the stored tips of its lowest seed (every k-th), with the
    reachable half-disc, and its drift and coverage diagnostics over all its seeds.

    Args:
        runs: Results (with tip_sample).
        groups: Labels drawn, one panel each.
    """
    groups = [g for g in groups if any(Label(run["spec"]) == g for run in runs)]
    figure, axes = plt.subplots(1, len(groups), figsize=(4.2 * len(groups), 4.6), squeeze=False)
    angles = np.linspace(-np.pi, np.pi, 200)
    for axis, group in zip(axes[0], groups, strict=True):
        group_runs = sorted(
            (run for run in runs if Label(run["spec"]) == group), key=lambda r: r["spec"]["seed"]
        )
        tips = np.array(group_runs[0]["tip_sample"])
        length = group_runs[0]["config"]["arm"]["total_length"]
        diagnostics = [run["diagnostics"] for run in group_runs]
        spread = np.mean([d["tip_spread"] for d in diagnostics])
        coverage = 100 * np.mean([d["tip_coverage"] for d in diagnostics])
        axis.scatter(tips[:, 0], tips[:, 1], s=1, alpha=0.3, color="C0", label="stored tips")
        axis.plot(
            length * np.cos(angles),
            length * np.sin(angles),
            color="black",
            linewidth=1,
            label=f"reachable disc (radius {length:g})",
        )
        drifts = [d["drift_ratio"] for d in diagnostics if "drift_ratio" in d]
        drift = f", drift ratio {np.mean(drifts):.2f}" if drifts else ""
        axis.set(
            xlabel="tip x [units]",
            ylabel="tip y [units]",
            title=f"{group}, seed {group_runs[0]['spec']['seed']}\n"
            f"spread {spread:.1f}, coverage {coverage:.0f} %{drift}",
            xlim=(-length * 1.05, length * 1.05),
            ylim=(-length * 1.05, length * 1.05),
            aspect="equal",
        )
        axis.title.set_fontsize(9)
        axis.legend(fontsize=7, loc="lower left", markerscale=6)
    figure.suptitle(
        "Stored tips of one run per group (every k-th micro-action); spread, coverage and drift: "
        "means over the group's seeds"
    )
    figure.tight_layout()
    return figure


def GoalsFigure(run: dict) -> Figure:
    """Histograms of the self-generated goals (subgoals excluded) in four windows, with regions
    (Fig. 3).
    """
    config = run["config"]
    low, high = config["goal_space_low"], config["goal_space_high"]
    length = config["arm"]["total_length"]
    log = np.array(run["goal_log"]).reshape(-1, 7)
    goals = log[log[:, 4] > 0]
    figure, axes = plt.subplots(
        1, NUM_HISTOGRAM_WINDOWS + 1, figsize=(4.2 * (NUM_HISTOGRAM_WINDOWS + 1), 5.5)
    )
    panels = [
        (snapshot["first_goal"], snapshot["end_goal"], snapshot["regions"])
        for snapshot in run["region_snapshots"]
    ]
    panels.append((0, len(goals), run["region_snapshots"][-1]["regions"]))
    angles = np.linspace(-np.pi / 2, np.pi / 2, 100)
    for axis, (begin, end, regions) in zip(axes, panels, strict=True):
        *_, shown = axis.hist2d(
            goals[begin:end, 1],
            goals[begin:end, 2],
            bins=30,
            range=[[low[0], high[0]], [low[1], high[1]]],
            cmap="viridis",
        )
        figure.colorbar(shown, ax=axis, label="goals per bin [count]", shrink=0.8)
        for i, (x0, y0, x1, y1) in enumerate(regions):
            axis.plot(
                [x0, x1, x1, x0, x0],
                [y0, y0, y1, y1, y0],
                color="white",
                linewidth=0.6,
                label=None if i else "regions (at the window's end)",
            )
        axis.plot(
            length * np.cos(angles),
            length * np.sin(angles),
            color="black",
            linewidth=1.5,
            label=f"reachable half-disc (radius {length:g})",
        )
        axis.set(
            xlabel="goal x [units]",
            ylabel="goal y [units]",
            title=f"goals {begin + 1}-{end}",
            xlim=(low[0], high[0]),
            ylim=(low[1], high[1]),
            aspect="equal",
        )
    axes[-1].legend(loc="lower right", fontsize=7, facecolor="0.85")
    spec = run["spec"]
    figure.suptitle(
        f"SAGG-RIAC's goals (30 x 30 bins) and regions, experiment {spec['experiment']}, "
        f"seed {spec['seed']}, {spec['budget']} time steps (cf. the paper's Fig. 3)"
    )
    return figure


def _Format(values: np.ndarray, digits: int = 2, scale: float = 1.0) -> str:
    """'mean ± sd (median)' of one value per run."""
    values = scale * np.asarray(values, dtype=float)
    spread = values.std(ddof=1) if values.size > 1 else 0.0
    return f"{values.mean():.{digits}f} ± {spread:.{digits}f} ({np.median(values):.{digits}f})"


def _GoalStatistics(runs: list[dict]) -> str:
    """'goals per run | % of goals within reach' of goal-space runs, '- | -' otherwise."""
    if "goal_log" not in runs[0]:
        return "- | -"
    counts, inside = [], []
    for run in runs:
        log = np.array(run["goal_log"]).reshape(-1, 7)
        goals = log[log[:, 4] > 0]
        length = run["config"]["arm"]["total_length"]
        counts.append(len(goals))
        inside.append(np.mean(np.hypot(goals[:, 1], goals[:, 2]) <= length) if len(goals) else 0.0)
    return f"{np.mean(counts):.0f} | {100 * np.mean(inside):.1f}"


def _Number(value, digits: int = 2) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    return f"{value:.{digits}f}"


def _P(value) -> str:
    if value is None or not math.isfinite(value):
        return "-"
    return f"{value:.2g}" if value >= 1e-3 else f"{value:.1e}"


def _Diagnostic(runs: list[dict], name: str, scale: float = 1.0, digits: int = 1) -> str:
    values = [run.get("diagnostics", {}).get(name) for run in runs]
    values = [value for value in values if value is not None]
    return f"{scale * np.mean(values):.{digits}f}" if values else "-"


def _GroupTable(
    runs: list[dict], groups: list[str], columns: list[str], Cells: Callable[..., list]
) -> list[str]:
    """Markdown rows: one per group with runs, its cells Cells(group, its runs)."""
    lines = ["| group | " + " | ".join(columns) + " |", "|---" * (len(columns) + 1) + "|"]
    for group in groups:
        group_runs = [run for run in runs if Label(run["spec"]) == group]
        if group_runs:
            lines.append(f"| {group} | " + " | ".join(map(str, Cells(group, group_runs))) + " |")
    return lines


def ResultsTable(runs: list[dict], groups: list[str]) -> list[str]:
    """Markdown rows: per group, the final measures as mean ± sd (median) over its runs."""
    columns = [
        "runs",
        "reaching error, mean over goals",
        "reaching error, median over goals",
        "goals within 1 unit (%)",
        "prediction error, reachable area",
        "prediction error, near rest",
        "wall time per run (s)",
    ]
    return _GroupTable(
        runs,
        groups,
        columns,
        lambda group, group_runs: [
            len(group_runs),
            _Format(_Final(runs, group, "reaching_error")),
            _Format(_Final(runs, group, "reaching_error_median")),
            _Format(_Final(runs, group, "reached_share"), digits=1, scale=100.0),
            _Format(_Final(runs, group, "prediction_error")),
            _Format(_Final(runs, group, "prediction_error_near_rest")),
            f"{np.mean([run['wall_time_s'] for run in group_runs]):.0f}",
        ],
    )


def DiagnosticsTable(runs: list[dict], groups: list[str]) -> list[str]:
    """Markdown rows: per group, the means over its runs of the diagnostics (see Diagnostics)."""
    columns = [
        "tip coverage (%)",
        "tip spread",
        "drift ratio",
        "exploration (%)",
        "on unreachable (sub)goals (%)",
        "attempts stalled (%)",
        "regions",
        "goals per run",
        "goals in reach (%)",
    ]

    def Cells(group: str, group_runs: list[dict]) -> list[str]:
        regions = [run["num_regions"] for run in group_runs if "num_regions" in run]
        return [
            _Diagnostic(group_runs, "tip_coverage", 100.0),
            _Diagnostic(group_runs, "tip_spread"),
            _Diagnostic(group_runs, "drift_ratio", digits=2),
            _Diagnostic(group_runs, "exploration_share", 100.0),
            _Diagnostic(group_runs, "unreachable_share", 100.0),
            _Diagnostic(group_runs, "stalled_share", 100.0),
            f"{np.mean(regions):.0f}" if regions else "-",
            _GoalStatistics(group_runs),
        ]

    return _GroupTable(runs, groups, columns, Cells)


def CheckpointTable(
    runs: list[dict], first: str, second: str, measures: tuple[str, ...]
) -> list[str]:
    """Markdown rows: at every checkpoint, the difference of the groups' means of each measure
    and its Welch p (one value per run and checkpoint; checkpoints are not pooled)."""
    curves = {
        group: np.array(
            [[[p[m] for m in measures] for p in run["curve"]] for run in runs
             if Label(run["spec"]) == group]
        )
        for group in (first, second)
    }  # fmt: skip
    if min(len(curve) for curve in curves.values()) < 2:
        return []
    steps = [point["time_step"] for point in next(r for r in runs if Label(r["spec"]) == first)[
        "curve"]]  # fmt: skip
    lines = [
        "| time step | "
        + " | ".join(f"{m}: {first} - {second} (Welch p)" for m in measures)
        + " |",
        "|---|" + "---|" * len(measures),
    ]
    for index, step in enumerate(steps[1:], start=1):
        cells = []
        for column in range(len(measures)):
            a, b = curves[first][:, index, column], curves[second][:, index, column]
            p_value = stats.ttest_ind(a, b, equal_var=False).pvalue if np.ptp(
                np.concatenate([a, b])) > 0 else math.nan  # fmt: skip
            cells.append(f"{a.mean() - b.mean():+.2f} ({_P(p_value)})")
        lines.append(f"| {step} | " + " | ".join(cells) + " |")
    return lines


RADIUS_BANDS = (0.0, 15.0, 30.0, 40.0, 50.0)


def RadiusTable(runs: list[dict], groups: list[str]) -> list[str]:
    """Markdown rows: per group, the share of test goals reached within 1 unit by distance of the
    goal from the base (mean over runs of each run's share in the band), and the band's mean
    error: where the heavy tail of missed goals lies."""
    config = ConfigFromDict(runs[0]["config"])
    radii = np.linalg.norm(MakeTestSet(config).goals, axis=1)
    bands = list(zip(RADIUS_BANDS[:-1], RADIUS_BANDS[1:], strict=True))
    reached = config.evaluation.reached_distance
    lines = [
        "| group | "
        + " | ".join(f"goals at {low:g}-{high:g} ({np.sum((radii >= low) & (radii < high))})"
                     for low, high in bands)
        + " |",
        "|---|" + "---|" * len(bands),
    ]  # fmt: skip
    for group in groups:
        errors = np.array(
            [run["final_reaching_errors"] for run in runs if Label(run["spec"]) == group]
        )
        if errors.size == 0:
            continue
        cells = []
        for low, high in bands:
            inside = (radii >= low) & (radii < high)
            share = 100 * np.mean(errors[:, inside] <= reached)
            cells.append(f"{share:.0f} % ({np.mean(errors[:, inside]):.1f})")
        lines.append(f"| {group} | " + " | ".join(cells) + " |")
    return lines


def TestsTable(statistics: list[dict], measures: tuple[str, ...] = MEASURES) -> list[str]:
    """Markdown rows: each pair's tests, effect sizes with 95 % intervals and power."""
    lines = [
        "| claim | measure | first vs second | runs | means | medians | p ANOVA | p Welch "
        "| p Mann-Whitney | Cohen's d [95 % CI] | power | runs for 80 % | rank-biserial "
        "[95 % CI] |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in statistics:
        if row["test"] != "pair" or row["measure"] not in measures:
            continue
        runs_needed = row["runs_for_80_percent"]
        lines.append(
            f"| {row['claim']} | {row['measure']} | {row['groups']} | "
            f"{row['n_a']}, {row['n_b']} | "
            f"{_Number(row['mean_a'], 3)}, {_Number(row['mean_b'], 3)} | "
            f"{_Number(row['median_a'], 3)}, {_Number(row['median_b'], 3)} | "
            f"{_P(row['anova_p'])} | {_P(row['welch_p'])} | {_P(row['mann_whitney_p'])} | "
            f"{_Number(row['cohens_d'])} [{_Number(row['d_low'])}, {_Number(row['d_high'])}] | "
            f"{_Number(row['power'])} | {runs_needed if runs_needed > 0 else '-'} | "
            f"{_Number(row['rank_biserial'])} [{_Number(row['r_low'])}, "
            f"{_Number(row['r_high'])}] |"
        )
    return lines


def WriteReport(
    all_runs: dict[int, list[dict]],
    statistics: dict[int, list[dict]],
    groups: list[str],
    command: str,
    path: pathlib.Path,
) -> None:
    """Markdown report: per experiment, final measures, diagnostics and tests."""
    lines = [
        "# SAGG-RIAC experiments (Baranes & Oudeyer, IROS 2010, Sec. IV)",
        "",
        f"Command: `{command}` ({Provenance(path.parent)})",
        "",
        "Variants: "
        + "; ".join(f"`{name}`: {variant.description}" for name, variant in VARIANTS.items()),
        "",
    ]
    for experiment, runs in all_runs.items():
        if not runs:
            continue
        budget = runs[0]["spec"]["budget"]
        lines += [
            f"## Experiment {experiment} ({budget} time steps per run)",
            "",
            *ResultsTable(runs, groups),
            "",
            "Each cell: mean ± sample standard deviation over runs (median over runs) of one "
            "value per run at its last checkpoint (units; arm length 50).",
            "",
            *DiagnosticsTable(runs, groups),
            "",
            "Diagnostics (means over runs): tip coverage, the share of test goals with a stored "
            "tip within 1 unit; tip spread, the RMS distance of the stored tips from the rest "
            "tip; drift ratio, the mean norm of the joint changes summed over a reset period over "
            "that of an unbiased random walk; exploration and unreachable, shares of the "
            "micro-actions; goals: self-generated goals (subgoals excluded) per run and the "
            "share inside the reachable half-disc.",
            "",
            *RadiusTable(runs, groups),
            "",
            "Share of the test goals reached within 1 unit by distance of the goal from the base "
            "(units; the number of test goals in each band in brackets), mean over runs (the mean "
            "final error of the band's goals in brackets).",
            "",
            *TestsTable(statistics[experiment]),
            "",
            "Tests at run level (one value per run). d and the rank-biserial r are positive "
            "when the first group's values are larger. Power: of the two-sided ANOVA at alpha "
            "0.05 for the observed |d| and these group sizes; runs for 80 %: per group, at the "
            "observed d. Rank-biserial interval: percentile bootstrap, 10,000 resamples.",
            "",
            *CheckpointTable(
                runs,
                "SAGG-RIAC",
                "SAGG-Random",
                ("reaching_error", "prediction_error", "prediction_error_near_rest"),
            ),
            "",
            f"Plots: `exp{experiment}_curves.png`, `exp{experiment}_effects.png`, "
            f"`exp{experiment}_tips.png`"
            + (f", `exp{experiment}_goals.png`" if any("goal_log" in run for run in runs) else ""),
            "",
        ]
    WriteTextAtomically(path, "\n".join(lines) + "\n")


def _NoNan(value):
    """``value`` with every NaN (a statistic that could not be computed) made None."""
    if isinstance(value, float) and math.isnan(value):
        return None
    if isinstance(value, dict):
        return {k: _NoNan(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_NoNan(v) for v in value]
    return value


def Analyse(specs: list[RunSpec], output: pathlib.Path, command: str) -> None:
    """Writes curves CSV, plots, statistics JSON and report.md from the run files present."""
    experiments = sorted({spec.experiment for spec in specs})
    groups = list(dict.fromkeys(spec.Label() for spec in specs))
    all_runs, statistics = {}, {}
    for experiment in experiments:
        runs = LoadRuns([spec for spec in specs if spec.experiment == experiment], output)
        all_runs[experiment] = runs
        statistics[experiment] = Statistics(runs, groups) if runs else []
        if not runs:
            continue
        WriteCurves(runs, output / f"exp{experiment}_curves.csv")
        SaveFigure(
            CurvesFigure(runs, groups, experiment),
            output / f"exp{experiment}_curves.png",
            dpi=110,
        )
        if any(row["test"] == "pair" for row in statistics[experiment]):
            SaveFigure(
                EffectsFigure(
                    _NoNan(statistics[experiment]),
                    experiment,
                    ["reaching_error", "reached_share", "prediction_error"],
                ),
                output / f"exp{experiment}_effects.png",
                dpi=110,
            )
        SaveFigure(TipsFigure(runs, groups), output / f"exp{experiment}_tips.png", dpi=100)
        sagg_riac_runs = [run for run in runs if Label(run["spec"]) == SaggRiac.name]
        if sagg_riac_runs:
            SaveFigure(
                GoalsFigure(sagg_riac_runs[0]), output / f"exp{experiment}_goals.png", dpi=100
            )
    WriteTextAtomically(
        output / "statistics.json",
        # A test that could not be computed (NaN) is written null.
        StrictJson({str(key): _NoNan(value) for key, value in statistics.items()}, indent=1),
    )
    WriteReport(all_runs, statistics, groups, command, output / "report.md")


def _Parser() -> CommandParser:
    """The command line of ``mobee-drake experiment saggriac``."""
    parser = CommandParser(
        prog="mobee-drake experiment saggriac",
        description=__doc__,
    )
    parser.add_argument(
        "--experiments",
        type=int,
        nargs="+",
        choices=[1, 2],
        default=[1, 2],
        help="which experiments of Sec. IV",
    )
    parser.add_argument(
        "--methods",
        nargs="+",
        choices=list(METHODS),
        default=list(METHODS),
        help="the learners compared",
    )
    parser.add_argument(
        "--variants",
        nargs="+",
        choices=list(VARIANTS),
        default=["paper"],
        help="settings per method (a variant runs only with the methods it applies to): "
        + "; ".join(
            f"{name}: {variant.description} ({', '.join(variant.methods)})"
            for name, variant in VARIANTS.items()
        ),
    )
    parser.add_argument(
        "--seeds",
        type=PositiveInt,
        default=argparse.SUPPRESS,
        help=f"number of seeds (default: {FULL['seeds']}; paper: 15)",
    )
    parser.add_argument("--first-seed", type=NonNegativeInt, default=0, help="the first seed")
    parser.add_argument(
        "--budget-exp1",
        type=PositiveInt,
        default=argparse.SUPPRESS,
        help=f"movements (default: {FULL['budget_exp1']:,}, the paper's)",
    )
    parser.add_argument(
        "--budget-exp2",
        type=PositiveInt,
        default=argparse.SUPPRESS,
        help=f"time steps (default: {FULL['budget_exp2']:,}, the paper's)",
    )
    parser.add_argument(
        "--checkpoints",
        type=PositiveInt,
        default=argparse.SUPPRESS,
        help=f"evaluations after step 0 (default: {FULL['checkpoints']})",
    )
    parser.add_argument(
        "--output",
        type=pathlib.Path,
        default=pathlib.Path("saggriac_results"),
        help="the battery folder (runs, curves, report)",
    )
    parser.add_argument(
        "--analyse-only", action="store_true", help="only rebuild the report from run files"
    )
    parser.add_argument(
        "--smoke",
        action="store_true",
        help="tiny battery, unless the flags say otherwise: "
        + ", ".join(f"--{name.replace('_', '-')} {value}" for name, value in SMOKE.items()),
    )
    AddBackendArguments(parser)
    return parser


def main(argv=None) -> None:
    """Command line: runs the missing runs, then analyses.

    Args:
        argv: Arguments (default: sys.argv[1:]).
    """
    parser = _Parser()
    args = parser.parse_args(argv)
    # --smoke's sizes, or the paper's, for what the command line does not give.
    for name, value in (SMOKE if args.smoke else FULL).items():
        setattr(args, name, getattr(args, name, value))
    budgets = {1: args.budget_exp1, 2: args.budget_exp2}
    for experiment in args.experiments:
        if args.checkpoints > budgets[experiment]:
            parser.error(
                f"--checkpoints {args.checkpoints}: more evaluations than experiment "
                f"{experiment}'s budget of {budgets[experiment]}"
            )
    # Seed-major order: an interrupted battery leaves every group with about as many seeds.
    specs = [
        RunSpec(experiment, method, seed, budgets[experiment], args.checkpoints, variant)
        for experiment in args.experiments
        for seed in range(args.first_seed, args.first_seed + args.seeds)
        for variant in args.variants
        for method in args.methods
        if method in VARIANTS[variant].methods
    ]
    if not specs:
        parser.error(
            f"no run: none of the variants {args.variants} applies to the methods {args.methods}"
        )
    started = time.perf_counter()
    if not args.analyse_only:
        RunAll(specs, args.output, BackendOf(args))
    command = "mobee-drake experiment saggriac " + " ".join(
        argv if argv is not None else sys.argv[1:]
    )
    # (Claimed like the battery: a user's folder, or another battery's, is never written into.)
    with OwnedFolder(args.output, "battery"):
        if not any((args.output / "runs" / spec.Name() / RESULT).exists() for spec in specs):
            parser.error(f"--output {args.output}: holds no SAGG-RIAC run of these arguments")
        Analyse(specs, args.output, command)
    print(
        f"done in {time.perf_counter() - started:.1f} s; report: {args.output / 'report.md'}",
        flush=True,
    )


if __name__ == "__main__":
    main()
