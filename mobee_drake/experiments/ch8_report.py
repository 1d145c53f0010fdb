"""The report of the reach-learning battery (ch. 8.4): per setting, the figures, the reward,
effort, MDP and fingerprint tables, and the source's claims tested at run level
(:mod:`mobee_drake.experiments.statistics`); a sweep's fingerprints across its settings."""

import math
import pathlib

import numpy as np

from mobee_drake.experiments.ch8_claims import ClaimsTables
from mobee_drake.experiments.ch8_figures import (
    CumulativeRewardFigure,
    FailedTransitionsFigure,
    ProblemTriesFigure,
    ReachesFigure,
    RunLog,
)
from mobee_drake.experiments.ch8_measures import (
    ALIKE_UNTIL,
    COVERAGE_AT,
    FAVOURITES,
    PENETRATION_HEADER,
    Fingerprints,
    PenetrationCell,
    RobotTimeRatio,
    RunSums,
    RunTrends,
    TimedOutTries,
)
from mobee_drake.experiments.ch8_reaching import SOURCE_HOURS, ReachRun, SettingLabel
from mobee_drake.experiments.plots import SaveFigure
from mobee_drake.experiments.statistics import CompareRuns, CompareToZero
from mobee_drake.reaching.learner import ReachLearningConfig
from mobee_drake.reaching.strategies import REACH_STRATEGIES


def _BarrierPeriods(results: list[ReachRun]) -> str:
    """The periods the safety barrier acted in ``results`` (n/a for runs from before it was
    counted)."""
    if any(r.barrier_periods is None for r in results):
        return "n/a"
    return str(sum(r.barrier_periods for r in results))


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


def _WindowAtOrBefore(windows, end: int) -> int | None:
    ends = [w for w in windows if w <= end]
    return max(ends) if ends else None


def _Group(results: list[ReachRun]) -> dict[str, list[ReachRun]]:
    strategies = [s for s in REACH_STRATEGIES if any(r.settings.strategy == s for r in results)]
    return {s: [r for r in results if r.settings.strategy == s] for s in strategies}


def _SweepRow(label: str, results: list[ReachRun]) -> str:
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
        f"{RobotTimeRatio(by_strategy):.2f}"
        if {"random", "greedy", "intrinsic"} <= set(by_strategy)
        else "-"
    )
    return "| " + " | ".join(cells) + " |"


