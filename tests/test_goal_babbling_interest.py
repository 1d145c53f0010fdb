"""Competence (Sec. II-D-1, eq. 7), interest (eq. 1-2), splits and the selection modes (eq. 3)."""

import itertools
import unittest

import numpy as np

from mobee_drake.goal_babbling.competence import (
    Competence,
    Interest,
    LocalCompetence,
    MaskedInterests,
    ReachingCost,
)
from mobee_drake.goal_babbling.config import InterestConfig
from mobee_drake.goal_babbling.regions import (
    BestSplit,
    InterestProbabilities,
    RegionTree,
    SelectRegion,
)


class TestCompetence(unittest.TestCase):
    def test_reaching_cost_eq7(self):
        # Start 10 away from the goal, end 2.5 away: C = -0.25.
        self.assertAlmostEqual(
            ReachingCost(np.array([10.0, 0]), np.array([10.0, 2.5]), np.zeros(2), -1.0), -0.25
        )
        # 3-4-5 triangle.
        self.assertAlmostEqual(
            ReachingCost(np.array([3.0, 4.0]), np.zeros(2), np.array([3.0, -1.0]), -1.0), -1.0
        )
        self.assertAlmostEqual(
            ReachingCost(np.array([3.0, 4.0]), np.array([0.0, 4.0]), np.zeros(2), -1.0), -0.6
        )
        # D(x_start, x_g) = 0: min_C if the end moved away, 0 if it stayed.
        self.assertEqual(ReachingCost(np.ones(2), np.zeros(2), np.ones(2), -3.0), -3.0)
        self.assertEqual(ReachingCost(np.ones(2), np.ones(2), np.ones(2), -3.0), 0.0)

    def test_competence_clips(self):
        tolerance, minimum = -0.05, -1.0
        self.assertEqual(Competence(-2.0, tolerance, minimum), -1.0)
        self.assertEqual(Competence(-1.0, tolerance, minimum), -1.0)
        self.assertEqual(Competence(-0.4, tolerance, minimum), -0.4)
        self.assertEqual(Competence(-0.05, tolerance, minimum), -0.05)
        self.assertEqual(Competence(-0.01, tolerance, minimum), 0.0)
        self.assertEqual(Competence(0.0, tolerance, minimum), 0.0)

    def test_local_competence_eq1(self):
        self.assertAlmostEqual(LocalCompetence([-1.0, -0.5, 0.0, -0.5]), -0.5)
        self.assertEqual(LocalCompetence([]), 0.0)


class TestInterest(unittest.TestCase):
    def test_eq2_on_hand_made_sequences(self):
        # zeta = 8: older half sums to -4, newer half to 0: |-4 - 0| / 8.
        self.assertAlmostEqual(Interest([-1, -1, -1, -1, 0, 0, 0, 0], 8), 0.5)
        # Decreasing competence counts as much as increasing (absolute value).
        self.assertAlmostEqual(Interest([0, 0, 0, 0, -1, -1, -1, -1], 8), 0.5)
        # Only the last zeta values count: the window sees only zeros.
        self.assertAlmostEqual(Interest([-1, -1, -1, -1, 0, 0, 0, 0], 4), 0.0)
        # Window slides: older [-0.2, -0.4], newer [-0.6, -0.6] -> |-0.6 + 1.2| / 4.
        self.assertAlmostEqual(Interest([-1.0, -0.2, -0.4, -0.6, -0.6], 4), 0.15)
        # Constant competence: no progress.
        self.assertAlmostEqual(Interest(np.full(30, -0.3), 20), 0.0)

    def test_fewer_values_than_the_window(self):
        self.assertAlmostEqual(Interest([-1.0, 0.0], 20), 0.5)
        # Odd count: the oldest value is left out of the even window.
        self.assertAlmostEqual(Interest([-5.0, -1.0, 0.0], 20), 0.5)
        self.assertEqual(Interest([-1.0], 20), 0.0)
        self.assertEqual(Interest([], 20), 0.0)

    def test_masked_interests_match_the_subsequences(self):
        rng = np.random.default_rng(3)
        values = rng.uniform(-1, 0, 40)
        masks = rng.random((25, 40)) < 0.5
        expected = [Interest(values[mask], 10) for mask in masks]
        np.testing.assert_allclose(MaskedInterests(values, masks, 10), expected)


