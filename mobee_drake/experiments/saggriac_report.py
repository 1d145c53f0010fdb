"""The analysis of the SAGG-RIAC battery: run-level statistics of the paper's claims, the curves
file, the tables and ``report.md`` (:func:`Analyse`)."""

from collections.abc import Callable
import csv
import dataclasses
import math
import pathlib

import numpy as np
from scipy import stats

from mobee_drake.atomic_files import StrictJson, WriteTextAtomically
from mobee_drake.experiments.battery import (
    Provenance,
)
from mobee_drake.experiments.plots import SaveFigure
from mobee_drake.experiments.saggriac import (
    METHODS,
    SAGG_METHODS,
    VARIANTS,
    BabblingRun,
    LoadRuns,
    RunSpec,
)
from mobee_drake.experiments.saggriac_figures import (
    CurvesFigure,
    EffectsFigure,
    GoalsFigure,
    TipsFigure,
)
from mobee_drake.experiments.saggriac_interest import Issue34Lines
from mobee_drake.experiments.statistics import CompareRuns
from mobee_drake.goal_babbling.config import (
    ConfigFromDict,
)
from mobee_drake.goal_babbling.evaluation import MEASURES, MakeTestSet
from mobee_drake.goal_babbling.sagg_riac import SaggRiac


def _Final(runs: list[BabblingRun], group: str, measure: str) -> np.ndarray:
    return np.array([run.curve[-1][measure] for run in runs if run.label == group])


# The comparisons behind the paper's claims (Sec. IV-B): (first group, second group, claim).
CLAIM_PAIRS = (
    ("SAGG-RIAC", "ACTUATOR-Random", "1"),
    ("SAGG-Random", "ACTUATOR-Random", "1"),
    ("SAGG-RIAC", "ACTUATOR-Random [set]", "1"),
    ("SAGG-Random", "ACTUATOR-Random [set]", "1"),
    ("ACTUATOR-RIAC", "ACTUATOR-Random", "2"),
    ("ACTUATOR-RIAC [set]", "ACTUATOR-Random [set]", "2"),
    ("SAGG-RIAC", "SAGG-Random", "3"),
    ("SAGG-RIAC [variance-only]", "SAGG-Random", "mechanism"),
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


def Statistics(runs: list[BabblingRun], groups: list[str]) -> list[dict]:
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


def WriteCurves(runs: list[BabblingRun], path: pathlib.Path) -> None:
    """CSV with one row per (method, variant, seed, checkpoint)."""
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(["experiment", "method", "variant", "seed", "time_step", *MEASURES])
        for run in runs:
            spec = run.spec
            for point in run.curve:
                writer.writerow(
                    [
                        spec.experiment,
                        spec.method,
                        spec.variant,
                        spec.seed,
                        point["time_step"],
                        *(f"{point[measure]:.6g}" for measure in MEASURES),
                    ]
                )


def _Format(values: np.ndarray, digits: int = 2, scale: float = 1.0) -> str:
    """'mean ± sd (median)' of one value per run."""
    values = scale * np.asarray(values, dtype=float)
    spread = values.std(ddof=1) if values.size > 1 else 0.0
    return f"{values.mean():.{digits}f} ± {spread:.{digits}f} ({np.median(values):.{digits}f})"


def _GoalStatistics(runs: list[BabblingRun]) -> str:
    """'goals per run | % of goals within reach' of goal-space runs, '- | -' otherwise."""
    if runs[0].goal_log is None:
        return "- | -"
    counts, inside = [], []
    for run in runs:
        goals = run.Goals()
        length = run.config["arm"]["total_length"]
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


def _Diagnostic(runs: list[BabblingRun], name: str, scale: float = 1.0, digits: int = 1) -> str:
    values = [run.diagnostics.get(name) for run in runs]
    values = [value for value in values if value is not None]
    return f"{scale * np.mean(values):.{digits}f}" if values else "-"


def _GroupTable(
    runs: list[BabblingRun], groups: list[str], columns: list[str], Cells: Callable[..., list]
) -> list[str]:
    """Markdown rows: one per group with runs, its cells Cells(group, its runs)."""
    lines = ["| group | " + " | ".join(columns) + " |", "|---" * (len(columns) + 1) + "|"]
    for group in groups:
        group_runs = [run for run in runs if run.label == group]
        if group_runs:
            lines.append(f"| {group} | " + " | ".join(map(str, Cells(group, group_runs))) + " |")
    return lines


def ResultsTable(runs: list[BabblingRun], groups: list[str]) -> list[str]:
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
            f"{np.mean([run.wall_time_s for run in group_runs]):.0f}",
        ],
    )


def DiagnosticsTable(runs: list[BabblingRun], groups: list[str]) -> list[str]:
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

    def Cells(group: str, group_runs: list[BabblingRun]) -> list[str]:
        regions = [run.num_regions for run in group_runs if run.num_regions is not None]
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
    runs: list[BabblingRun], first: str, second: str, measures: tuple[str, ...]
) -> list[str]:
    """Markdown rows: at every checkpoint, the difference of the groups' means of each measure
    and its Welch p (one value per run and checkpoint; checkpoints are not pooled)."""
    curves = {
        group: np.array(
            [[[p[m] for m in measures] for p in run.curve] for run in runs
             if run.label == group]
        )
        for group in (first, second)
    }  # fmt: skip
    if min(len(curve) for curve in curves.values()) < 2:
        return []
    steps = [point["time_step"] for point in next(r for r in runs if r.label == first).curve]
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


def RadiusTable(runs: list[BabblingRun], groups: list[str]) -> list[str]:
    """Markdown rows: per group, the share of test goals reached within 1 unit by distance of the
    goal from the base (mean over runs of each run's share in the band), and the band's mean
    error: where the heavy tail of missed goals lies."""
    config = ConfigFromDict(runs[0].config)
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
        errors = np.array([run.final_reaching_errors for run in runs if run.label == group])
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
    all_runs: dict[int, list[BabblingRun]],
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
    if any(r.leaf_interests for runs in all_runs.values() for r in runs):
        lines += [
            "## The interest against its noise floor (issue 34)",
            "",
            *Issue34Lines(all_runs, groups),
            "Per final leaf: eq. 2's interest against 999 reorderings of its own competences; "
            "rho per run over its leaves.",
            "",
        ]
    for experiment, runs in all_runs.items():
        if not runs:
            continue
        budget = runs[0].spec.budget
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
            + (
                f", `exp{experiment}_goals.png`"
                if any(run.goal_log is not None for run in runs)
                else ""
            ),
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


def Analyse(
    specs: list[RunSpec], output: pathlib.Path, command: str
) -> dict[int, list[BabblingRun]]:
    """Writes curves CSV, plots, statistics JSON and report.md from the run files present;
    returns the runs per experiment."""
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
        sagg_riac_runs = [run for run in runs if run.label == SaggRiac.name]
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
    return all_runs
