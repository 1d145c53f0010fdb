"""The benchmarks' measurements run and report what they say (smoke runs: figures are printed by
the benchmarks themselves, never asserted as speeds here)."""

import unittest

import numpy as np

from mobee_drake.experiments import bench_objects, bench_values
from mobee_drake.experiments.bench_forces import STAGES, MeasureForceEvaluations, MeasureStages
from mobee_drake.experiments.bench_simulation import ControlPeriodAndFloor
from mobee_drake.scenario import LoadScenario
from mobee_drake.station.config import MAX_OBJECTS


class TestBenchmarks(unittest.TestCase):
    def test_forces_beside_drakes_floor(self):
        for churn in (False, True):
            with self.subTest(churn=churn):
                result = MeasureForceEvaluations(5, num_poses=40, repeats=2, churn=churn, seed=3)
                self.assertTrue(np.isfinite(result.ratio) and result.ratio > 0)
                self.assertGreater(result.peak_rss_mib, 0.0)
                self.assertGreater(result.mean_pairs_in_fields, 0.0)
                # The poses sweep the joints' ranges, far from the attractor: MoBeE pulls back.
                self.assertGreater(result.mean_total_norm, 1.0)

    def test_stages_of_an_evaluation(self):
        stages = MeasureStages(5, num_poses=40, repeats=2, seed=3)
        self.assertEqual(list(stages), list(STAGES))
        self.assertTrue(np.isfinite(list(stages.values())).all(), stages)
        # The field pairs are timed net of their own query (a difference); the others on their own.
        for stage in ("pose update", "query", "forces"):
            self.assertGreater(stages[stage], 0.0, stage)

    def test_one_control_period_beside_its_floor(self):
        scenario = LoadScenario("motor_babbling", "{duration: 2.0}")
        measured = ControlPeriodAndFloor(scenario)
        self.assertTrue(np.isfinite([measured.period_us, measured.floor_us]).all())
        self.assertGreater(min(measured.period_us, measured.floor_us), 0.0)
        # The periods timed are a babbling robot's: some joint swept a good part of its range.
        self.assertGreater(measured.travel_deg, 20.0)


class TestObjectCount(unittest.TestCase):
    def test_builds_measured_in_their_own_processes_and_the_limit_refused(self):
        """Issue 31, item 5: ``bench objects`` on 20 boxes, and the station of one more than the
        limit refused at load (Drake's floor for it, seconds of work, is left to the bench)."""
        table = bench_objects.Table([20], cap_bytes=8 * 2**30)
        header, _, small = (line.strip("|").split("|") for line in table.splitlines())
        self.assertEqual(len(header), 7)
        floor_seconds, floor_peak, seconds, peak, time_ratio, memory_ratio = map(float, small[1:])
        # A build's peak is at least an imported pydrake's, and each ratio is its columns' (but
        # for their rounding to 0.01).
        self.assertGreater(min(floor_peak, peak), 0.1)
        rounding = 0.005 / floor_seconds + 0.005 / seconds
        self.assertAlmostEqual(time_ratio, seconds / floor_seconds, delta=time_ratio * rounding)
        peaks_rounding = 0.005 / floor_peak + 0.005 / peak  # (GiB shown to 0.01)
        self.assertAlmostEqual(memory_ratio, peak / floor_peak, delta=memory_ratio * peaks_rounding)
        *_, error = bench_objects.Measure("station", MAX_OBJECTS + 1, cap_bytes=8 * 2**30)
        self.assertEqual(error, "refused at load")

    def test_a_process_over_its_cap_is_reported_by_how_it_ended(self):
        seconds, peak, error = bench_objects.Measure("floor", 100, cap_bytes=2**28)
        self.assertRegex(error, r"^(over the cap|died \(SIG[A-Z]+\))$")
        self.assertTrue(np.isnan(peak) or peak > 0)
        seconds, peak, error = bench_objects.Measure("floor", 100, 8 * 2**30, timeout=0.01)
        self.assertEqual(error, "timed out")


class TestValueIteration(unittest.TestCase):
    def test_sparse_and_dense(self):
        T, rewards, action_state = bench_values.LearnerModel(6, 40, outcomes=2)
        # Each transition's row is a distribution over its own state, its goal and what it
        # observed (at least two states); each state's reach has an empty row.
        sums = T.sum(axis=1)
        np.testing.assert_allclose(np.sort(sums), [0.0] * 6 + [1.0] * 40, atol=1e-12)
        stored = np.diff(T.indptr)
        self.assertTrue(np.all((stored >= 2) == (sums > 0)))
        self.assertTrue(np.all(np.diff(action_state) >= 0))  # (value iteration's order)
        self.assertEqual(len(rewards), 46)
        self.assertEqual(T.nnz, np.count_nonzero(T.toarray()))
        # A model whose dense T is about 1.6 MiB (2100 state-actions x 100 states x 8 bytes).
        row = bench_values.Row(100, 2000, outcomes=1, repeats=2).strip("|").split("|")
        cells = [cell.replace(",", "") for cell in row]  # (thousands separated)
        states, transitions, entries, mib, dense, fast, ratio, difference = cells
        big, _, _ = bench_values.LearnerModel(100, 2000, outcomes=1)
        self.assertEqual((int(states), int(transitions), int(entries)), (100, 2000, big.nnz))
        self.assertEqual(float(mib), round(2100 * 100 * 8 / 2**20, 1))
        self.assertLess(float(difference), 1e-12)  # (the same values, summed in another order)
        rounding = 0.005 / float(dense) + 0.005 / float(fast)  # (ms shown to 0.01)
        self.assertAlmostEqual(
            float(ratio), float(dense) / float(fast), delta=0.05 + float(ratio) * rounding
        )


if __name__ == "__main__":
    unittest.main()
