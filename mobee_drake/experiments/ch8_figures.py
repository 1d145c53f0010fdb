"""The figures of the reach-learning battery (ch. 8.4): Fig. 8.2, 8.4-8.6, 8.7 and 8.8, from the
runs' results (:func:`mobee_drake.experiments.ch8_reaching.RunOne`)."""

import math

import numpy as np

from mobee_drake.experiments.ch8_reaching import ReachRun
from mobee_drake.experiments.plots import Figure, Legend, StackedBars, plt
from mobee_drake.reaching.learner import (
    LOG_COLUMNS,
)
from mobee_drake.reaching.predictors import (
    FAILED_TRANSITION_REWARD,
)


def EvaluationSum(evaluation: list[dict], penalties: bool = True) -> float:
    """The reward summed over an evaluation's problem-tries: the reaches' rewards (eq. 8.4; a
    try that timed out has none) and, with ``penalties`` (the source's definition, ch. 8.3.1 and
    8.3.3), the -10 of every failed transition."""
    reaches = sum(r["reward"] or 0.0 for r in evaluation)
    if not penalties:
        return reaches
    if any("failed_transitions" not in r for r in evaluation):
        return math.nan  # A result file written before the count was kept: unknown.
    return reaches + FAILED_TRANSITION_REWARD * sum(r["failed_transitions"] for r in evaluation)


def RunLog(run: ReachRun) -> np.ndarray:
    """A run's log of actions, one row per action (columns: LOG_COLUMNS)."""
    return np.array(run.log).reshape(-1, len(LOG_COLUMNS))


def _Cumulatives(runs: list[ReachRun], stages: list[int], penalties: bool = True) -> np.ndarray:
    """The summed reward of every evaluation (:func:`EvaluationSum`): runs x stages x
    evaluations."""
    return np.array(
        [
            [[EvaluationSum(e, penalties) for e in r.evaluations[stage]] for stage in stages]
            for r in runs
        ]
    )


def _Seeds(runs: list[ReachRun], repeat: int = 1) -> list[str]:
    """Legend labels of the runs' seeds, each ``repeat`` times (one per stacked row)."""
    return [f"seed {r.settings.seed}" for r in runs for _ in range(repeat)]


def CumulativeRewardFigure(by_strategy: dict[str, list[ReachRun]], stages: list[int]) -> Figure:
    """Fig. 8.2: the cumulative reward of every evaluation, stacked per stage, one colour per
    seed (its evaluations split by white edges): the reaches' rewards as bars, and a black tick
    where the stack ends with the failed transitions' penalties counted (the source's sum)."""
    figure, axes = plt.subplots(
        1, len(by_strategy), figsize=(6.5 * len(by_strategy), 4.5), squeeze=False, sharey=True
    )
    for axis, (strategy, runs) in zip(axes[0], by_strategy.items()):
        table = _Cumulatives(runs, stages, penalties=False)
        evaluations = table.shape[2]
        StackedBars(
            axis,
            table.transpose(0, 2, 1).reshape(-1, len(stages)),
            _Seeds(runs, evaluations),
            x=np.arange(len(stages)),
            width=0.6,
        )
        axis.hlines(
            _Cumulatives(runs, stages).sum(axis=(0, 2)),
            np.arange(len(stages)) - 0.35,
            np.arange(len(stages)) + 0.35,
            colors="black",
            label="sum with the -10 penalties",
        )
        Legend(axis)  # (again: the seeds' colours and the penalties' tick)
        axis.set_xticks(np.arange(len(stages)), [str(s) for s in stages])
        axis.set(
            xlabel="exploratory problem-tries [count]",
            ylabel="cumulative reward [sum of eq. 8.4\nover the problems], evaluations stacked",
            title=f"{strategy}: {len(runs)} seeds x {evaluations} evaluations per stage",
        )
        axis.yaxis.set_tick_params(labelleft=True)
    figure.suptitle(
        "Fig. 8.2 on the kinematic iCub: cumulative reward of the exploitation evaluations"
    )
    return figure


def ReachesFigure(strategy: str, runs: list[ReachRun], stages: list[int], k: int, m: int) -> Figure:
    """Fig. 8.4-8.6: the reaching state-actions chosen in evaluations, per stage, seeds
    stacked (``k`` transitions, ``m`` states)."""
    figure, axes = plt.subplots(len(stages), 1, figsize=(12, 2.6 * len(stages)), squeeze=False)
    for axis, stage in zip(axes[:, 0], stages):
        counts = np.array(
            [
                np.bincount(
                    [t["reach"] - k for e in r.evaluations[stage] for t in e if t["reach"] >= 0],
                    minlength=m,
                )
                for r in runs
            ]
        )
        StackedBars(axis, counts, _Seeds(runs))
        axis.set(
            xlabel=f"reaching state-action - {k} = the state it reaches from [index]",
            ylabel="reaches [count]",
            title=f"{strategy}, after {stage} problem-tries: reaches chosen in the "
            "evaluations, seeds stacked",
        )
    return figure


def ProblemTriesFigure(
    by_strategy: dict[str, list[ReachRun]], stages: list[int], k: int, m: int
) -> Figure:
    """Fig. 8.7: exploratory tries per problem (row) and state-action (column) before each
    stage, mean over seeds, one column of images per strategy."""
    figure, axes = plt.subplots(
        len(stages),
        len(by_strategy),
        figsize=(6.5 * len(by_strategy), 2.6 * len(stages)),
        squeeze=False,
    )
    num_problems = len(next(iter(by_strategy.values()))[0].evaluations[stages[0]][0])
    for column, (strategy, runs) in enumerate(by_strategy.items()):
        for row, stage in enumerate(stages):
            image = np.zeros((num_problems, k + m))
            for r in runs:
                log = RunLog(r)
                log = log[log[:, 0] < stage]
                np.add.at(image, (log[:, 1].astype(int), log[:, 2].astype(int)), 1.0)
            axis = axes[row, column]
            shown = axis.imshow(
                image / len(runs), aspect="auto", cmap="jet", interpolation="nearest"
            )
            figure.colorbar(shown, ax=axis, label=f"tries [count,\nmean of {len(runs)} seeds]")
            axis.set(
                xlabel=f"state-action [index; reaches from {k}]",
                ylabel="problem [index]",
                title=f"{strategy}: tries in the first {stage} problem-tries",
            )
    return figure


def FailedTransitionsFigure(by_strategy: dict[str, list[ReachRun]], k: int) -> Figure:
    """Fig. 8.8: failed transitions (reward -10) per transition state-action, seeds stacked."""
    figure, axes = plt.subplots(
        len(by_strategy), 1, figsize=(12, 3.2 * len(by_strategy)), squeeze=False
    )
    for axis, (strategy, runs) in zip(axes[:, 0], by_strategy.items()):
        counts = []
        for r in runs:
            log = RunLog(r)
            counts.append(np.bincount(log[log[:, 6] < 0, 2].astype(int), minlength=k)[:k])
        StackedBars(axis, np.array(counts), _Seeds(runs))
        axis.set(
            xlabel="transition state-action [index]",
            ylabel="failed transitions [count]",
            title=f"{strategy}: failed transitions (reward -10) in "
            f"{runs[0].settings.problem_tries} problem-tries per seed, seeds stacked",
        )
    return figure
