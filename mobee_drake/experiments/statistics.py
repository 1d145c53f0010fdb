"""Run-level statistics for the experiments' reports (issue 23, point 8): the one module with which
every battery compares learners over their runs (the reach learner of ch. 8, SAGG-RIAC's methods).

Every sample is one value per independent run (one seed). The evaluations or test goals of one
run share one learner, so they are not independent; a run's values are averaged first
(:func:`RunMeans`), never pooled. With the same number of evaluations in every run this is also
what a random-intercept model (the run a random effect) tests for a between-group effect: in a
balanced design its F-test of the fixed effect equals the pooled-variance t-test on the run means
(unless the run variance's estimate is truncated at zero).

:func:`CompareRuns` gives, for group a against group b:

- the tests: Student's t (= the two-group one-way ANOVA, SAGG-RIAC's test), Welch's t (no equal
  variances assumed) and Mann-Whitney's U (exact when small and without ties);
- the effect sizes: Cohen's d with the pooled standard deviation and its exact interval (by
  inverting the noncentral t), Hedges' g (d corrected by ``1 - 3 / (4 (n_a + n_b) - 9)``), the
  probability of superiority ``U / (n_a n_b)`` and the rank-biserial correlation ``2 U / (n_a
  n_b) - 1`` with a bootstrap interval;
- the power of the t-test at the observed effect and the runs it would need for 80 %.

A claim about a change over a run (ch. 8's "improves steadily") takes one value per run too:
:func:`Trend`, the run's change per doubling, tested against 0 by :func:`CompareToZero` and
between groups by :func:`CompareRuns`.

Signs follow the first group: a positive d means a tends to be larger (for an error: worse).
"""

import dataclasses as dc
import math

import numpy as np
from scipy import optimize, stats

# Resamples of the rank-biserial correlation's bootstrap interval, and its seed.
BOOTSTRAP_RESAMPLES = 10_000
BOOTSTRAP_SEED = 0


@dc.dataclass
class Comparison:
    """Group a against group b on one value per run (the fields of :func:`CompareRuns`)."""

    n_a: int
    n_b: int
    mean_a: float
    mean_b: float
    median_a: float
    median_b: float
    # Sample standard deviations (ddof 1).
    sd_a: float
    sd_b: float
    # mean_a - mean_b.
    difference: float
    # Cohen's d (pooled standard deviation) with its interval, and its small-sample correction.
    cohens_d: float
    d_low: float
    d_high: float
    hedges_g: float
    # Student's t-test, the same p as the two-group one-way ANOVA.
    anova_p: float
    welch_t: float
    welch_df: float
    welch_p: float
    mann_whitney_u: float
    mann_whitney_p: float
    # P(a run of a beats a run of b) + P(tie) / 2 = U / (n_a n_b).
    superiority: float
    # P(a > b) - P(a < b) = 2 superiority - 1, with its bootstrap interval.
    rank_biserial: float
    r_low: float
    r_high: float
    # Power of the t-test at |d| and these group sizes; runs per group for 80 % (-1: none).
    power: float
    runs_for_80_percent: int

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


def _CheckAlpha(alpha: float) -> None:
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"alpha must be in (0, 1), got {alpha}")


def _CheckRuns(n_a: int, n_b: int) -> None:
    if n_a < 2 or n_b < 2:
        raise ValueError(f"compare at least 2 runs per side, got {n_a} and {n_b}")


def _Samples(a, b) -> tuple[np.ndarray, np.ndarray]:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    if a.ndim != 1 or b.ndim != 1:
        raise ValueError(f"compare one value per run; got shapes {a.shape} and {b.shape}")
    _CheckRuns(a.size, b.size)
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError("run values must be finite")
    return a, b


def CohensD(a, b) -> float:
    """(mean(a) - mean(b)) / pooled standard deviation; 0 for identical constant groups and
    +-inf for constant groups apart (separated without any overlap)."""
    a, b = _Samples(a, b)
    difference = float(a.mean() - b.mean())
    pooled = math.sqrt(
        ((a.size - 1) * a.var(ddof=1) + (b.size - 1) * b.var(ddof=1)) / (a.size + b.size - 2)
    )
    if pooled > 0:
        return difference / pooled
    return 0.0 if difference == 0 else math.copysign(math.inf, difference)


