"""The experiments of Baranes & Oudeyer (IROS 2010), Sec. IV: four methods on the 15-joint arm.

Each run (experiment, method, seed, budget) is a job of the battery runner
(:mod:`mobee_drake.experiments.battery`): its result is written atomically as soon as it
finishes, and on restart runs with a result are skipped, so an interrupted battery loses at most
the runs in progress. Then curves (CSV), plots like Fig. 3-5 (PNG), statistics and a markdown
report are written from whatever results exist.

Usage::

    mobee-drake experiment saggriac --experiments 1 2 --seeds 15 --workers 2 --output DIR
    mobee-drake experiment saggriac --smoke --output /tmp/saggriac_smoke [--ray [ADDRESS]]
"""

import csv
import dataclasses
import json
import math
import pathlib
import sys
import time

import numpy as np
from scipy import stats

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
from mobee_drake.goal_babbling.baselines import ActuatorRandom, ActuatorRiac, SaggRandom
from mobee_drake.goal_babbling.config import ConfigToDict, Experiment1Config, Experiment2Config
from mobee_drake.goal_babbling.evaluation import MakeEvaluator
from mobee_drake.goal_babbling.sagg_riac import SaggRiac

METHODS = {
    learner.name: learner for learner in (SaggRiac, SaggRandom, ActuatorRandom, ActuatorRiac)
}
EXPERIMENT_CONFIGS = {1: Experiment1Config, 2: Experiment2Config}
MEASURES = ("reaching_error", "prediction_error")
NUM_HISTOGRAM_WINDOWS = 4


@dataclasses.dataclass(frozen=True)
class RunSpec:
    """One learning run.

    Attributes:
        experiment: 1 or 2 (Sec. IV-B-1 or IV-B-2).
        method: A key of METHODS.
        seed: Learner seed.
        budget: Micro-actions.
        num_checkpoints: Evaluations after step 0.
    """

    experiment: int
    method: str
    seed: int
    budget: int
    num_checkpoints: int

    def Name(self) -> str:
        """Name of the run (its folder in the battery's runs)."""
        return f"exp{self.experiment}_{self.method}_seed{self.seed:02d}_budget{self.budget}"


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


