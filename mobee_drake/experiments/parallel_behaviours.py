"""Experiment: the palm-normal behaviour beside the curious reach planner (ch. 9.4.2;
docs/behaviours.md).

``diagrams/parallel_behaviours.yaml`` runs three behaviours at once on the iCub: the curious agent
explores the right arm's shoulder-elbow hypercube (ch. 7.1), the neck keeps a ball in the head's
view, and the right wrist keeps the palm's normal pointed at the ball. Each seed runs twice: with
the palm behaviour ("on") and with it only measuring, the wrist held at home ("off"); the other
behaviours are the same. Measured per run, from its data log:

- the palm's pointing error (degrees between the palm's normal and the line to the ball) at the
  end of each of the agent's actions (a reach of the arm), their mean, and the share of actions
  that end with the palm facing the ball (within :data:`FACING_DEG`);
- the gaze's error, its mean over the run and at the end;
- the agent's actions, and the control periods with a penetration (the safety of the whole).

The comparison is paired by seed (on minus off; the paired t-test and Wilcoxon's signed-rank
test, Holm-corrected over the two measures compared).

Run: ``mobee-drake experiment parallel-behaviours [--seeds 10] [--duration 60] [--output DIR]
[--doc docs/behaviours.md]``.
"""

import dataclasses as dc
import pathlib
import time

import numpy as np
import pandas as pd

from mobee_drake.experiments.arguments import CommandParser, PositiveFloat, PositiveInt
from mobee_drake.experiments.battery import (
    AddBackendArguments,
    BackendOf,
    Job,
    RunBattery,
    RunFolder,
)
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.experiments.plots import Legend, SaveFigure, plt
from mobee_drake.experiments.statistics import FiniteMean, PairedBySeed
from mobee_drake.owned_folders import OwnedFolder
from mobee_drake.scenario import LoadScenario, RunScenario

SCENARIO = "parallel_behaviours"
# A reach ends with the palm facing the ball when its normal is within this of the line to it.
FACING_DEG = 15.0
CONDITIONS = ("on", "off")
# The data log's columns read.
PALM, GAZE, ACTIONS = (
    "palm_pointing.error_deg",
    "gaze_pointing.error_deg",
    "agent.right_arm.actions_done",
)
# The traces kept for the figure: one sample per this many seconds.
TRACE_PERIOD = 0.1


@dc.dataclass
class ParallelRun:
    """One seed in one condition (angles in degrees, times in s)."""

    seed: int
    condition: str
    # The palm's error at the end of each action, and the gaze's over the run.
    end_angles: list[float]
    gaze_mean: float
    gaze_final: float
    penetrating_steps: int
    wall_seconds: float
    # (time, palm error, gaze error) every TRACE_PERIOD, for the figure.
    trace: list[list[float]] = dc.field(repr=False)

    @property
    def palm_mean(self) -> float:
        return float(np.mean(self.end_angles)) if self.end_angles else float("nan")

    @property
    def facing(self) -> float:
        """The share of the actions that end with the palm facing the ball."""
        angles = np.asarray(self.end_angles)
        return float(np.mean(angles <= FACING_DEG)) if angles.size else float("nan")


def RunOne(run: RunFolder, seed: int, condition: str, duration: float) -> dict:
    """The battery job: one seed, the palm behaviour on or only measuring."""
    scenario = LoadScenario(SCENARIO, f"{{duration: {duration}, random_seed: {seed}}}")
    palm = scenario.attractor.behaviours[1]
    if condition == "off":
        palm.client = dc.replace(palm.client, gain=0.0)
    log = run.path / "log.parquet"
    began = time.perf_counter()
    summary = RunScenario(scenario, data_log=str(log))
    wall = time.perf_counter() - began
    table = pd.read_parquet(log)
    ends = np.flatnonzero(np.diff(table[ACTIONS].to_numpy()) > 0) + 1
    every = max(1, round(TRACE_PERIOD / (table["time"].iloc[1] - table["time"].iloc[0])))
    gaze = summary.outcome["client"]["gaze_pointing"]
    return dc.asdict(
        ParallelRun(
            seed=seed,
            condition=condition,
            end_angles=table[PALM].to_numpy()[ends].tolist(),
            gaze_mean=gaze["mean_error_deg"],
            gaze_final=gaze["final_error_deg"],
            penetrating_steps=summary.safety.penetrating_steps,
            wall_seconds=wall,
            trace=table[["time", PALM, GAZE]].to_numpy()[::every].tolist(),
        )
    )


