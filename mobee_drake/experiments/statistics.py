"""Run-level statistics for the experiments' reports (issue 23, point 8): first the reach-learning
battery's (ch. 8); one module for every battery that compares learners over their runs.

The evaluations of one run share one learner (its histories), so they are not independent: the
five evaluations at a stage differ only in their start state and problem order. Every comparison
here therefore takes one value per run and stage (the mean over that run's evaluations) and
compares strategies over their runs. With the same number of evaluations in every run this is
also what a random-intercept model (the run a random effect) tests for a between-strategy effect:
in a balanced design its F-test of the fixed effect equals the pooled-variance t-test on the run
means (unless the run variance's estimate is truncated at zero); we report Welch's version, which
does not assume equal variances between strategies.

Beside the p-values, effect sizes: the difference of means, Hedges' g (Cohen's d with the
pooled run-level standard deviation, corrected for small samples by ``1 - 3 / (4 (n_a + n_b) -
9)``) and, from the Mann-Whitney U test, the probability of superiority ``U / (n_a n_b)`` (the
chance that a run of the first strategy beats one of the second, ties counting half).
"""

import dataclasses as dc
import math

import numpy as np
from scipy.stats import mannwhitneyu, ttest_ind


@dc.dataclass
class Comparison:
    """Strategy a against strategy b on one value per run."""

    n_a: int
    n_b: int
    mean_a: float
    mean_b: float
    # mean_a - mean_b.
    difference: float
    # Cohen's d (pooled standard deviation, ddof 1) and its small-sample correction.
    cohens_d: float
    hedges_g: float
    welch_t: float
    welch_df: float
    welch_p: float
    mann_whitney_u: float
    mann_whitney_p: float
    # P(a run of a beats a run of b) + P(tie) / 2 = U / (n_a n_b).
    superiority: float

    def Text(self) -> str:
        """One line for a report: difference, g, Welch's p, superiority and Mann-Whitney's p."""
        return (
            f"{self.difference:+.2f} (g = {_Number(self.hedges_g)}, Welch p = "
            f"{_Number(self.welch_p, '.2g')}; P(a > b) = {self.superiority:.2f}, "
            f"Mann-Whitney p = {_Number(self.mann_whitney_p, '.2g')}; "
            f"{self.n_a} vs {self.n_b} runs)"
        )


def _Number(value: float, spec: str = ".2f") -> str:
    return "n/a" if math.isnan(value) else format(value, spec)


def CompareRuns(a, b) -> Comparison:
    """Welch's t-test, Mann-Whitney's U test (exact when small and without ties) and effect
    sizes of ``a`` against ``b``, one finite value per run each (at least 2 runs a side)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.ndim != 1 or b.ndim != 1 or len(a) < 2 or len(b) < 2:
        raise ValueError(
            f"compare at least 2 runs per side, one value each; got shapes {a.shape} and {b.shape}"
        )
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError("run values must be finite")
    n_a, n_b = len(a), len(b)
    difference = float(a.mean() - b.mean())
    pooled = math.sqrt(((n_a - 1) * a.var(ddof=1) + (n_b - 1) * b.var(ddof=1)) / (n_a + n_b - 2))
    if pooled > 0:
        d = difference / pooled
    else:  # No spread at all: identical groups, or separated without any overlap.
        d = 0.0 if difference == 0 else math.copysign(math.inf, difference)
    g = d * (1 - 3 / (4 * (n_a + n_b) - 9))
    va, vb = a.var(ddof=1) / n_a, b.var(ddof=1) / n_b
    if va + vb > 0:
        welch = ttest_ind(a, b, equal_var=False)
        t, p = float(welch.statistic), float(welch.pvalue)
        df = (va + vb) ** 2 / (va**2 / (n_a - 1) + vb**2 / (n_b - 1))
    else:
        t, p, df = math.nan, math.nan, math.nan
    if np.all(a == a[0]) and np.all(b == a[0]):  # Mann-Whitney says nothing about equal groups.
        u, mw_p = n_a * n_b / 2, 1.0
    else:
        test = mannwhitneyu(a, b, alternative="two-sided")
        u, mw_p = float(test.statistic), float(test.pvalue)
    return Comparison(
        n_a=n_a,
        n_b=n_b,
        mean_a=float(a.mean()),
        mean_b=float(b.mean()),
        difference=difference,
        cohens_d=d,
        hedges_g=g,
        welch_t=t,
        welch_df=df,
        welch_p=p,
        mann_whitney_u=u,
        mann_whitney_p=mw_p,
        superiority=u / (n_a * n_b),
    )


def RunMeans(values_per_run) -> np.ndarray:
    """One value per run: the mean of each run's own values (its evaluations at a stage),
    never a pool of them; runs may have different numbers of values, but none may be empty."""
    means = []
    for i, values in enumerate(values_per_run):
        values = np.asarray(values, dtype=float)
        if values.size == 0:
            raise ValueError(f"run {i} has no values to average")
        means.append(values.mean())
    return np.array(means)
