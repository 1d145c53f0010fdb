"""What the reach-learning battery's runs did, one value per run (ch. 8.4): the evaluations'
summed rewards per stage and their trend, and the behaviour the source describes (its
fingerprints: favourite reaches, Fig. 8.7's lines, coverage, robot time)."""

import math

import numpy as np

from mobee_drake.experiments.ch8_figures import EvaluationSum, RunLog
from mobee_drake.experiments.ch8_reaching import ReachRun
from mobee_drake.experiments.statistics import RunMeans, Trend

# The reaches a run's favourites (Fig. 8.4) and a window's vertical lines (Fig. 8.7) count.
FAVOURITES = 2
# Where the source's fingerprints are read (ch. 8.4.3): greedy and intrinsic alike up to about
# 800 problem-tries; the intrinsic agent's coverage by 3200.
ALIKE_UNTIL, COVERAGE_AT = 800, 3200


def _TopShare(counts: np.ndarray) -> float:
    """The share of ``counts`` in its FAVOURITES largest entries (nan when empty)."""
    total = counts.sum()
    return float(np.sort(counts)[::-1][:FAVOURITES].sum() / total) if total else math.nan


def Fingerprints(run: ReachRun) -> dict:
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
    k, m = run.num_transitions, run.num_states
    stages = run.stages
    last = run.evaluations[stages[-1]]
    tries = [t for e in last for t in e]
    counts = np.bincount([t["reach"] - k for t in tries if t["reach"] >= 0], minlength=m)
    log = RunLog(run)
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
        robot_hours=run.simulated_seconds / 3600,
    )


def TimedOutTries(run: ReachRun) -> int:
    """The run's exploratory problem-tries that ran out of actions without a reach (a try
    reaches at most once; the rest end after ``max_actions``). For runs on a fixed space, whose
    log numbers every reach from ``num_transitions`` on (a reshaped space's log renumbers
    them)."""
    reaches = np.count_nonzero(RunLog(run)[:, 2] >= run.num_transitions)
    return run.settings.problem_tries - int(reaches)


def RunSums(runs: list[ReachRun], stage: int, penalties: bool) -> np.ndarray:
    """One value per run: the mean of its evaluations' sums at ``stage``."""
    return RunMeans([[EvaluationSum(e, penalties) for e in r.evaluations[stage]] for r in runs])


def RunTrends(runs: list[ReachRun], stages: list[int], penalties: bool) -> list[float]:
    """One value per run: the trend (:func:`Trend`) of its evaluations' mean sums over
    ``stages``."""
    sums = np.array([RunSums(runs, stage, penalties) for stage in stages])  # stages x runs
    return [Trend(stages, sums[:, i]) for i in range(len(runs))]


def RobotTimeRatio(by_strategy: dict[str, list[ReachRun]]) -> float:
    """Random's mean robot time over that of greedy and intrinsic (the source: 1.86)."""
    hours = {s: np.mean([r.simulated_seconds for r in by_strategy[s]]) for s in by_strategy}
    return hours["random"] / np.mean([hours["greedy"], hours["intrinsic"]])


# A report's column of penetrations (see PenetrationCell).
PENETRATION_HEADER = (
    "penetrating periods, summed over the runs: all / outside the problems whose target "
    "appeared inside the robot (such problems)"
)


def PenetrationCell(runs) -> str:
    """The runs' penetrating periods, summed: all of them / those of the problems whose target
    did not appear inside the robot (the problems whose did); ``-`` where some run did not count
    them (:mod:`~mobee_drake.reaching.appearance`)."""
    total = sum(r.penetrating_steps for r in runs)
    if any(r.appeared_inside is None for r in runs):
        return f"{total} / - (-)"
    other = sum(r.other_penetrating_steps for r in runs)
    return f"{total} / {other} ({sum(r.appeared_inside for r in runs)})"
