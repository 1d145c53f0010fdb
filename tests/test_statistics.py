"""Run-level statistics of the experiments' reports (issue 23, point 8) against closed forms,
textbook values, scipy and simulation."""

import collections
import dataclasses as dc
import math
import unittest

import numpy as np
from scipy import stats

from mobee_drake.experiments.statistics import (
    CohensD,
    CohensDInterval,
    ComparePaired,
    CompareRuns,
    CompareToZero,
    Holm,
    PairedBySeed,
    RankBiserialInterval,
    RatioOfMeans,
    RunMeans,
    RunsForPower,
    Trend,
    TwoSampleTPower,
)


def RankBiserial(a, b) -> float:
    """P(a > b) - P(a < b) over all pairs, by brute force (the definition)."""
    return float(np.mean([np.sign(x - y) for x in a for y in b]))


class TestCompareRuns(unittest.TestCase):
    def test_two_runs_a_side_closed_form(self):
        # Equal variances s^2 = 2 and n = 2: Welch's df is 2, t = -2 / sqrt(2 / 2 + 2 / 2), and
        # Student's t with 2 degrees of freedom has the two-sided p = 1 - |t| / sqrt(2 + t^2).
        c = CompareRuns([0.0, 2.0], [2.0, 4.0])
        t = -2 / math.sqrt(2.0)
        self.assertAlmostEqual(c.difference, -2.0)
        self.assertAlmostEqual(c.welch_t, t)
        self.assertAlmostEqual(c.welch_df, 2.0)
        self.assertAlmostEqual(c.welch_p, 1 - abs(t) / math.sqrt(2 + t**2))
        # d = -2 / sqrt(2); g corrects by 1 - 3 / (4 * 4 - 9).
        self.assertAlmostEqual(c.cohens_d, -2 / math.sqrt(2))
        self.assertAlmostEqual(c.hedges_g, c.cohens_d * (1 - 3 / 7))
        # The pairs (0, 2), (0, 4), (2, 2), (2, 4): a wins none, ties one: U = 0.5.
        self.assertAlmostEqual(c.mann_whitney_u, 0.5)
        self.assertAlmostEqual(c.superiority, 0.5 / 4)

    def test_complete_separation_exact_mann_whitney(self):
        # Five runs a side, every a above every b: U = 25 and the exact two-sided p is 2 / C(10, 5).
        a, b = [6.0, 7.0, 8.0, 9.0, 10.0], [1.0, 2.0, 3.0, 4.0, 5.0]
        c = CompareRuns(a, b)
        self.assertEqual(c.mann_whitney_u, 25.0)
        self.assertAlmostEqual(c.mann_whitney_p, 2 / math.comb(10, 5))
        self.assertEqual(c.superiority, 1.0)
        # Variances 2.5 each: d = 5 / sqrt(2.5), t = 5 / sqrt(2.5 / 5 + 2.5 / 5) = 5, df = 8.
        self.assertAlmostEqual(c.cohens_d, 5 / math.sqrt(2.5))
        self.assertAlmostEqual(c.hedges_g, c.cohens_d * (1 - 3 / 31))
        self.assertAlmostEqual(c.welch_t, 5.0)
        self.assertAlmostEqual(c.welch_df, 8.0)

    def test_welch_df_with_unequal_variances(self):
        a, b = [0.0, 1.0, 2.0], [0.0, 10.0]
        va, vb = 1.0 / 3, 50.0 / 2  # s^2 / n
        c = CompareRuns(a, b)
        self.assertAlmostEqual(c.welch_df, (va + vb) ** 2 / (va**2 / 2 + vb**2 / 1))

    def test_run_means_not_pooled_evaluations(self):
        # Two runs per strategy, five identical evaluations each: pooled, the evaluations would
        # look like 10 independent values; at run level it is two against two.
        a = [[1.0] * 5, [3.0] * 5]
        b = [[2.0] * 5, [4.0] * 5]
        means_a, means_b = RunMeans(a), RunMeans(b)
        np.testing.assert_array_equal(means_a, [1.0, 3.0])
        c = CompareRuns(means_a, means_b)
        t = -1 / math.sqrt(2 / 2 + 2 / 2)
        self.assertAlmostEqual(c.welch_p, 1 - abs(t) / math.sqrt(2 + t**2))
        self.assertEqual((c.n_a, c.n_b), (2, 2))

    def test_degenerate_groups(self):
        same = CompareRuns([1.0, 1.0], [1.0, 1.0])
        self.assertEqual((same.difference, same.cohens_d, same.mann_whitney_p), (0.0, 0.0, 1.0))
        self.assertTrue(math.isnan(same.welch_p))
        apart = CompareRuns([2.0, 2.0], [1.0, 1.0])
        self.assertEqual(apart.cohens_d, math.inf)
        self.assertEqual(apart.superiority, 1.0)
        self.assertIn("Welch p = n/a", apart.Text())

    def test_bad_input(self):
        with self.assertRaisesRegex(ValueError, "at least 2 runs per side"):
            CompareRuns([1.0], [1.0, 2.0])
        with self.assertRaisesRegex(ValueError, "must be finite"):
            CompareRuns([1.0, np.nan], [1.0, 2.0])
        with self.assertRaisesRegex(ValueError, "run 1 has no values"):
            RunMeans([[1.0], []])


