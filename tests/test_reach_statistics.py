"""Run-level statistics of the reach-learning battery against closed forms (issue 23, point 8)."""

import math
import unittest

import numpy as np

from mobee_drake.experiments.statistics import CompareRuns, RunMeans


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


if __name__ == "__main__":
    unittest.main()