def _Scale(n_a: int, n_b: int) -> float:
    """The noncentrality of a two-sample t statistic per unit of d: sqrt(n_a n_b / (n_a + n_b))."""
    return math.sqrt(n_a * n_b / (n_a + n_b))


def CohensDInterval(d: float, n_a: int, n_b: int, confidence: float = 0.95) -> tuple[float, float]:
    """Confidence interval of Cohen's d by inverting the noncentral t distribution.

    The two-sample t statistic is t = d sqrt(n_a n_b / (n_a + n_b)) with df = n_a + n_b - 2; the
    bounds are the noncentrality parameters under which the observed t sits at the upper and
    lower (1 - confidence) / 2 quantiles, scaled back to d (exact under normality and equal
    variances). NaNs when d is not finite.
    """
    _CheckAlpha(1.0 - confidence)
    _CheckRuns(n_a, n_b)
    if not math.isfinite(d):
        return math.nan, math.nan
    df, scale = n_a + n_b - 2, _Scale(n_a, n_b)
    t = d * scale
    tail = (1.0 - confidence) / 2.0

    def Bound(quantile: float) -> float:
        def Gap(ncp: float) -> float:
            cdf = stats.nct.cdf(t, df, ncp)
            if math.isnan(cdf):  # (SciPy's far tails, e.g. t = -40.8, df = 2, ncp = 23: ~0)
                cdf = 0.0 if ncp > t else 1.0
            return cdf - quantile

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
    """Power of the two-sided two-sample Student t-test: P(|T| > t_crit) with T noncentral t,
    df = n_a + n_b - 2, noncentrality d sqrt(n_a n_b / (n_a + n_b)); NaN when d is not finite."""
    _CheckAlpha(alpha)
    _CheckRuns(n_a, n_b)
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
    """The fewest runs per group (equal groups) with which the t-test reaches ``power`` at the
    effect d; -1 when d is 0 or not finite, or more than ``most`` runs would be needed."""
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


