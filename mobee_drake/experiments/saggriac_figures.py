"""The figures of the SAGG-RIAC battery (Baranes & Oudeyer, Sec. IV): learning curves, effects,
reachable tips and goals, from the runs' results (:mod:`mobee_drake.experiments.saggriac`)."""

import math

import numpy as np

from mobee_drake.experiments.plots import Figure, plt
from mobee_drake.experiments.saggriac import MEASURE_TITLES, BabblingRun

# Each group's line style, the first widest: groups whose curves coincide all stay visible.
_LINE_STYLES = (("-", 3.0), ("--", 1.8), (":", 1.8), ("-.", 1.8))


def CurvesFigure(
    runs: list[BabblingRun], groups: list[str], experiment: int, measures: list[str] | None = None
) -> Figure:
    """Mean and standard deviation over seeds of each measure against time steps (Fig. 4-5).

    Args:
        runs: Results.
        groups: Labels of the groups drawn (see Label), in order.
        experiment: For the title.
        measures: Measures drawn, one panel each (default: those of MEASURE_TITLES in the runs).
    """
    if measures is None:
        present = runs[0].curve[0]
        measures = [measure for measure in MEASURE_TITLES if measure in present]
        measures += [m for m in present if m != "time_step" and m not in measures]
    columns = min(len(measures), 3)
    rows = math.ceil(len(measures) / columns)
    figure, axes = plt.subplots(rows, columns, figsize=(6 * columns, 4.5 * rows), squeeze=False)
    for axis in axes.flat[len(measures) :]:
        axis.remove()
    for offset, group in enumerate(groups):
        group_runs = [run for run in runs if run.label == group]
        if not group_runs:
            continue
        steps = np.array([point["time_step"] for point in group_runs[0].curve]) / 1000
        for axis, measure in zip(axes.flat, measures, strict=False):
            values = np.array([[point[measure] for point in run.curve] for run in group_runs])
            mean, spread = values.mean(axis=0), values.std(axis=0)
            style, width = _LINE_STYLES[offset % len(_LINE_STYLES)]
            (line,) = axis.plot(
                steps,
                mean,
                linestyle=style,
                linewidth=width,
                label=f"{group} ({len(group_runs)} seeds)",
            )
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
    colours = {"1": "C0", "2": "C3", "3": "C2", "option": "C4", "mechanism": "C1"}
    names = {
        "1": "claim 1 (goal vs actuator space)",
        "2": "claim 2 (ACTUATOR-RIAC vs -Random)",
        "3": "claim 3 (SAGG-RIAC vs SAGG-Random)",
        "option": "option vs paper settings",
        "mechanism": "variance-only vs SAGG-Random (issue 34)",
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


def TipsFigure(runs: list[BabblingRun], groups: list[str]) -> Figure:
    """Where each group's memory lies: the stored tips of its lowest seed (every k-th), with the
    reachable half-disc, and its drift and coverage diagnostics over all its seeds.

    Args:
        runs: Results (with tip_sample).
        groups: Labels drawn, one panel each.
    """
    groups = [g for g in groups if any(run.label == g for run in runs)]
    figure, axes = plt.subplots(1, len(groups), figsize=(4.2 * len(groups), 4.6), squeeze=False)
    angles = np.linspace(-np.pi, np.pi, 200)
    for axis, group in zip(axes[0], groups, strict=True):
        group_runs = sorted((run for run in runs if run.label == group), key=lambda r: r.spec.seed)
        tips = np.array(group_runs[0].tip_sample)
        length = group_runs[0].config["arm"]["total_length"]
        diagnostics = [run.diagnostics for run in group_runs]
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
            title=f"{group}, seed {group_runs[0].spec.seed}\n"
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


def GoalsFigure(run: BabblingRun) -> Figure:
    """Histograms of the self-generated goals (subgoals excluded) in four windows, with regions
    (Fig. 3).
    """
    config = run.config
    low, high = config["goal_space_low"], config["goal_space_high"]
    length = config["arm"]["total_length"]
    goals = run.Goals()
    panels = [
        (snapshot["first_goal"], snapshot["end_goal"], snapshot["regions"])
        for snapshot in run.region_snapshots
    ]
    panels.append((0, len(goals), run.region_snapshots[-1]["regions"]))
    if len(goals) == 0:  # (a short run may set subgoals only: one panel says so)
        panels = panels[-1:]
    figure, axes = plt.subplots(
        1, len(panels), figsize=(max(4.2 * len(panels), 7.0), 5.5), squeeze=False
    )
    angles = np.linspace(-np.pi / 2, np.pi / 2, 100)
    for axis, (begin, end, regions) in zip(axes[0], panels, strict=True):
        if end > begin:
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
            title=f"goals {begin + 1}-{end}" if end > begin else "no goals (subgoals only)",
            xlim=(low[0], high[0]),
            ylim=(low[1], high[1]),
            aspect="equal",
        )
        if end <= begin or axis is axes[0][-1]:
            axis.legend(loc="lower right", fontsize=7, facecolor="0.85")
    spec = run.spec
    figure.suptitle(
        f"SAGG-RIAC's goals (30 x 30 bins) and regions, experiment {spec.experiment},\n"
        f"seed {spec.seed}, {spec.budget} time steps (cf. the paper's Fig. 3)"
    )
    return figure