def RunOne(run: RunFolder, spec: dict) -> dict:
    """Runs one learner (a battery job; ``spec`` a :class:`RunSpec` as a dict) and returns its
    result.
    """
    spec = RunSpec(**spec)
    config = EXPERIMENT_CONFIGS[spec.experiment](seed=spec.seed, budget=spec.budget)
    config.evaluation.num_checkpoints = spec.num_checkpoints
    started = time.perf_counter()
    learner = METHODS[spec.method](config, MakeEvaluator(config)).Run()
    result = {
        "spec": dataclasses.asdict(spec),
        "config": ConfigToDict(config),
        "wall_time_s": time.perf_counter() - started,
        "time_steps": learner.time_steps,
        "curve": learner.curve,
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


def _Final(runs: list[dict], method: str, measure: str) -> np.ndarray:
    return np.array([run["curve"][-1][measure] for run in runs if run["spec"]["method"] == method])


def Statistics(runs: list[dict], methods: list[str]) -> list[dict]:
    """Tests at the end of the runs, per measure: one-way ANOVA over all methods, and pairs.

    Pairs, for the paper's claims: SAGG-RIAC vs SAGG-Random, each goal-space method vs
    ACTUATOR-Random, ACTUATOR-RIAC vs ACTUATOR-Random. Each pair gets a two-group one-way ANOVA (as
    in the paper) and a Welch t-test.

    Args:
        runs: Results of one experiment.
        methods: Methods present.

    Returns:
        Rows {measure, test, groups, statistic, p_value, means}.
    """
    pairs = [
        ("SAGG-RIAC", "SAGG-Random"),
        ("SAGG-RIAC", "ACTUATOR-Random"),
        ("SAGG-Random", "ACTUATOR-Random"),
        ("ACTUATOR-RIAC", "ACTUATOR-Random"),
    ]
    rows = []
    for measure in MEASURES:
        samples = {method: _Final(runs, method, measure) for method in methods}
        present = [method for method in methods if samples[method].size >= 2]
        if len(present) >= 2:
            result = stats.f_oneway(*(samples[method] for method in present))
            rows.append(
                {
                    "measure": measure,
                    "test": "one-way ANOVA",
                    "groups": " / ".join(present),
                    "statistic": float(result.statistic),
                    "p_value": float(result.pvalue),
                    "means": [float(samples[method].mean()) for method in present],
                }
            )
        for first, second in pairs:
            if first not in present or second not in present:
                continue
            anova = stats.f_oneway(samples[first], samples[second])
            welch = stats.ttest_ind(samples[first], samples[second], equal_var=False)
            for name, result in (("ANOVA (2 groups)", anova), ("Welch t-test", welch)):
                rows.append(
                    {
                        "measure": measure,
                        "test": name,
                        "groups": f"{first} vs {second}",
                        "statistic": float(result.statistic),
                        "p_value": float(result.pvalue),
                        "means": [float(samples[first].mean()), float(samples[second].mean())],
                    }
                )
    return rows


def WriteCurves(runs: list[dict], path: pathlib.Path) -> None:
    """CSV with one row per (method, seed, checkpoint)."""
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(["experiment", "method", "seed", "time_step", *MEASURES])
        for run in runs:
            spec = run["spec"]
            for point in run["curve"]:
                writer.writerow(
                    [
                        spec["experiment"],
                        spec["method"],
                        spec["seed"],
                        point["time_step"],
                        *(f"{point[measure]:.6g}" for measure in MEASURES),
                    ]
                )


def CurvesFigure(runs: list[dict], methods: list[str], experiment: int) -> Figure:
    """Mean and standard deviation over seeds of both errors against time steps (Fig. 4-5)."""
    figure, axes = plt.subplots(1, 2, figsize=(12, 4.5))
    for offset, method in enumerate(methods):
        method_runs = [run for run in runs if run["spec"]["method"] == method]
        if not method_runs:
            continue
        steps = np.array([point["time_step"] for point in method_runs[0]["curve"]]) / 1000
        for axis, measure in zip(axes, MEASURES, strict=True):
            values = np.array([[point[measure] for point in run["curve"]] for run in method_runs])
            mean, spread = values.mean(axis=0), values.std(axis=0)
            (line,) = axis.plot(steps, mean, label=f"{method} ({len(method_runs)} seeds)")
            # Error bars shifted per method for readability, as in the paper's figures.
            shift = (offset - 1.5) * 0.01 * steps[-1]
            axis.errorbar(
                steps[1:] + shift,
                mean[1:],
                yerr=spread[1:],
                fmt="none",
                color=line.get_color(),
                capsize=2,
                alpha=0.7,
            )
    for axis, measure, title in zip(
        axes,
        MEASURES,
        ("inverse model: reaching error on the test goals", "forward model: prediction error"),
        strict=True,
    ):
        axis.set(
            xlabel="time steps [thousands of micro-actions]",
            ylabel=f"mean {measure.replace('_', ' ')} [units; arm length 50]",
            title=title,
        )
        axis.grid(alpha=0.3)
        axis.legend(fontsize=8, title="method (mean ± std)", title_fontsize=8)
    figure.suptitle(
        f"Experiment {experiment}: errors of the learned models, mean ± std over seeds "
        "(cf. the paper's Fig. 4-5)"
    )
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


def _Format(values: np.ndarray) -> str:
    spread = values.std(ddof=1) if values.size > 1 else 0.0
    return f"{values.mean():.2f} ± {spread:.2f}"


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


def WriteReport(
    all_runs: dict[int, list[dict]],
    statistics: dict[int, list[dict]],
    methods: list[str],
    command: str,
    path: pathlib.Path,
) -> None:
    """Markdown report: per experiment, final errors, wall times and tests."""
    lines = [
        "# SAGG-RIAC experiments (Baranes & Oudeyer, IROS 2010, Sec. IV)",
        "",
        f"Command: `{command}` ({Provenance(path.parent)})",
        "",
    ]
    for experiment, runs in all_runs.items():
        if not runs:
            continue
        budget = runs[0]["spec"]["budget"]
        lines += [
            f"## Experiment {experiment} ({budget} time steps per run)",
            "",
            "| method | seeds | final reaching error | final prediction error "
            "| mean wall time per run (s) | goals per run | goals in reach (%) |",
            "|---|---|---|---|---|---|---|",
        ]
        for method in methods:
            method_runs = [run for run in runs if run["spec"]["method"] == method]
            if not method_runs:
                continue
            reaching, prediction = (_Format(_Final(runs, method, measure)) for measure in MEASURES)
            wall = np.mean([run["wall_time_s"] for run in method_runs])
            goals = _GoalStatistics(method_runs)
            row = f"| {method} | {len(method_runs)} | {reaching} | {prediction} | {wall:.1f} |"
            lines.append(f"{row} {goals} |")
        lines += [
            "",
            "Errors: mean ± sample standard deviation over seeds at the last checkpoint "
            "(units; arm length 50). Goals: self-generated goals (subgoals excluded) per run, and "
            "the share of them inside the reachable half-disc of radius 50 (goal-space methods).",
            "",
            "| measure | test | groups | means | statistic | p |",
            "|---|---|---|---|---|---|",
        ]
        for row in statistics[experiment]:
            means = ", ".join(f"{value:.2f}" for value in row["means"])
            lines.append(
                f"| {row['measure']} | {row['test']} | {row['groups']} | {means} | "
                f"{row['statistic']:.3f} | {row['p_value']:.3g} |"
            )
        lines += [
            "",
            f"Plots: `exp{experiment}_curves.png`"
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


def Analyse(specs: list[RunSpec], output: pathlib.Path, methods: list[str], command: str) -> None:
    """Writes curves CSV, plots, statistics JSON and report.md from the run files present."""
    experiments = sorted({spec.experiment for spec in specs})
    all_runs, statistics = {}, {}
    for experiment in experiments:
        runs = LoadRuns([spec for spec in specs if spec.experiment == experiment], output)
        all_runs[experiment] = runs
        statistics[experiment] = Statistics(runs, methods) if runs else []
        if not runs:
            continue
        WriteCurves(runs, output / f"exp{experiment}_curves.csv")
        SaveFigure(
            CurvesFigure(runs, methods, experiment),
            output / f"exp{experiment}_curves.png",
            dpi=110,
        )
        sagg_riac_runs = [run for run in runs if run["spec"]["method"] == SaggRiac.name]
        if sagg_riac_runs:
            SaveFigure(
                GoalsFigure(sagg_riac_runs[0]), output / f"exp{experiment}_goals.png", dpi=100
            )
    WriteTextAtomically(
        output / "statistics.json",
        # A test that could not be computed (NaN) is written null.
        StrictJson({str(key): _NoNan(value) for key, value in statistics.items()}, indent=1),
    )
    WriteReport(all_runs, statistics, methods, command, output / "report.md")


def main(argv=None) -> None:
    """Command line: runs the missing runs, then analyses.

    Args:
        argv: Arguments (default: sys.argv[1:]).
    """
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
    parser.add_argument("--seeds", type=PositiveInt, default=15, help="number of seeds (paper: 15)")
    parser.add_argument("--first-seed", type=NonNegativeInt, default=0, help="the first seed")
    parser.add_argument(
        "--budget-exp1", type=PositiveInt, default=50_000, help="paper: 50,000 movements"
    )
    parser.add_argument(
        "--budget-exp2", type=PositiveInt, default=200_000, help="paper: 200,000 time steps"
    )
    parser.add_argument(
        "--checkpoints", type=PositiveInt, default=20, help="evaluations after step 0"
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
        help="tiny battery: 2 seeds, 600/800 time steps, 2 checkpoints",
    )
    AddBackendArguments(parser)
    args = parser.parse_args(argv)
    if args.smoke:
        args.seeds, args.budget_exp1, args.budget_exp2, args.checkpoints = 2, 600, 800, 2
    budgets = {1: args.budget_exp1, 2: args.budget_exp2}
    # Seed-major order: an interrupted battery leaves every method with about as many seeds.
    specs = [
        RunSpec(experiment, method, seed, budgets[experiment], args.checkpoints)
        for experiment in args.experiments
        for seed in range(args.first_seed, args.first_seed + args.seeds)
        for method in args.methods
    ]
    started = time.perf_counter()
    if not args.analyse_only:
        RunAll(specs, args.output, BackendOf(args))
    command = "mobee-drake experiment saggriac " + " ".join(
        argv if argv is not None else sys.argv[1:]
    )
    Analyse(specs, args.output, args.methods, command)
    print(
        f"done in {time.perf_counter() - started:.1f} s; report: {args.output / 'report.md'}",
        flush=True,
    )


if __name__ == "__main__":
    main()