def Report(runs: list[ParallelRun], command: str) -> str:
    """The report's table and the paired comparisons (markdown)."""
    by = {
        c: sorted((r for r in runs if r.condition == c), key=lambda r: r.seed) for c in CONDITIONS
    }
    lines = [
        "| palm behaviour | runs | actions per run | palm error at an action's end, deg (mean "
        f"of runs) | actions ending with the palm facing the ball (<= {FACING_DEG:g} deg) | gaze "
        "error, mean over the run, deg | gaze error at the end, deg | penetrating periods | "
        "wall s per run |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for condition, group in by.items():
        lines.append(
            f"| {condition} | {len(group)} | {np.mean([len(r.end_angles) for r in group]):.1f} | "
            f"{FiniteMean([r.palm_mean for r in group]):.1f} | "
            f"{100 * FiniteMean([r.facing for r in group]):.0f} % | "
            f"{np.mean([r.gaze_mean for r in group]):.1f} | "
            f"{np.mean([r.gaze_final for r in group]):.2f} | "
            f"{sum(r.penetrating_steps for r in group)} | "
            f"{np.mean([r.wall_seconds for r in group]):.1f} |"
        )
    measures = {
        "palm error at an action's end (deg)": lambda r: r.palm_mean,
        "share of actions ending facing the ball": lambda r: r.facing,
    }
    lines += PairedBySeed({"": (by["on"], by["off"])}, measures, "On minus off")
    return "\n".join(lines) + f"\n\nCommand: `{command}`."


def Figure(runs: list[ParallelRun]):
    """The palm's and the gaze's errors over one seed's run, on and off, and every action-end
    palm error of all runs."""
    figure, (trace_axis, ends_axis) = plt.subplots(1, 2, figsize=(13, 4.2))
    seed = min(r.seed for r in runs)
    for run, colour in zip(
        sorted((r for r in runs if r.seed == seed), key=lambda r: r.condition),
        ("tab:red", "tab:green"),
    ):
        trace = np.array(run.trace)
        style = "-" if run.condition == "on" else "--"
        trace_axis.plot(
            trace[:, 0], trace[:, 1], style, color=colour, label=f"palm, behaviour {run.condition}"
        )
        if run.condition == "on":
            trace_axis.plot(trace[:, 0], trace[:, 2], color="tab:blue", label="gaze")
    trace_axis.set(
        xlabel="time [s]",
        ylabel="pointing error [deg]",
        title=f"seed {seed}: the palm's normal and the head's gaze to the ball",
    )
    Legend(trace_axis)
    bins = np.linspace(0, 180, 37)
    for condition, colour in (("off", "tab:red"), ("on", "tab:green")):
        angles = np.concatenate([r.end_angles for r in runs if r.condition == condition] or [[]])
        ends_axis.hist(angles, bins=bins, color=colour, alpha=0.6, label=f"behaviour {condition}")
    ends_axis.axvline(
        FACING_DEG, color="black", linestyle=":", label=f"facing (<= {FACING_DEG:g} deg)"
    )
    ends_axis.set(
        xlabel="palm error at an action's end [deg]",
        ylabel="actions [count]",
        title=f"every action's end, {len({r.seed for r in runs})} seeds",
    )
    Legend(ends_axis)
    return figure


def main(argv: list[str] | None = None) -> None:
    parser = CommandParser(
        prog="mobee-drake experiment parallel-behaviours", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument("--seeds", type=PositiveInt, default=10, help="seeds (run pairs)")
    parser.add_argument(
        "--duration", type=PositiveFloat, default=60.0, help="simulated seconds per run"
    )
    parser.add_argument(
        "--output", default="results/parallel_behaviours", help="the battery folder"
    )
    parser.add_argument(
        "--doc", help="a doc whose generated block 'parallel-behaviours' gets the report"
    )
    AddBackendArguments(parser)
    args = parser.parse_args(argv)
    CheckDocBlocks(parser, args.doc, "parallel-behaviours")
    output = pathlib.Path(args.output)
    jobs = [
        Job(
            f"seed{seed}_{condition}",
            RunOne,
            dict(seed=seed, condition=condition, duration=args.duration),
        )
        for seed in range(args.seeds)
        for condition in CONDITIONS
    ]
    results = RunBattery(jobs, output, backend=BackendOf(args), description="parallel behaviours")
    runs = [ParallelRun(**r) for r in results.values()]
    command = "mobee-drake experiment parallel-behaviours " + " ".join(
        argv if argv is not None else []
    )
    report = Report(runs, command.strip())
    with OwnedFolder(output, "battery"):
        (output / "report.md").write_text(report + "\n")
        SaveFigure(Figure(runs), output / "parallel_behaviours.png")
    if args.doc:
        WriteGeneratedTable(args.doc, "parallel-behaviours", command.strip(), report)
    print(report)
    print(f"report: {output / 'report.md'}; figure: {output / 'parallel_behaviours.png'}")


if __name__ == "__main__":
    main()
