"""Run-level statistics for comparing two learners: effect sizes with confidence intervals, tests,
and the power of the test at the measured effect (scipy only).

Every sample is one value per independent run (one seed); nothing here pools the test goals or
checkpoints of a run. Conventions: ``a`` is the first group, ``b`` the second; a positive Cohen's
d or rank-biserial correlation means that ``a`` tends to be larger than ``b`` (for an error,
that ``a`` is worse).
"""

import dataclasses
import math

import numpy as np
from scipy import optimize, stats

# Resamples of the rank-biserial correlation's bootstrap interval, and its seed.
BOOTSTRAP_RESAMPLES = 10_000
BOOTSTRAP_SEED = 0


def _Samples(a, b) -> tuple[np.ndarray, np.ndarray]:
    a, b = np.asarray(a, dtype=float).ravel(), np.asarray(b, dtype=float).ravel()
    if a.size < 2 or b.size < 2:
        raise ValueError(f"each group needs at least 2 runs, got {a.size} and {b.size}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError("the samples must be finite numbers")
    return a, b


def _CheckAlpha(alpha: float) -> None:
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"alpha must be in (0, 1), got {alpha}")


def CohensD(a, b) -> float:
    """Cohen's d = (mean(a) - mean(b)) / pooled standard deviation.

    Args:
        a: Values of the first group (one per run, at least 2).
        b: Values of the second group.

    Returns:
        d; NaN when both groups are constant (pooled standard deviation 0).
    """
    a, b = _Samples(a, b)
    pooled = math.sqrt(
        ((a.size - 1) * a.var(ddof=1) + (b.size - 1) * b.var(ddof=1)) / (a.size + b.size - 2)
    )
    if pooled == 0.0:
        return math.nan
    return float((a.mean() - b.mean()) / pooled)


def _Scale(n_a: int, n_b: int) -> float:
    """The noncentrality of a two-sample t statistic per unit of d: sqrt(n_a n_b / (n_a + n_b))."""
    return math.sqrt(n_a * n_b / (n_a + n_b))


def CohensDInterval(d: float, n_a: int, n_b: int, confidence: float = 0.95) -> tuple[float, float]:
    """Confidence interval of Cohen's d by inverting the noncentral t distribution.

    The two-sample t statistic is t = d sqrt(n_a n_b / (n_a + n_b)) with df = n_a + n_b - 2; the
    bounds are the noncentrality parameters under which the observed t sits at the upper and
    lower (1 - confidence) / 2 quantiles, scaled back to d (the exact interval under normality
    and equal variances).

    Args:
        d: Observed Cohen's d.
        n_a: Runs in the first group (>= 2).
        n_b: Runs in the second group (>= 2).
        confidence: Coverage, in (0, 1).

    Returns:
        (lower, upper); NaNs when d is NaN.
    """
    _CheckAlpha(1.0 - confidence)
    if n_a < 2 or n_b < 2:
        raise ValueError(f"each group needs at least 2 runs, got {n_a} and {n_b}")
    if not math.isfinite(d):
        return math.nan, math.nan
    df, scale = n_a + n_b - 2, _Scale(n_a, n_b)
    t = d * scale
    tail = (1.0 - confidence) / 2.0

    def Bound(quantile: float) -> float:
        def Gap(ncp: float) -> float:
            return stats.nct.cdf(t, df, ncp) - quantile

        # nct.cdf(t, df, ncp) falls from 1 to 0 as ncp grows; widen until the root is bracketed.
        low, high, width = t - 1.0, t + 1.0, 1.0
        while Gap(low) < 0.0:
            width *= 2.0
            low = t - width
        while Gap(high) > 0.0:
            width *= 2.0
            high = t + width
        return optimize.brentq(Gap, low, high, xtol=1e-10)

    return Bound(1.0 - tail) / scale, Bound(tail) / scale


def TwoSampleTPower(d: float, n_a: int, n_b: int, alpha: float = 0.05) -> float:
    """Power of the two-sided two-sample Student t test (= the two-group one-way ANOVA).

    Power = P(|T| > t_crit) with T noncentral t, df = n_a + n_b - 2, noncentrality d sqrt(n_a
    n_b / (n_a + n_b)), t_crit the 1 - alpha / 2 quantile of the central t.

    Args:
        d: The true (or assumed) standardised effect.
        n_a: Runs in the first group (>= 2).
        n_b: Runs in the second group (>= 2).
        alpha: Significance level.

    Returns:
        The probability of p < alpha; NaN when d is NaN.
    """
    _CheckAlpha(alpha)
    if n_a < 2 or n_b < 2:
        raise ValueError(f"each group needs at least 2 runs, got {n_a} and {n_b}")
    if not math.isfinite(d):
        return math.nan
    df, ncp = n_a + n_b - 2, d * _Scale(n_a, n_b)
    critical = stats.t.ppf(1.0 - alpha / 2.0, df)
    power = stats.nct.sf(critical, df, ncp) + stats.nct.cdf(-critical, df, ncp)
    if not math.isfinite(power):
        # scipy's noncentral t fails far in its tails (large ncp); there the normal limit holds.
        power = stats.norm.sf(critical - ncp) + stats.norm.cdf(-critical - ncp)
    return float(min(1.0, max(0.0, power)))