class TestEffectSizes(unittest.TestCase):
    def test_cohens_d_by_hand(self):
        # Means 2 and 3, both variances 1: d = -1; the sign follows the first group.
        self.assertAlmostEqual(CohensD([1, 2, 3], [2, 3, 4]), -1.0)
        self.assertAlmostEqual(CohensD([2, 3, 4], [1, 2, 3]), 1.0)
        # Unequal sizes: pooled variance ((3 - 1) 1 + (2 - 1) 0.5) / 3 = 2.5 / 3.
        self.assertAlmostEqual(CohensD([1, 2, 3], [5, 6]), (2 - 5.5) / math.sqrt(2.5 / 3))
        self.assertEqual(CohensD([1, 1], [1, 1]), 0.0)
        self.assertEqual(CohensD([1, 1], [0, 0]), math.inf)

    def test_rank_biserial_against_mann_whitney(self):
        rng = np.random.default_rng(3)
        a, b = rng.normal(0, 1, 17), rng.normal(0.5, 1, 23)
        u = stats.mannwhitneyu(a, b).statistic
        self.assertAlmostEqual(CompareRuns(a, b).rank_biserial, 2 * u / (17 * 23) - 1)
        self.assertAlmostEqual(CompareRuns(a, b).rank_biserial, RankBiserial(a, b))
        self.assertEqual(CompareRuns([5, 6, 7], [1, 2]).rank_biserial, 1.0)
        self.assertEqual(CompareRuns([1, 2], [1, 2]).rank_biserial, 0.0)  # ties count zero

    def test_rank_biserial_interval_holds_the_estimate_and_repeats(self):
        rng = np.random.default_rng(4)
        a, b = rng.normal(0, 1, 30), rng.normal(0.8, 1, 30)
        low, high = RankBiserialInterval(a, b)
        self.assertLess(low, RankBiserial(a, b))
        self.assertLess(RankBiserial(a, b), high)
        self.assertTrue(-1 <= low < high <= 1)
        self.assertEqual((low, high), RankBiserialInterval(a, b))
        self.assertEqual(RankBiserialInterval([5, 6, 7], [1, 2]), (1.0, 1.0))

    def test_d_interval_inverts_the_noncentral_t(self):
        d, n_a, n_b = 0.5, 30, 30
        low, high = CohensDInterval(d, n_a, n_b)
        scale = math.sqrt(n_a * n_b / (n_a + n_b))
        t, df = d * scale, n_a + n_b - 2
        self.assertAlmostEqual(stats.nct.cdf(t, df, low * scale), 0.975, places=6)
        self.assertAlmostEqual(stats.nct.cdf(t, df, high * scale), 0.025, places=6)
        # Close to the large-sample interval d ± 1.96 sqrt(1/n_a + 1/n_b + d^2 / (2 (n_a + n_b))).
        half = 1.96 * math.sqrt(1 / n_a + 1 / n_b + d**2 / (2 * (n_a + n_b)))
        self.assertAlmostEqual(low, d - half, delta=0.03)
        self.assertAlmostEqual(high, d + half, delta=0.03)
        # Symmetric in the sign of d, and defined far out.
        mirrored = CohensDInterval(-d, n_a, n_b)
        self.assertAlmostEqual(mirrored[0], -high)
        self.assertAlmostEqual(mirrored[1], -low)
        low, high = CohensDInterval(6.0, 30, 30)
        self.assertTrue(4.0 < low < 6.0 < high < 8.0)

    def test_d_interval_of_a_huge_effect_in_few_runs(self):
        """SciPy's noncentral t gives NaN far in its tails (t = -40.8, df = 2, ncp = 23); the
        bracket widens through them and the bounds still invert the distribution."""
        d = -40.84691578627283  # (the decisive battery's first report, 2 runs a side)
        low, high = CohensDInterval(d, 2, 2)
        self.assertLess(low, d)
        self.assertLess(d, high)
        self.assertAlmostEqual(stats.nct.cdf(d, 2, low), 0.975, places=6)  # (scale 1 at 2, 2)
        self.assertAlmostEqual(stats.nct.cdf(d, 2, high), 0.025, places=6)

    def test_d_interval_covers_the_true_effect(self):
        rng = np.random.default_rng(5)
        covered = 0
        for _ in range(300):
            a, b = rng.normal(0.7, 1, 15), rng.normal(0, 1, 15)
            low, high = CohensDInterval(CohensD(a, b), 15, 15)
            covered += low <= 0.7 <= high
        self.assertAlmostEqual(covered / 300, 0.95, delta=0.04)