class TestSplit(unittest.TestCase):
    def test_cut_separates_progress_from_stagnation(self):
        # 60 goals in time order: even ones on the left (x < 0.4) with constant competence, odd ones
        # on the right (x > 0.6) whose competence improves from -1 to 0. Any cut mixing them lowers
        # the difference.
        rng = np.random.default_rng(0)
        count = 60
        left = np.arange(count) % 2 == 0
        points = np.column_stack(
            [
                np.where(left, rng.uniform(0, 0.4, count), rng.uniform(0.6, 1, count)),
                rng.uniform(0, 1, count),
            ]
        )
        values = np.where(left, -0.5, np.where(np.arange(count) < 40, -1.0, 0.0))
        dimension, cut = BestSplit(points, values, window=20, min_child=10)
        self.assertEqual(dimension, 0)
        self.assertAlmostEqual(cut, 0.5 * (points[left, 0].max() + points[~left, 0].min()))
        best = abs(
            Interest(values[points[:, 0] < cut], 20) - Interest(values[points[:, 0] >= cut], 20)
        )
        self.assertAlmostEqual(best, 0.5)
        # Brute force over every admissible cut in both dimensions.
        for axis, index in itertools.product(range(2), range(count)):
            lower = points[:, axis] < points[index, axis]
            if 10 <= lower.sum() <= count - 10:
                other = abs(Interest(values[lower], 20) - Interest(values[~lower], 20))
                self.assertLessEqual(other, best + 1e-12)

    def test_no_admissible_cut(self):
        self.assertIsNone(BestSplit(np.ones((30, 2)), np.zeros(30), window=20, min_child=10))
        self.assertIsNone(BestSplit(np.random.default_rng(0).random((15, 2)), np.zeros(15), 20, 10))

    def test_tree_splits_beyond_g_max_and_keeps_history(self):
        config = InterestConfig(max_region_goals=50, window=20, min_child_goals=10)
        tree = RegionTree([0.0, -1.0], [1.0, 1.0], config)
        rng = np.random.default_rng(1)
        for _ in range(50):
            tree.Add(rng.uniform([0, -1], [1, 1]), -0.5)
        self.assertEqual(len(tree.leaves), 1)
        tree.Add(rng.uniform([0, -1], [1, 1]), -0.5)
        self.assertEqual(len(tree.leaves), 2)
        self.assertEqual(sum(len(leaf.values) for leaf in tree.leaves), 51)
        for leaf in tree.leaves:
            self.assertGreaterEqual(len(leaf.values), 10)
            points = np.array(leaf.points)
            self.assertTrue(np.all((points >= leaf.low) & (points <= leaf.high)))
        # The halves tile the box.
        lower, upper = tree.leaves
        np.testing.assert_allclose(
            np.prod(lower.high - lower.low) + np.prod(upper.high - upper.low), 2.0
        )
        self.assertEqual(tree.LeavesAt(50), [tree.root])
        self.assertEqual(tree.LeavesAt(51), tree.leaves)

    def test_leaves_containing_a_state(self):
        tree = RegionTree(
            np.zeros(2), np.ones(2), InterestConfig(max_region_goals=4, window=4, min_child_goals=2)
        )
        rng = np.random.default_rng(2)
        for _ in range(200):
            point = rng.random(2)
            tree.Add(point, -point[0] * rng.random())
        state = np.array([0.3, 0.0])
        found = tree.LeavesContaining(state, np.array([True, False]))
        expected = [leaf for leaf in tree.leaves if leaf.low[0] <= 0.3 < leaf.high[0]]
        self.assertEqual(sorted(map(id, found)), sorted(map(id, expected)))
        self.assertAlmostEqual(sum(leaf.high[1] - leaf.low[1] for leaf in found), 1.0)


class _Leaf:
    def __init__(self, interest, mean):
        self.interest, self.mean = interest, mean

    def MeanCompetence(self):
        return self.mean


class TestSelectionModes(unittest.TestCase):
    def test_eq3(self):
        np.testing.assert_allclose(
            InterestProbabilities([0.1, 0.3, 0.6]), [0.0, 0.2 / 0.7, 0.5 / 0.7]
        )
        np.testing.assert_allclose(InterestProbabilities([0.2, 0.2]), [0.5, 0.5])

    def test_mode_proportions_and_choices(self):
        leaves = [_Leaf(0.0, -0.2), _Leaf(0.1, -0.9), _Leaf(0.3, -0.1)]
        rng = np.random.default_rng(42)
        draws = 20_000
        modes, chosen = np.zeros(4), np.zeros(3)
        for _ in range(draws):
            mode, region = SelectRegion(leaves, rng, (0.7, 0.2, 0.1))
            modes[mode] += 1
            if mode == 1:
                chosen[leaves.index(region)] += 1
            elif mode == 2:
                self.assertIsNone(region)
            else:
                self.assertIs(region, leaves[1])  # lowest mean competence
        # Binomial standard deviations are below 0.0033; allow 5 of them.
        np.testing.assert_allclose(modes[1:] / draws, [0.7, 0.2, 0.1], atol=0.0165)
        np.testing.assert_allclose(chosen / chosen.sum(), [0.0, 0.25, 0.75], atol=0.02)


if __name__ == "__main__":
    unittest.main()