def _Superiority(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """P(a > b) + P(a = b) / 2 over all pairs of runs, along the last axis (resamples first)."""
    signs = np.sign(a[..., :, None] - b[..., None, :])
    return (np.mean(signs, axis=(-2, -1)) + 1.0) / 2.0


def RankBiserialInterval(
    a, b, confidence: float = 0.95, resamples: int = BOOTSTRAP_RESAMPLES, seed: int = BOOTSTRAP_SEED
) -> tuple[float, float]:
    """Percentile bootstrap interval of the rank-biserial correlation: runs resampled with
    replacement within each group, with a fixed seed (the same data give the same interval)."""
    _CheckAlpha(1.0 - confidence)
    a, b = _Samples(a, b)
    rng = np.random.default_rng(seed)
    resampled_a = a[rng.integers(0, a.size, (resamples, a.size))]
    resampled_b = b[rng.integers(0, b.size, (resamples, b.size))]
    values = 2.0 * _Superiority(resampled_a, resampled_b) - 1.0
    tail = 100.0 * (1.0 - confidence) / 2.0
    lower, upper = np.percentile(values, [tail, 100.0 - tail])
    return float(lower), float(upper)


def CompareRuns(a, b, alpha: float = 0.05, confidence: float = 0.95) -> Comparison:
    """Every run-level statistic of group a against group b (see the module's docstring).

    Args:
        a: One finite value per run of the first group (at least 2 runs).
        b: One finite value per run of the second group (at least 2 runs).
        alpha: Significance level of the power.
        confidence: Coverage of the intervals.

    Returns:
        The comparison; the t-tests are NaN when both groups are constant, and Mann-Whitney's p is
        1 when all runs are equal.
    """
    a, b = _Samples(a, b)
    n_a, n_b = a.size, b.size
    d = CohensD(a, b)
    d_low, d_high = CohensDInterval(d, n_a, n_b, confidence)
    va, vb = a.var(ddof=1) / n_a, b.var(ddof=1) / n_b
    if va + vb > 0:
        welch = stats.ttest_ind(a, b, equal_var=False)
        t, welch_p = float(welch.statistic), float(welch.pvalue)
        df = (va + vb) ** 2 / (va**2 / (n_a - 1) + vb**2 / (n_b - 1))
        anova_p = float(stats.ttest_ind(a, b).pvalue)
    else:
        t, welch_p, df, anova_p = math.nan, math.nan, math.nan, math.nan
    if np.all(a == a[0]) and np.all(b == a[0]):  # Mann-Whitney says nothing about equal groups.
        u, mann_whitney_p = n_a * n_b / 2, 1.0
    else:
        test = stats.mannwhitneyu(a, b, alternative="two-sided")
        u, mann_whitney_p = float(test.statistic), float(test.pvalue)
    r_low, r_high = RankBiserialInterval(a, b, confidence)
    return Comparison(
        n_a=int(n_a),
        n_b=int(n_b),
        mean_a=float(a.mean()),
        mean_b=float(b.mean()),
        median_a=float(np.median(a)),
        median_b=float(np.median(b)),
        sd_a=float(a.std(ddof=1)),
        sd_b=float(b.std(ddof=1)),
        difference=float(a.mean() - b.mean()),
        cohens_d=d,
        d_low=d_low,
        d_high=d_high,
        hedges_g=d * (1 - 3 / (4 * (n_a + n_b) - 9)),
        anova_p=anova_p,
        welch_t=t,
        welch_df=df,
        welch_p=welch_p,
        mann_whitney_u=u,
        mann_whitney_p=mann_whitney_p,
        superiority=u / (n_a * n_b),
        rank_biserial=2 * u / (n_a * n_b) - 1,
        r_low=r_low,
        r_high=r_high,
        power=TwoSampleTPower(abs(d), n_a, n_b, alpha),
        runs_for_80_percent=RunsForPower(abs(d), 0.8, alpha),
    )


@dc.dataclass
class ZeroComparison:
    """One value per run (a run's trend, say) tested against 0."""

    n: int
    mean: float
    sd: float
    # Runs above 0.
    positive: int
    # Student's one-sample t-test and Wilcoxon's signed-rank test, two-sided.
    t_p: float
    wilcoxon_p: float

    def Text(self) -> str:
        return (
            f"{self.mean:+.3f} ± {self.sd:.3f} ({self.positive} of {self.n} runs above 0; "
            f"t-test p = {_Number(self.t_p, '.2g')}, "
            f"Wilcoxon p = {_Number(self.wilcoxon_p, '.2g')})"
        )


def CompareToZero(values) -> ZeroComparison:
    """Whether runs' values differ from 0 (at least 2 finite values): NaN p-values when they
    are all equal."""
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or values.size < 2 or not np.all(np.isfinite(values)):
        raise ValueError(f"test at least 2 finite run values, got {values}")
    constant = np.all(values == values[0])
    return ZeroComparison(
        n=int(values.size),
        mean=float(values.mean()),
        sd=float(values.std(ddof=1)),
        positive=int(np.sum(values > 0)),
        t_p=math.nan if constant else float(stats.ttest_1samp(values, 0.0).pvalue),
        wilcoxon_p=math.nan if np.all(values == 0) else float(stats.wilcoxon(values).pvalue),
    )


def Trend(stages, values) -> float:
    """A run's trend: the least-squares slope of its values at ``stages`` (problem-tries, say)
    over log2 of the stages, that is the change per doubling."""
    stages, values = np.asarray(stages, dtype=float), np.asarray(values, dtype=float)
    if stages.shape != values.shape or stages.size < 2 or np.any(stages <= 0):
        raise ValueError(
            f"a trend needs 2 or more positive stages and one value each, got {stages}"
        )
    return float(np.polyfit(np.log2(stages), values, 1)[0])


def FiniteMean(values) -> float:
    """The mean of the finite ``values`` (NaN marks a run without the measure), NaN if none is."""
    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite)]
    return float(finite.mean()) if finite.size else float("nan")


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