class TestPower(unittest.TestCase):
    def test_textbook_values(self):
        # Cohen (1988): 64 runs per group give 80 % power at d = 0.5, 26 at d = 0.8.
        self.assertAlmostEqual(TwoSampleTPower(0.5, 64, 64), 0.80, delta=0.005)
        self.assertAlmostEqual(TwoSampleTPower(0.8, 26, 26), 0.81, delta=0.005)
        self.assertEqual(RunsForPower(0.5), 64)
        self.assertEqual(RunsForPower(0.8), 26)
        self.assertIn(RunsForPower(0.2), (393, 394))
        # No effect: the power is the level.
        self.assertAlmostEqual(TwoSampleTPower(0.0, 15, 15), 0.05, places=9)
        self.assertEqual(RunsForPower(0.0), -1)
        # Far in the tails, where scipy's noncentral t gives up: the normal limit.
        self.assertEqual(TwoSampleTPower(0.5, 5000, 5000), 1.0)

    def test_the_issues_example_by_simulation(self):
        # d = 0.7 at 15 runs per group: about 45 % power (issue 23); simulated t tests agree.
        power = TwoSampleTPower(0.7, 15, 15)
        self.assertAlmostEqual(power, 0.45, delta=0.02)
        rng = np.random.default_rng(6)
        a, b = rng.normal(0.7, 1, (4000, 15)), rng.normal(0, 1, (4000, 15))
        simulated = np.mean(stats.ttest_ind(a, b, axis=1).pvalue < 0.05)
        self.assertAlmostEqual(simulated, power, delta=0.025)

    def test_runs_for_power_is_the_smallest(self):
        for d in (0.3, 0.7, 1.5):
            n = RunsForPower(d, 0.9, 0.01)
            self.assertGreaterEqual(TwoSampleTPower(d, n, n, 0.01), 0.9)
            self.assertLess(TwoSampleTPower(d, n - 1, n - 1, 0.01), 0.9)

    def test_bad_input_is_refused(self):
        with self.assertRaisesRegex(ValueError, "at least 2 runs"):
            CohensD([1.0], [1.0, 2.0])
        with self.assertRaisesRegex(ValueError, "alpha"):
            TwoSampleTPower(0.5, 10, 10, alpha=1.5)
        with self.assertRaisesRegex(ValueError, "power"):
            RunsForPower(0.5, power=0.01)
        with self.assertRaisesRegex(ValueError, "finite"):
            CompareRuns([1.0, math.nan], [1.0, 2.0])