def Report(output: pathlib.Path, results: list[ReachRun]) -> str:
    """Plots like Fig. 8.2, 8.4-8.8 and a markdown report; returns the report. Results of
    several settings (a sweep: distance unit, reach force) get a fingerprint table across the
    settings, then a section each, their figures in ``output/<SettingLabel>/``."""
    groups: dict[str, list[ReachRun]] = {}
    for r in results:
        groups.setdefault(SettingLabel(r.settings), []).append(r)
    claims = [
        "## The source's claims, marked per setting (issue 33)",
        "",
        *ClaimsTables(results),
        "",
    ]
    if len(groups) == 1:
        return "\n".join(claims) + "\n" + _SettingReport(output, results)
    lines = [
        *claims,
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


def _SettingReport(output: pathlib.Path, results: list[ReachRun]) -> str:
    """Plots and the report of one setting's runs."""
    by_strategy = _Group(results)
    stages = sorted({stage for r in results for stage in r.evaluations})
    k, m = results[0].num_transitions, results[0].num_states
    _SaveSettingFigures(output, by_strategy, stages, k, m)
    prints = {s: [Fingerprints(r) for r in runs] for s, runs in by_strategy.items()}
    sections = (
        _RewardSection(results, by_strategy, stages),
        _EffortSection(by_strategy),
        _MdpSection(results, by_strategy, k),
        _FingerprintSection(results, prints, stages, m),
        _UnpairedSection(by_strategy, prints, stages),
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


def _RewardSection(results: list[ReachRun], by_strategy: dict, stages) -> list[str]:
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
                    ReachLearningConfig(
                        tie_break=r.settings.tie_break, plateau_rule=r.settings.plateau_rule
                    ).EffectiveTieBreak()
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
                + " | ".join(_MeanSd(RunSums(runs, s, penalties)) for s in stages)
                + " |"
            )
    return lines


def _EvaluationHours(runs: list[ReachRun], hours: float) -> str:
    """The runs' evaluations' robot hours and their share of ``hours``; ``-`` where some run
    did not time its evaluations."""
    if any(r.evaluation_seconds is None for r in runs):
        return "-"
    evaluation = sum(r.evaluation_seconds for r in runs) / 3600
    return f"{evaluation:.1f} ({evaluation / hours:.0%})"


def _EffortSection(by_strategy: dict) -> list[str]:
    """Robot time, failed transitions, timed-out problem-tries and safety per strategy."""
    strategies = list(by_strategy)
    lines = [
        "",
        "## Robot time, failed transitions and reaches",
        "",
        "| strategy | runs | robot hours (all runs) | of them, the evaluations' | source's robot "
        "hours (5 runs of 6400) | actions per problem-try | failed transitions per problem-try | "
        "timed-out problem-tries | wall hours (all runs) | "
        f"{PENETRATION_HEADER} | periods the safety barrier acted |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for strategy in strategies:
        actions, failed, timeouts, tries = 0, 0, 0, 0
        for r in by_strategy[strategy]:
            log = RunLog(r)
            actions += len(log)
            failed += int(np.sum(log[:, 6] < 0))
            tries += r.settings.problem_tries
            timeouts += TimedOutTries(r)
        hours = sum(r.simulated_seconds for r in by_strategy[strategy]) / 3600
        lines.append(
            f"| {strategy} | {len(by_strategy[strategy])} | {hours:.1f} | "
            f"{_EvaluationHours(by_strategy[strategy], hours)} | "
            f"{SOURCE_HOURS.get(strategy, '-')} | {actions / tries:.2f} | {failed / tries:.2f} | "
            f"{timeouts} | {sum(r.wall_seconds for r in by_strategy[strategy]) / 3600:.2f} | "
            f"{PenetrationCell(by_strategy[strategy])} | "
            f"{_BarrierPeriods(by_strategy[strategy])} |"
        )

    return lines


def _MdpSection(results: list[ReachRun], by_strategy: dict, k: int) -> list[str]:
    """The MDP learned with the reaches (ch. 9.4.1), when the runs recorded it."""
    if any(r.mdp is None for r in results):
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
        runs = [r.mdp for r in strategy_runs]
        success = [r["success_probability"] for r in runs if r["success_probability"] is not None]
        lines.append(
            f"| {strategy} | "
            f"{np.mean([r['updated_state_actions'] for r in runs]):.0f} | "
            + (f"{np.mean(success):.2f} |" if success else "- |")
        )
    return lines


def _FingerprintSection(results: list[ReachRun], prints: dict, stages, m: int) -> list[str]:
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
        f"{m} x {len(results[0].evaluations[stages[0]][0])}.",
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


def _UnpairedSection(by_strategy: dict, prints: dict, stages) -> list[str]:
    """Intrinsic motivation against the other strategies, unpaired and uncorrected (descriptive:
    the claims are marked by :mod:`mobee_drake.experiments.ch8_claims`)."""
    strategies = list(by_strategy)
    lines = [
        "",
        "## Intrinsic against the others, unpaired (descriptive)",
        "",
        "Intrinsic minus each other strategy, one value per run and stage (the mean of the "
        "run's evaluations; evaluations of one run share its learner and are never pooled): "
        "the difference of means, Hedges' g, Welch's t-test, the probability that an "
        "intrinsic run beats the other's and Mann-Whitney's test over the runs. These tests "
        "ignore the pairing by seed and are not corrected for their number: the claims are "
        "marked in the first section, from paired tests with Holm's correction.",
        "",
    ]
    if {"intrinsic", "random", "greedy"} <= set(strategies):
        trended = [s for s in stages if s > 0]
        for penalties, title in ((True, "the source's sum"), (False, "reaches only")):
            for stage in stages:
                sums = {s: RunSums(by_strategy[s], stage, penalties) for s in strategies}
                lines.append(
                    f"- {title}, after {stage} problem-tries, intrinsic minus "
                    + _IntrinsicMinusOthers(sums)
                )
            if len(trended) >= 2:
                trends = {s: RunTrends(by_strategy[s], trended, penalties) for s in strategies}
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
            f"- random exploration took {RobotTimeRatio(by_strategy):.2f} times the robot time "
            "of the other two (source: 207 h against 109 and 113 h, 1.86 times); robot hours per "
            "run, random minus the other two's runs: "
            + _Compare(hours["random"], hours["greedy"] + hours["intrinsic"])
            + ".",
        ]
    return lines
