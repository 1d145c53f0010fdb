"""Run-level statistics of the SAGG-RIAC comparisons (issue 23): effect sizes, their intervals,
the power of the two-sample t test, against textbook values, closed forms and simulation."""

import math
import unittest

import numpy as np
from scipy import stats

from mobee_drake.goal_babbling.statistics import (
    CohensD,
    CohensDInterval,
    Compare,
    RankBiserial,
    RankBiserialInterval,
    RunsForPower,
    TwoSampleTPower,
)


class TestEffectSizes(unittest.TestCase):
    def test_cohens_d_by_hand(self):
        # Means 2 and 3, both variances 1: d = -1; the sign follows the first group.
        self.assertAlmostEqual(CohensD([1, 2, 3], [2, 3, 4]), -1.0)
        self.assertAlmostEqual(CohensD([2, 3, 4], [1, 2, 3]), 1.0)
        # Unequal sizes: pooled variance ((3 - 1) 1 + (2 - 1) 0.5) / 3 = 2.5 / 3.
        self.assertAlmostEqual(CohensD([1, 2, 3], [5, 6]), (2 - 5.5) / math.sqrt(2.5 / 3))
        self.assertTrue(math.isnan(CohensD([1, 1], [1, 1])))

    def test_rank_biserial_against_mann_whitney(self):
        rng = np.random.default_rng(3)
        a, b = rng.normal(0, 1, 17), rng.normal(0.5, 1, 23)
        u = stats.mannwhitneyu(a, b).statistic
        self.assertAlmostEqual(RankBiserial(a, b), 2 * u / (17 * 23) - 1)
        self.assertEqual(RankBiserial([5, 6, 7], [1, 2]), 1.0)
        self.assertEqual(RankBiserial([1, 2], [1, 2]), 0.0)  # ties count zero

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
            Compare([1.0, math.nan], [1.0, 2.0])


class TestCompare(unittest.TestCase):
    def test_fields_agree_with_scipy(self):
        rng = np.random.default_rng(7)
        a, b = rng.normal(1, 1, 30), rng.normal(0, 2, 25)
        result = Compare(a, b)
        self.assertEqual((result.n_a, result.n_b), (30, 25))
        self.assertAlmostEqual(result.p_anova, stats.f_oneway(a, b).pvalue)
        self.assertAlmostEqual(result.p_anova, stats.ttest_ind(a, b).pvalue)
        self.assertAlmostEqual(result.p_welch, stats.ttest_ind(a, b, equal_var=False).pvalue)
        self.assertAlmostEqual(result.median_b, np.median(b))
        self.assertAlmostEqual(result.power, TwoSampleTPower(abs(result.cohens_d), 30, 25))
        self.assertLess(result.d_low, result.cohens_d)
        self.assertLess(result.cohens_d, result.d_high)

    def test_constant_groups_give_nan_not_an_error(self):
        result = Compare([1.0, 1.0], [1.0, 1.0])
        self.assertTrue(math.isnan(result.cohens_d))
        self.assertTrue(math.isnan(result.p_anova))
        self.assertEqual(result.runs_for_80_percent, -1)


if __name__ == "__main__":
    unittest.main()