class TestCompareRunsAgainstScipy(unittest.TestCase):
    def test_fields_agree_with_scipy(self):
        rng = np.random.default_rng(7)
        a, b = rng.normal(1, 1, 30), rng.normal(0, 2, 25)
        result = CompareRuns(a, b)
        self.assertEqual((result.n_a, result.n_b), (30, 25))
        self.assertAlmostEqual(result.anova_p, stats.f_oneway(a, b).pvalue)
        self.assertAlmostEqual(result.anova_p, stats.ttest_ind(a, b).pvalue)
        self.assertAlmostEqual(result.welch_p, stats.ttest_ind(a, b, equal_var=False).pvalue)
        self.assertAlmostEqual(result.median_b, np.median(b))
        self.assertAlmostEqual(result.power, TwoSampleTPower(abs(result.cohens_d), 30, 25))
        self.assertLess(result.d_low, result.cohens_d)
        self.assertLess(result.cohens_d, result.d_high)

    def test_constant_groups_give_no_test_not_an_error(self):
        result = CompareRuns([1.0, 1.0], [1.0, 1.0])
        self.assertEqual((result.cohens_d, result.rank_biserial), (0.0, 0.0))
        self.assertTrue(math.isnan(result.anova_p))
        self.assertEqual(result.runs_for_80_percent, -1)
        apart = CompareRuns([2.0, 2.0], [1.0, 1.0])
        self.assertTrue(math.isnan(apart.d_low) and math.isnan(apart.power))
        self.assertEqual(apart.runs_for_80_percent, -1)

    def test_rank_biserial_is_twice_superiority_less_one(self):
        rng = np.random.default_rng(8)
        a, b = rng.integers(0, 4, 9).astype(float), rng.integers(0, 4, 7).astype(float)  # ties
        result = CompareRuns(a, b)
        self.assertAlmostEqual(result.rank_biserial, RankBiserial(a, b))
        self.assertAlmostEqual(result.rank_biserial, 2 * result.superiority - 1)


class TestTrends(unittest.TestCase):
    def test_trend_is_the_change_per_doubling(self):
        # Values 1, 2, 3 at 100, 200, 400: one more per doubling; a constant has none.
        self.assertAlmostEqual(Trend([100, 200, 400], [1.0, 2.0, 3.0]), 1.0)
        self.assertAlmostEqual(Trend([100, 200, 400, 800], [5.0] * 4), 0.0)
        # Least squares over log2: values 0, 0, 3 at 1, 2, 4 give (3 * 1) / 2 = 1.5.
        self.assertAlmostEqual(Trend([1, 2, 4], [0.0, 0.0, 3.0]), 1.5)
        with self.assertRaisesRegex(ValueError, "2 or more positive stages"):
            Trend([0, 100], [1.0, 2.0])

    def test_against_zero(self):
        # Values -1, 1, 3: mean 1, sd 2, t = 1 / (2 / sqrt(3)); two-sided p with 2 df is
        # 1 - |t| / sqrt(2 + t^2).
        result = CompareToZero([-1.0, 1.0, 3.0])
        t = 1 / (2 / math.sqrt(3))
        self.assertEqual((result.n, result.positive), (3, 2))
        self.assertAlmostEqual(result.mean, 1.0)
        self.assertAlmostEqual(result.sd, 2.0)
        self.assertAlmostEqual(result.t_p, 1 - t / math.sqrt(2 + t**2))
        # Five runs all above 0: the exact signed-rank p is 2 / 2^5.
        self.assertAlmostEqual(CompareToZero([1.0, 2.0, 3.0, 4.0, 5.0]).wilcoxon_p, 2 / 32)
        same = CompareToZero([0.0, 0.0])
        self.assertTrue(math.isnan(same.t_p) and math.isnan(same.wilcoxon_p))
        self.assertIn("0 of 2 runs above 0", same.Text())
        with self.assertRaisesRegex(ValueError, "at least 2 finite"):
            CompareToZero([1.0])


