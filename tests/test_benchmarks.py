"""The benchmarks' measurements run and report what they say (smoke runs: figures are printed by
the benchmarks themselves, never asserted as speeds here)."""

import unittest

import numpy as np

from mobee_drake.experiments.bench_forces import STAGES, MeasureForceEvaluations, MeasureStages
from mobee_drake.experiments.bench_simulation import ControlPeriodAndFloor
from mobee_drake.scenario import LoadScenario


class TestBenchmarks(unittest.TestCase):
    def test_forces_beside_drakes_floor(self):
        for churn in (False, True):
            with self.subTest(churn=churn):
                result = MeasureForceEvaluations(5, num_poses=40, repeats=2, churn=churn, seed=3)
                self.assertTrue(np.isfinite(result.ratio) and result.ratio > 0)
                self.assertGreater(result.peak_rss_mib, 0.0)
                self.assertGreater(result.mean_pairs_in_fields, 0.0)

    def test_stages_of_an_evaluation(self):
        stages = MeasureStages(5, num_poses=40, repeats=2, seed=3)
        self.assertEqual(list(stages), list(STAGES))
        self.assertTrue(np.isfinite(list(stages.values())).all(), stages)
        # The field pairs are timed net of their own query (a difference); the others on their own.
        for stage in ("pose update", "query", "forces"):
            self.assertGreater(stages[stage], 0.0, stage)

    def test_one_control_period_beside_its_floor(self):
        scenario = LoadScenario("motor_babbling", "{duration: 2.0}")
        period, floor = ControlPeriodAndFloor(scenario)
        self.assertTrue(np.isfinite([period, floor]).all() and period > 0 and floor > 0)


if __name__ == "__main__":
    unittest.main()