def Holm(p_values) -> np.ndarray:
    """Holm's step-down adjustment of a family's p-values (in their order; NaN stays NaN and is
    not counted): the k-th smallest of m becomes max over j <= k of min(1, (m - j + 1) p_(j))."""
    p = np.asarray(p_values, dtype=float)
    adjusted = np.full(p.shape, math.nan)
    finite = np.flatnonzero(np.isfinite(p))
    order = finite[np.argsort(p[finite], kind="stable")]
    m, running = len(order), 0.0
    for rank, index in enumerate(order):
        running = max(running, min(1.0, (m - rank) * p[index]))
        adjusted[index] = running
    return adjusted


@dc.dataclass
class PairedComparison:
    """Group a against group b on matched runs (the same seed: in ch. 8's battery the same MDP
    and evaluation seeds; where the groups learn on different spaces, the same seeds alone), the
    MDP a block (the fields of :func:`ComparePaired`). The interval is the difference's own
    95 % interval, not adjusted for other comparisons (the p-value its text is given may be:
    :func:`PairedBySeed` gives Holm's)."""

    n: int
    blocks: int
    # The mean of the paired differences a - b, its 95 % interval and their standard deviation.
    difference: float
    low: float
    high: float
    sd: float
    # Cohen's d_z: the mean difference over the differences' standard deviation.
    d_z: float
    # The test of the mean difference with the block as a fixed factor (a randomised block
    # design: the error is the differences' variance within the blocks, n - blocks degrees of
    # freedom, so its inference holds for these MDPs; with one block, the paired t-test), and
    # Wilcoxon's signed-rank test, two-sided.
    t_p: float
    wilcoxon_p: float
    # Pairs in which a is larger.
    a_larger: int
    # Whether the difference depends on the block (the MDP): one-way ANOVA of the differences
    # over the blocks (NaN with one block, or a block of one pair).
    block_p: float
    # The block as a random factor (inference for MDPs learned anew; not Holm-adjusted): the
    # blocks' mean differences against 0, blocks - 1 degrees of freedom, their standard error
    # never below the within-block one (NaN with fewer than 3 blocks).
    over_blocks_p: float = math.nan

    def Text(self, p: float | None = None) -> str:
        """One line: the difference with its interval, d_z, the test's p (or ``p``, an adjusted
        one), the pairs in a's favour and, with several blocks, whether the difference depends
        on them."""
        shown = self.t_p if p is None else p
        blocks = (
            f"; over {self.blocks} MDPs, the MDP's effect p = {_Number(self.block_p, '.2g')}"
            f", for MDPs learned anew p = {_Number(self.over_blocks_p, '.2g')} (unadjusted)"
            if self.blocks > 1
            else ""
        )
        return (
            f"{self.difference:+.2f} [{self.low:+.2f}, {self.high:+.2f}] (d_z = "
            f"{_Number(self.d_z)}, p = {_Number(shown, '.2g')}; {self.a_larger} of {self.n} "
            f"pairs{blocks})"
        )