class TestPairedAndFamilies(unittest.TestCase):
    """Issue 33: paired comparisons on shared seeds, Holm's correction, ratios of means."""

    def test_holm_by_hand(self):
        # Sorted 0.01, 0.03, 0.04 of m = 3: 0.03, max(0.03, 0.06), max(0.06, 0.04).
        np.testing.assert_allclose(Holm([0.01, 0.04, 0.03]), [0.03, 0.06, 0.06])
        np.testing.assert_allclose(Holm([0.5, 0.9]), [1.0, 1.0])
        adjusted = Holm([0.02, math.nan, 0.01])
        self.assertTrue(math.isnan(adjusted[1]))
        np.testing.assert_allclose(adjusted[[0, 2]], [0.02, 0.02])  # m = 2: NaN not counted

    def test_paired_against_scipy_and_the_blocked_closed_form(self):
        rng = np.random.default_rng(4)
        b = rng.normal(0, 1, 12)
        a = b + 0.5 + rng.normal(0, 0.3, 12)
        d = a - b
        one = ComparePaired(a, b, np.zeros(12))  # one MDP: the paired t-test
        self.assertAlmostEqual(one.t_p, stats.ttest_rel(a, b).pvalue)
        self.assertAlmostEqual(one.wilcoxon_p, stats.wilcoxon(d).pvalue)
        self.assertAlmostEqual(one.d_z, d.mean() / d.std(ddof=1))
        half = stats.t.ppf(0.975, 11) * d.std(ddof=1) / math.sqrt(12)
        self.assertAlmostEqual(one.high - one.low, 2 * half)
        self.assertTrue(math.isnan(one.block_p))
        # Three MDPs: the error is the variance within them, 12 - 3 degrees of freedom.
        blocks = np.repeat([0, 1, 2], 4)
        c = ComparePaired(a, b, blocks)
        within = sum(np.sum((d[k : k + 4] - d[k : k + 4].mean()) ** 2) for k in (0, 4, 8)) / 9
        t = d.mean() / math.sqrt(within / 12)
        self.assertAlmostEqual(c.t_p, 2 * stats.t.sf(abs(t), 9))
        self.assertAlmostEqual(c.block_p, stats.f_oneway(d[:4], d[4:8], d[8:]).pvalue)
        # For MDPs learned anew: the MDPs' means against 0 on 2 df, their standard error the
        # larger of their spread's and the within-MDP one.
        means = np.array([d[k : k + 4].mean() for k in (0, 4, 8)])
        se = max(means.std(ddof=1) / math.sqrt(3), math.sqrt(within / 12))
        self.assertAlmostEqual(c.over_blocks_p, 2 * stats.t.sf(abs(means.mean()) / se, 2))
        self.assertIn(f"for MDPs learned anew p = {c.over_blocks_p:.2g} (unadjusted))", c.Text())
        self.assertTrue(math.isnan(one.over_blocks_p))
        # Three MDPs whose means agree by chance are no evidence beyond the within-MDP spread.
        agree = np.array([1, -3, 0.95, -2.9, 1.1, -3.1])
        close = ComparePaired(agree, np.zeros(6), np.repeat([0, 1, 2], 2))
        self.assertGreaterEqual(close.over_blocks_p, close.t_p)
        self.assertEqual(c.a_larger, int(np.sum(d > 0)))
        # An MDP's own shift of the difference (summing to 0) is not noise to the blocked test.
        shifted = a + np.repeat([-1.0, 0.0, 1.0], 4)
        self.assertAlmostEqual(ComparePaired(shifted, b, blocks).t_p, c.t_p)
        self.assertGreater(ComparePaired(shifted, b, np.zeros(12)).t_p, 10 * c.t_p)
        self.assertLess(c.t_p, stats.ttest_ind(a, b).pvalue)  # pairing removes the seeds' luck
        with self.assertRaisesRegex(ValueError, "more pairs than blocks"):
            ComparePaired(a[:3], b[:3], [0, 1, 2])

    def test_paired_by_seed_matches_seeds_and_corrects_over_every_comparison(self):
        Run = collections.namedtuple("Run", "seed value")
        rng = np.random.default_rng(2)
        control = rng.normal(0, 1, 6)
        treated = control + 1.0 + rng.normal(0, 0.2, 6)
        on = [Run(s, v) for s, v in enumerate(treated)]
        off = [Run(s, v) for s, v in enumerate(control)][::-1]  # (another order: paired by seed)
        off.append(Run(9, 100.0))  # No pair: left out.
        measures = {"value": lambda r: r.value, "double": lambda r: 2 * r.value}
        lines = PairedBySeed(
            {"arm": (on, off), "alone": (on[:1], off)}, measures, "On minus off"
        )  # ("alone" has one pair: left out, so the family is the two measures of "arm")
        self.assertEqual(lines[:3], ["", "On minus off, paired by seed (Holm over the 2):", ""])
        expected = ComparePaired(treated, control, np.zeros(6))
        p = Holm([expected.t_p] * 2)[0]
        self.assertEqual(lines[3], f"- arm, value: {expected.Text(p)}")
        self.assertTrue(lines[4].startswith(f"- arm, double: {2 * expected.difference:+.2f} "))
        self.assertEqual(
            lines[5:], ["", "Not compared (fewer than two seeds on both sides): alone."]
        )
        self.assertEqual(
            PairedBySeed({"": (on[:1], off)}, measures, "On minus off"),
            ["", "On minus off: not compared (fewer than two seeds on both sides)."],
        )
        self.assertEqual(PairedBySeed({}, measures, "On minus off"), [])

    def test_paired_by_seed_without_spread_or_values(self):
        """A comparison equal in every pair is not tested (nor counted by Holm); one differing
        by the same in every pair gets Wilcoxon's exact p; a pair without a value is left out
        of its comparison alone; ties are counted; a measure that repeats an earlier one in every
        run is the same comparison, not tested again."""
        Run = collections.namedtuple("Run", "seed value same shifted sparse")
        rng = np.random.default_rng(3)
        control = rng.normal(0, 1, 6)
        treated = control + 1.0 + rng.normal(0, 0.2, 6)
        treated[4] = np.nan
        treated[5] = control[5]  # a tie
        # (0.2 more in every pair but for rounding: 0.19999999999999996, 0.20000000000000007)
        shifted = [0.6, 0.8, 1.0, 1.2, 1.4, 1.6]
        on = [Run(s, v, 1.0, shifted[s], 1.0) for s, v in enumerate(treated)]
        off = [Run(s, v, 1.0, shifted[s] - 0.2, np.nan if s else 0.0)
               for s, v in enumerate(control)]  # fmt: skip
        names = ("value", "same", "shifted", "sparse")
        measures = {m: lambda r, m=m: getattr(r, m) for m in names}
        measures["value again"] = measures["value"]  # (as "without the -10s" with none)
        lines = PairedBySeed({"arm": (on, off)}, measures, "On minus off")
        self.assertEqual(lines[1], "On minus off, paired by seed (Holm over the 2):")
        kept = np.isfinite(treated)
        value = ComparePaired(treated[kept], control[kept], np.zeros(5))
        shifted = ComparePaired(np.array(shifted), np.array(shifted) - 0.2, np.zeros(6))
        self.assertLess(shifted.t_p, 1e-12)  # (the t-test on rounding: not what is shown)
        shifted = dc.replace(shifted, sd=0.0, d_z=math.nan, t_p=math.nan, low=0.2, high=0.2)
        self.assertAlmostEqual(shifted.wilcoxon_p, 2 / 2**6)
        p_value, p_shifted = Holm([value.t_p, shifted.wilcoxon_p])
        self.assertEqual(
            lines[3],
            f"- arm, value: {value.Text(p_value)}; 1 tied; 1 pairs without a value left out",
        )
        self.assertEqual(
            lines[4],
            f"- arm, shifted: {shifted.Text(p_shifted)}; Wilcoxon's p: every pair differs by "
            "the same",
        )
        self.assertEqual(
            lines[5:],
            ["", "Equal in every pair, not tested: arm, same.", "",
             "The same as an earlier measure in every run, not tested again: arm, value again "
             "(as value).", "", "Not compared (fewer than two pairs with values): arm, sparse."],
        )  # fmt: skip
        self.assertEqual(
            PairedBySeed({"arm": (on, off)}, {"same": measures["same"]}, "On minus off"),
            ["", "On minus off, paired by seed: equal in every pair, not tested: arm, same."],
        )

    def test_ratio_of_means_and_its_interval(self):
        a, b = np.array([2.0, 4.0, 6.0, 8.0]), np.array([1.0, 2.0, 3.0, 4.0])
        ratio, low, high = RatioOfMeans(a, b, [0, 0, 1, 1])
        self.assertEqual((ratio, low, high), (2.0, 2.0, 2.0))  # every pair 2:1
        rng = np.random.default_rng(1)
        b = rng.uniform(1, 2, 20)
        a = 1.5 * b * rng.uniform(0.8, 1.2, 20)
        ratio, low, high = RatioOfMeans(a, b, np.repeat([0, 1], 10), resamples=2000)
        self.assertAlmostEqual(ratio, a.mean() / b.mean())
        self.assertLess(low, ratio)
        self.assertLess(ratio, high)
        self.assertLess(high - low, 0.4)
        # One pair per MDP: the MDPs are resampled, so the interval is not a point.
        ratio, low, high = RatioOfMeans(a, b, np.arange(20), resamples=2000)
        self.assertLess(low, ratio)
        self.assertLess(ratio, high)
        # MDPs that differ widen the interval beyond resampling pairs within them could.
        scaled = a * np.repeat([0.8, 1.2], 10)
        _, low_mdp, high_mdp = RatioOfMeans(scaled, b, np.repeat([0, 1], 10), resamples=2000)
        _, low_one, high_one = RatioOfMeans(scaled, b, np.zeros(20), resamples=2000)
        self.assertGreater(high_mdp - low_mdp, high_one - low_one)


if __name__ == "__main__":
    unittest.main()
