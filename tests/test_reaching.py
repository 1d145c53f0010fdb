"""Reward predictors of ch. 8 against their closed forms (eq. 8.1-8.7)."""

import unittest

import numpy as np

from mobee_drake.reaching.predictors import (
    FAILED_TRANSITION_REWARD,
    ReachReward,
    RewardHistories,
    TransitionReward,
)


class TestPredictors(unittest.TestCase):
    def setUp(self):
        # State-action 0 is a transition, 1 a reach.
        self.histories = RewardHistories([False, True])

    def test_empty_histories(self):
        self.assertEqual(self.histories.Predict(0, [0, 0, 0]), 0.0)  # eq. 8.3: e_1 = 0
        self.assertEqual(self.histories.Predict(1, [0, 0, 0]), 1.0)  # eq. 8.5: e_1 = 1
        self.assertEqual(self.histories.PredictIntrinsic(1, [0, 0, 0]), 1.0)

    def test_one_record_closed_forms(self):
        h = self.histories
        h.Record(0, [1, 0, 0], 0.0, FAILED_TRANSITION_REWARD)
        # Eq. 8.1 with one record is that record's reward, whatever the distance.
        self.assertAlmostEqual(h.Predict(0, [4, 4, 2]), -10.0)
        h.Record(1, [0, 0, 0], 0.9, 0.5)
        w = 1 / (1 + 3.0)  # target 3 m away
        self.assertAlmostEqual(h.Predict(1, [0, 3, 0]), (1 + w * 0.5) / (1 + w))
        # The prediction error e - r = 0.4 feeds eq. 8.7.
        self.assertAlmostEqual(h.PredictIntrinsic(1, [0, 3, 0]), (1 + w * 0.4) / (1 + w))
        # Spatially optimistic: far from all experience the prediction tends to 1.
        self.assertGreater(h.Predict(1, [1e6, 0, 0]), 0.999999)
        # At the very target tried, the weights are 1.
        self.assertAlmostEqual(h.Predict(1, [0, 0, 0]), (1 + 0.5) / 2)

    def test_two_records_weighted(self):
        h = self.histories
        h.Record(0, [0, 0, 0], 0.0, 0.0)
        h.Record(0, [2, 0, 0], 0.0, -10.0)
        w0, w1 = 1 / (1 + 1.0), 1 / (1 + 1.0)  # the midpoint is 1 m from both
        self.assertAlmostEqual(h.Predict(0, [1, 0, 0]), (w0 * 0 + w1 * -10) / (w0 + w1))
        targets, estimates, rewards = h.History(0)
        np.testing.assert_array_equal(rewards, [0.0, -10.0])
        self.assertEqual(targets.shape, (2, 3))

    def test_rewards(self):
        self.assertEqual(ReachReward([0, 0, 0], [0, 0, 0]), 1.0)  # eq. 8.4
        self.assertAlmostEqual(ReachReward([0.3, 0, 0.4], [0, 0, 0]), 1 / 1.5)
        self.assertEqual(TransitionReward(0.2, 0.3), 0.0)
        self.assertEqual(TransitionReward(0.3, 0.3), FAILED_TRANSITION_REWARD)


if __name__ == "__main__":
    unittest.main()
