"""The reactive benchmark's tables and figure (:mod:`mobee_drake.experiments.bench_reactive`)."""

import math

from matplotlib.ticker import MaxNLocator
import numpy as np

from mobee_drake.experiments.plots import Legend, plt
from mobee_drake.experiments.reactive_runs import EARLY, REACHED, ControllerSummary, RunResult
from mobee_drake.experiments.reactive_tasks import PERIOD, QUERY_DISTANCE, SHIPPED


def _Cm(value: float) -> str:
    shown = f"{100 * value:+.1f}"
    return f">= {shown}" if value >= QUERY_DISTANCE else shown


def Table(summaries: list[ControllerSummary], horizon: float, early: float = EARLY) -> str:
    """The markdown table of the controllers' summaries."""
    lines = [
        f"| controller | reached (< {100 * REACHED:g} cm) by {early:g} s | by {horizon:g} s "
        "| median time to reach (s) | median final error (cm) | worst clearance to obstacles "
        "(cm) | worst self clearance (cm) | penetrating periods (tasks) | constraint violations: "
        "tasks (worst, deg) | step cost median / p95 (ms) | peak joint speed (rad/s) |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for s in summaries:
        time_to_reach = "-" if s.median_time is None else f"{s.median_time:.2f}"
        lines.append(
            f"| {s.label} | {s.reached_early}/{s.tasks} | {s.reached}/{s.tasks} | "
            f"{time_to_reach} | {100 * s.median_final_error:.1f} | "
            f"{_Cm(s.obstacle_clearance)} | {_Cm(s.self_clearance)} | "
            f"{s.penetrating_steps} ({s.penetrating_tasks}) | "
            f"{s.violating_tasks} ({math.degrees(s.worst_violation):.1f}) | "
            f"{1000 * s.step_median:.2f} / {1000 * s.step_p95:.2f} | {s.peak_speed:.2f} |"
        )
    return "\n".join(lines)


def KindTable(
    results: dict[str, list[RunResult]],
    labels: dict[str, str],
    horizon: float,
    early: float = EARLY,
) -> str:
    """Per task kind: tasks reached by ``early`` / by the horizon, of the kind's tasks."""
    kinds = list(dict.fromkeys(r.kind for rows in results.values() for r in rows))
    lines = [
        f"| controller | {' | '.join(kinds)} |",
        "|---|" + "---:|" * len(kinds),
    ]
    for name, rows in results.items():
        cells = []
        for kind in kinds:
            mine = [r for r in rows if r.kind == kind]
            by_early = sum(r.reached_at is not None and r.reached_at <= early for r in mine)
            by_end = sum(r.reached_at is not None for r in mine)
            cells.append(f"{by_early} / {by_end} of {len(mine)}")
        lines.append(f"| {labels[name]} | {' | '.join(cells)} |")
    return f"Reached by {early:g} s / by {horizon:g} s, per kind of task:\n" + "\n".join(lines)


# (An empty reached_at_s: not reached; an empty obstacle_clearance_cm: no obstacle ever within
# QUERY_DISTANCE.)
DETAIL_COLUMNS = (
    "controller,task,kind,reached_at_s,final_error_cm,obstacle_clearance_cm,self_clearance_cm,"
    "penetrating_periods,violating_periods,worst_violation_deg,peak_speed_rad_s,"
    "step_median_ms,step_p95_ms,failed_periods"
)


def DetailRows(results: dict[str, list[RunResult]]) -> list[str]:
    """One CSV row per controller and task (DETAIL_COLUMNS)."""
    rows = []
    for name, mine in results.items():
        for r in mine:
            reached = "" if r.reached_at is None else f"{r.reached_at:.2f}"
            obstacle = (
                ""
                if r.obstacle_clearance >= QUERY_DISTANCE
                else f"{100 * r.obstacle_clearance:.2f}"
            )
            rows.append(
                f"{name},{r.task},{r.kind},{reached},{100 * r.final_error:.2f},"
                f"{obstacle},{100 * r.self_clearance:.2f},"
                f"{r.penetrating_steps},{r.violating_steps},"
                f"{math.degrees(r.worst_violation):.2f},{r.peak_speed:.3f},"
                f"{1000 * np.median(r.step_seconds):.3f},"
                f"{1000 * np.percentile(r.step_seconds, 95):.3f},{r.failed_steps}"
            )
    return rows


# The kinds as the figure's task axis names them.
SHORT_KINDS = {"ball": "ball", "two_balls": "2 balls", "shelf": "shelf", "behind_arm": "arm"}


def ReactiveFigure(
    results: dict[str, list[RunResult]],
    labels: dict[str, str],
    horizon: float,
    early: float = EARLY,
):
    """Three panels: tasks reached over time; the palm's distance to its goal over time
    (median and interquartile range over the tasks, below 1 mm shown at 1 mm); each task's time
    to reach."""
    figure = plt.figure(figsize=(13, 8.5))
    grid = figure.add_gridspec(2, 2)
    reached_axis, error_axis = figure.add_subplot(grid[0, 0]), figure.add_subplot(grid[0, 1])
    task_axis = figure.add_subplot(grid[1, :])
    count = len(results)
    for i, (name, rows) in enumerate(results.items()):
        colour, label = f"C{i}", labels[name]
        times = np.sort([r.reached_at for r in rows if r.reached_at is not None])
        reached_axis.step(
            np.concatenate([[0.0], times, [horizon]]),
            np.concatenate([[0], np.arange(1, len(times) + 1), [len(times)]]),
            where="post",
            color=colour,
            label=label,
        )
        errors = np.maximum(100 * np.array([r.palm_error for r in rows]), 0.1)
        t = PERIOD * np.arange(errors.shape[1])
        low, median, high = np.percentile(errors, [25, 50, 75], axis=0)
        error_axis.plot(t, median, color=colour, label=label)
        error_axis.fill_between(t, low, high, color=colour, alpha=0.15)
        x = np.arange(len(rows)) + (i - (count - 1) / 2) * 0.2
        reached = np.array([r.reached_at is not None for r in rows])
        y = np.array([horizon if r.reached_at is None else r.reached_at for r in rows])
        task_axis.plot(x[reached], y[reached], "o", color=colour, label=f"{label}, reached")
        task_axis.plot(x[~reached], y[~reached], "x", color=colour, label=f"{label}, not reached")
    reached_axis.axvline(early, color="grey", linestyle=":", label=f"{early:g} s")
    reached_axis.set(
        xlabel="time [s]",
        ylabel="tasks reached [count]",
        title=f"Tasks reached (palm within {100 * REACHED:g} cm)",
    )
    error_axis.axhline(100 * REACHED, color="grey", linestyle=":", label="reached")
    error_axis.set(
        xlabel="time [s]",
        ylabel="palm to goal [cm]",
        yscale="log",
        title="Palm to goal: median, quartiles",
    )
    first = next(iter(results.values()))
    names = [
        "S" if r.kind == "shipped" else f"{r.task.removeprefix('random ')}\n{SHORT_KINDS[r.kind]}"
        for r in first
    ]
    task_axis.set_xticks(np.arange(len(names)), names, fontsize="x-small")
    reached_axis.yaxis.set_major_locator(MaxNLocator(integer=True))
    task_axis.set(
        xlabel="task",
        ylabel="time to reach [s]",
        title=f"Time to reach per task (S: {SHIPPED}; x: not reached by {horizon:g} s)",
    )
    for axis in (reached_axis, error_axis, task_axis):
        Legend(axis)
    return figure