def ComparePaired(a, b, blocks) -> PairedComparison:
    """Paired comparison of run values ``a`` and ``b`` (run i of a matched with run i of b) in
    ``blocks`` (one label per pair: its MDP). The mean difference is tested against the
    differences' variance within the blocks (the MDP a fixed factor: how much a strategy's lead
    varies from one MDP to another is not taken for noise, so the test speaks for these MDPs);
    with one block this is the paired t-test. ``over_blocks_p`` speaks for MDPs learned anew
    (the MDP a random factor: the blocks' mean differences, one value each)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    blocks = np.asarray(blocks)
    if a.shape != b.shape or a.ndim != 1 or blocks.shape != a.shape:
        raise ValueError(f"pair runs one to one, one block each; got {a.size}, {b.size}")
    d = a - b
    labels = list(dict.fromkeys(blocks.tolist()))
    groups = [d[blocks == label] for label in labels]
    n, j = d.size, len(groups)
    if n - j < 1:
        raise ValueError(f"a paired test needs more pairs than blocks, got {n} in {j}")
    mean, sd = float(d.mean()), float(d.std(ddof=1))
    within = math.sqrt(sum(np.sum((g - g.mean()) ** 2) for g in groups) / (n - j))
    se = within / math.sqrt(n)
    half = stats.t.ppf(0.975, n - j) * se
    varied = j > 1 and all(g.size > 1 for g in groups) and within > 0
    return PairedComparison(
        n=n,
        blocks=j,
        difference=mean,
        low=mean - half,
        high=mean + half,
        sd=sd,
        d_z=mean / sd if sd > 0 else math.nan,
        t_p=float(2 * stats.t.sf(abs(mean) / se, n - j)) if se > 0 else math.nan,
        wilcoxon_p=float(stats.wilcoxon(d).pvalue) if np.any(d != 0) else math.nan,
        a_larger=int(np.sum(d > 0)),
        block_p=float(stats.f_oneway(*groups).pvalue) if varied else math.nan,
        over_blocks_p=_OverBlocks(groups, within),
    )


def _OverBlocks(groups: list[np.ndarray], within: float) -> float:
    """The p of the mean difference for blocks drawn anew (the block a random factor): the
    blocks' means tested against 0 with blocks - 1 degrees of freedom, their standard error
    never below the within-block one (three means that happen to agree are no evidence);
    NaN below 3 blocks."""
    means = np.array([g.mean() for g in groups])
    n, j = sum(g.size for g in groups), len(groups)
    if j < 3:
        return math.nan
    se = math.sqrt(max(means.var(ddof=1) / j, within**2 / n))
    return float(2 * stats.t.sf(abs(means.mean()) / se, j - 1)) if se > 0 else math.nan


def _Compared(a: np.ndarray, b: np.ndarray) -> PairedComparison:
    """:func:`ComparePaired` in one block, but a difference the same in every pair (also but
    for rounding) has no spread: no d_z, no t-test (Wilcoxon's test stands), not a t of 1e15."""
    c = ComparePaired(a, b, np.zeros(a.size))
    d = a - b
    if np.ptp(d) > 1e-9 * max(1.0, float(np.abs(d).max())):
        return c
    return dc.replace(c, sd=0.0, d_z=math.nan, t_p=math.nan, low=c.difference, high=c.difference)


def PairedBySeed(families: dict, measures: dict, heading: str) -> list[str]:
    """Report lines: for each of ``families`` (a name: the runs with a treatment and the runs
    without, each run with a ``seed``), treatment minus control on each of ``measures`` (a name:
    run -> value), paired by seed (:func:`ComparePaired`, one block), Holm over the comparisons
    tested. "k of n pairs" counts the pairs in which the treatment's value is the larger ("t
    tied" follows if any are). A pair without a finite value is left out of its comparison (the
    line says how many). A comparison equal in every pair is not tested (the lines end by
    naming it); one whose every pair differs by the same amount has no spread for the t-test,
    and Wilcoxon's p stands in. A measure whose values are an earlier measure's in every run
    of the family's pairs is the same comparison again: not tested a second time (nor counted by
    Holm), and named. A family with fewer than two seeds on both sides, or a comparison with
    fewer than two pairs with values, is named as not compared; no lines when there were no
    families."""
    compared, notes, equal, repeated = {}, {}, [], []
    not_compared = {
        "fewer than two seeds on both sides": [],
        "fewer than two pairs with values": [],
    }
    for family, (treated, control) in families.items():
        seeds = sorted({r.seed for r in treated} & {r.seed for r in control})
        if len(seeds) < 2:
            not_compared["fewer than two seeds on both sides"].append(family)
            continue
        treated, control = (sorted((r for r in rs if r.seed in seeds), key=lambda r: r.seed)
                            for rs in (treated, control))  # fmt: skip
        earlier = {}
        for name, f in measures.items():
            a = np.array([f(r) for r in treated], dtype=float)
            b = np.array([f(r) for r in control], dtype=float)
            kept = np.isfinite(a) & np.isfinite(b)
            label = f"{family}, {name}" if family else name
            same = [m for m, (a0, b0) in earlier.items()
                    if np.array_equal(a, a0, equal_nan=True)
                    and np.array_equal(b, b0, equal_nan=True)]  # fmt: skip
            earlier[name] = (a, b)
            if same:
                repeated.append(f"{label} (as {same[0]})")
                continue
            tied = int(np.sum(a[kept] == b[kept]))  # (as ComparePaired's a_larger: d > 0)
            if np.sum(kept) < 2:
                not_compared["fewer than two pairs with values"].append(label)
            elif np.allclose(a[kept], b[kept], rtol=1e-9, atol=0.0):
                equal.append(label)
            else:
                compared[label] = c = _Compared(a[kept], b[kept])
                notes[label] = (
                    ("; Wilcoxon's p: every pair differs by the same" if c.sd == 0 else "")
                    + (f"; {tied} tied" if tied else "")
                    + (
                        f"; {np.sum(~kept)} pairs without a value left out"
                        if not kept.all()
                        else ""
                    )
                )
    adjusted = Holm([c.t_p if c.sd > 0 else c.wilcoxon_p for c in compared.values()])
    lines = []
    if compared:
        lines += ["", f"{heading}, paired by seed (Holm over the {len(compared)}):", ""]
        lines += [f"- {label}: {c.Text(p)}{notes[label]}"
                  for (label, c), p in zip(compared.items(), adjusted)]  # fmt: skip
    if equal:
        lead = "Equal" if compared else f"{heading}, paired by seed: equal"
        lines += ["", f"{lead} in every pair, not tested: {'; '.join(equal)}."]
    if repeated:
        lead = "The same" if compared or equal else f"{heading}: the same"
        lines += ["", f"{lead} as an earlier measure in every run, not tested again: "
                  f"{'; '.join(repeated)}."]  # fmt: skip
    for reason, labels in not_compared.items():
        if labels:
            lead = "Not compared" if compared or equal or repeated else f"{heading}: not compared"
            named = "; ".join(label for label in labels if label)
            lines += ["", f"{lead} ({reason})" + (f": {named}." if named else ".")]
    return lines


def RatioOfMeans(a, b, blocks, resamples: int = BOOTSTRAP_RESAMPLES) -> tuple[float, float, float]:
    """mean(a) / mean(b) of matched runs, with a 95 % percentile bootstrap interval of two
    stages: the blocks (MDPs) resampled, then the pairs within each block drawn (seeded:
    BOOTSTRAP_SEED); with one block, the pairs alone."""
    a, b, blocks = np.asarray(a, dtype=float), np.asarray(b, dtype=float), np.asarray(blocks)
    if a.shape != b.shape or blocks.shape != a.shape or a.size < 2:
        raise ValueError(f"a ratio needs at least 2 matched runs, one block each; got {a.size}")
    rng = np.random.default_rng(BOOTSTRAP_SEED)
    members = [np.flatnonzero(blocks == label) for label in dict.fromkeys(blocks.tolist())]
    j = len(members)
    # Per resample, the blocks in its j slots, then in each slot the block's pairs drawn.
    chosen = rng.integers(j, size=(resamples, j)) if j > 1 else np.zeros((resamples, 1), int)
    sum_a, sum_b = np.zeros(resamples), np.zeros(resamples)
    for slot in range(j):
        for block, pairs in enumerate(members):
            rows = np.flatnonzero(chosen[:, slot] == block)
            picks = pairs[rng.integers(pairs.size, size=(rows.size, pairs.size))]
            sum_a[rows] += a[picks].sum(axis=1)
            sum_b[rows] += b[picks].sum(axis=1)
    low, high = np.percentile(sum_a / sum_b, [2.5, 97.5])
    return float(a.mean() / b.mean()), float(low), float(high)