def RunsForPower(d: float, power: float = 0.8, alpha: float = 0.05, most: int = 100_000) -> int:
    """The fewest runs per group (equal groups) for which the two-sample t test reaches ``power``.

    Args:
        d: The assumed standardised effect.
        power: Target power, in (alpha, 1).
        alpha: Significance level.
        most: Search limit.

    Returns:
        n >= 2; -1 when d is 0 or NaN or n would exceed ``most``.
    """
    _CheckAlpha(alpha)
    if not alpha < power < 1.0:
        raise ValueError(f"power must be in (alpha, 1), got {power}")
    if not math.isfinite(d) or d == 0.0:
        return -1
    if TwoSampleTPower(d, 2, 2, alpha) >= power:
        return 2
    low, high = 2, 4  # power(low) < target; double high until power(high) >= target.
    while TwoSampleTPower(d, high, high, alpha) < power:
        if high >= most:
            return -1
        low, high = high, min(2 * high, most)
    while high - low > 1:
        middle = (low + high) // 2
        if TwoSampleTPower(d, middle, middle, alpha) >= power:
            high = middle
        else:
            low = middle
    return high


def RankBiserial(a, b) -> float:
    """Rank-biserial correlation r = P(a > b) - P(a < b) over all pairs (ties count zero).

    Equals 2 U_a / (n_a n_b) - 1 with U_a the Mann-Whitney statistic of ``a``.

    Args:
        a: Values of the first group.
        b: Values of the second group.

    Returns:
        r in [-1, 1].
    """
    a, b = _Samples(a, b)
    return float(np.mean(np.sign(a[:, None] - b[None, :])))


def RankBiserialInterval(
    a, b, confidence: float = 0.95, resamples: int = BOOTSTRAP_RESAMPLES, seed: int = BOOTSTRAP_SEED
) -> tuple[float, float]:
    """Percentile bootstrap interval of the rank-biserial correlation (runs resampled with
    replacement within each group, a fixed seed: the same data give the same interval).

    Args:
        a: Values of the first group.
        b: Values of the second group.
        confidence: Coverage, in (0, 1).
        resamples: Bootstrap resamples.
        seed: Seed of the resampling.

    Returns:
        (lower, upper).
    """
    _CheckAlpha(1.0 - confidence)
    a, b = _Samples(a, b)
    rng = np.random.default_rng(seed)
    resampled_a = a[rng.integers(0, a.size, (resamples, a.size))]
    resampled_b = b[rng.integers(0, b.size, (resamples, b.size))]
    values = np.mean(np.sign(resampled_a[:, :, None] - resampled_b[:, None, :]), axis=(1, 2))
    tail = 100.0 * (1.0 - confidence) / 2.0
    lower, upper = np.percentile(values, [tail, 100.0 - tail])
    return float(lower), float(upper)


@dataclasses.dataclass
class Comparison:
    """Two groups of runs compared on one measure.

    Attributes:
        n_a, n_b: Runs per group.
        mean_a, mean_b, median_a, median_b, sd_a, sd_b: Summaries over runs (sd: sample).
        p_anova: Two-group one-way ANOVA (= Student t test), the paper's test.
        p_welch: Welch's t test.
        p_mann_whitney: Two-sided Mann-Whitney U test.
        cohens_d: (mean_a - mean_b) / pooled sd, with its confidence interval d_low, d_high.
        power: Power of the ANOVA at alpha for the observed |d| and these group sizes.
        runs_for_80_percent: Runs per group the ANOVA would need for 80 % power at the observed
            d (-1: not computable).
        rank_biserial: P(a > b) - P(a < b), with its bootstrap interval r_low, r_high.
    """

    n_a: int
    n_b: int
    mean_a: float
    mean_b: float
    median_a: float
    median_b: float
    sd_a: float
    sd_b: float
    p_anova: float
    p_welch: float
    p_mann_whitney: float
    cohens_d: float
    d_low: float
    d_high: float
    power: float
    runs_for_80_percent: int
    rank_biserial: float
    r_low: float
    r_high: float


def Compare(a, b, alpha: float = 0.05, confidence: float = 0.95) -> Comparison:
    """All the run-level statistics of two groups on one measure.

    Args:
        a: One value per run of the first group (>= 2 runs).
        b: One value per run of the second group (>= 2 runs).
        alpha: Significance level of the power computation.
        confidence: Coverage of the intervals.

    Returns:
        The comparison; a statistic that cannot be computed (constant groups) is NaN.
    """
    a, b = _Samples(a, b)
    d = CohensD(a, b)
    d_low, d_high = CohensDInterval(d, a.size, b.size, confidence)
    r_low, r_high = RankBiserialInterval(a, b, confidence)
    constant = a.var() == 0.0 and b.var() == 0.0
    return Comparison(
        n_a=int(a.size),
        n_b=int(b.size),
        mean_a=float(a.mean()),
        mean_b=float(b.mean()),
        median_a=float(np.median(a)),
        median_b=float(np.median(b)),
        sd_a=float(a.std(ddof=1)),
        sd_b=float(b.std(ddof=1)),
        p_anova=math.nan if constant else float(stats.f_oneway(a, b).pvalue),
        p_welch=math.nan if constant else float(stats.ttest_ind(a, b, equal_var=False).pvalue),
        p_mann_whitney=float(stats.mannwhitneyu(a, b, alternative="two-sided").pvalue),
        cohens_d=d,
        d_low=d_low,
        d_high=d_high,
        power=TwoSampleTPower(abs(d), a.size, b.size, alpha),
        runs_for_80_percent=RunsForPower(abs(d), 0.8, alpha),
        rank_biserial=RankBiserial(a, b),
        r_low=r_low,
        r_high=r_high,
    )
