"""The four learners (Sec. IV-B-1): budgets, resets, subgoals, goal modes, reproducibility; the
experiment script.
"""

import contextlib
import io
import json
import pathlib
import tempfile
import unittest

import numpy as np

from mobee_drake.experiments import saggriac_command as command
from mobee_drake.goal_babbling.baselines import ActuatorRandom, ActuatorRiac, SaggRandom
from mobee_drake.goal_babbling.config import Experiment1Config, Experiment2Config, InterestConfig
from mobee_drake.goal_babbling.evaluation import MakeEvaluator, MakeTestSet
from mobee_drake.goal_babbling.sagg_riac import SaggRiac


def SmallConfig(seed=0, budget=1500):
    """Experiment 1 with small regions so that splits happen within a short budget."""
    config = Experiment1Config(seed=seed, budget=budget)
    config.interest = InterestConfig(max_region_goals=10, window=6, min_child_goals=3)
    config.evaluation.num_checkpoints = 3
    return config


class TestLearners(unittest.TestCase):
    def test_budget_memory_and_checkpoints(self):
        for learner_class in (SaggRiac, SaggRandom, ActuatorRandom, ActuatorRiac):
            config = SmallConfig(budget=700)
            learner = learner_class(config, MakeEvaluator(config)).Run()
            self.assertEqual(learner.time_steps, 700)
            self.assertEqual(learner.memory.size, 700)
            self.assertEqual([point["time_step"] for point in learner.curve], [0, 233, 467, 700])
            # The stored displacements are those of the true arm.
            memory = learner.memory
            following = memory.positions[1:] - memory.positions[:-1]
            continuing = (
                np.linalg.norm(
                    memory.joint_angles[1:] - memory.joint_angles[:-1] - memory.joint_steps[:-1],
                    axis=1,
                )
                < 1e-12
            )
            np.testing.assert_allclose(
                following[continuing], memory.displacements[:-1][continuing], atol=1e-9
            )

    def test_same_seed_same_results_other_seed_other_results(self):
        for learner_class in (SaggRiac, ActuatorRiac):
            runs = [
                learner_class(SmallConfig(seed=seed), MakeEvaluator(SmallConfig(seed=seed))).Run()
                for seed in (3, 3, 4)
            ]
            np.testing.assert_array_equal(runs[0].memory.joint_angles, runs[1].memory.joint_angles)
            self.assertEqual(runs[0].curve, runs[1].curve)
            self.assertFalse(
                np.array_equal(runs[0].memory.joint_angles, runs[2].memory.joint_angles)
            )
        self.assertEqual(
            SaggRiac(SmallConfig(seed=3)).Run().goal_log,
            SaggRiac(SmallConfig(seed=3)).Run().goal_log,
        )

    def test_actuator_methods_reset_every_period(self):
        config = SmallConfig(budget=3 * Experiment1Config().ActuatorResetPeriod() + 5)
        period = config.ActuatorResetPeriod()
        for learner_class in (ActuatorRandom, ActuatorRiac):
            memory = learner_class(config).Run().memory
            starts = memory.joint_angles[[0, period, 2 * period, 3 * period]]
            np.testing.assert_array_equal(starts, 0.0)
            self.assertGreater(np.abs(memory.joint_angles[period - 1]).max(), 0.0)
            self.assertTrue(
                np.all(
                    np.abs(memory.joint_steps) <= config.low_level.exploration_joint_step + 1e-15
                )
            )

    def test_actuator_riac_records_prediction_errors_in_its_regions(self):
        learner = ActuatorRiac(SmallConfig(budget=1000)).Run()
        self.assertGreater(len(learner.tree.leaves), 2)
        self.assertEqual(
            learner.tree.num_points, 999
        )  # the last action ends the budget before being recorded
        values = np.concatenate([leaf.values for leaf in learner.tree.leaves])
        self.assertTrue(np.all(values <= 0.0))

    def test_sagg_subgoals_resets_and_modes(self):
        learner = SaggRiac(SmallConfig(budget=3000)).Run()
        log = np.array(learner.goal_log)
        self.assertGreater(len(learner.tree.leaves), 2)
        complete = [
            attempt for attempt in np.unique(log[:, 5]) if np.sum(log[:, 5] == attempt) == 5
        ]
        self.assertGreater(len(complete), 10)
        for attempt in complete:
            rows = log[log[:, 5] == attempt]
            # Five equally spaced subgoals on a line, the last being the goal.
            steps = np.diff(rows[:, 1:3], axis=0)
            np.testing.assert_allclose(steps, np.broadcast_to(steps[0], steps.shape), atol=1e-9)
            np.testing.assert_array_equal(rows[:4, 4], 0)
            self.assertIn(rows[4, 4], (1, 2, 3))
            if attempt % 2 == 0:
                # The arm was reset: the first subgoal is a fifth of the way from the rest tip (50,
                # 0).
                np.testing.assert_allclose(rows[0, 1:3] - [50, 0], steps[0], atol=1e-9)
        modes = log[log[:, 4] > 0, 4]
        self.assertTrue({1, 2}.issubset(set(modes.tolist())))
        self.assertTrue(np.all((log[:, 3] >= -1.0) & (log[:, 3] <= 0.0)))

    def test_sagg_random_draws_uniform_goals(self):
        config = Experiment2Config(seed=5)
        learner = SaggRandom(config)
        goals = np.array([learner.SelectGoal()[0] for _ in range(4000)])
        self.assertTrue(np.all((goals >= [0, -150]) & (goals <= [150, 150])))
        np.testing.assert_allclose(goals.mean(axis=0), [75, 0], atol=3.0)

    def test_learning_reduces_both_errors(self):
        config = Experiment1Config(seed=1, budget=6000)
        config.evaluation.num_checkpoints = 1
        curve = SaggRandom(config, MakeEvaluator(config)).Run().curve
        self.assertLess(curve[-1]["reaching_error"], 0.5 * curve[0]["reaching_error"])
        self.assertLess(curve[-1]["prediction_error"], 0.5 * curve[0]["prediction_error"])

    def test_test_set(self):
        test_set = MakeTestSet(Experiment1Config())
        radii = np.linalg.norm(test_set.goals, axis=1)
        self.assertTrue(np.all((radii <= 50) & (test_set.goals[:, 0] >= 0)))
        self.assertEqual(test_set.configurations.shape, (100, 15))
        np.testing.assert_array_equal(test_set.goals, MakeTestSet(Experiment2Config(seed=9)).goals)


class TestExperimentScript(unittest.TestCase):
    def test_smoke_run_writes_results_and_resumes(self):
        with tempfile.TemporaryDirectory() as folder:
            output = pathlib.Path(folder)
            argv = [
                "--smoke",
                "--experiments",
                "1",
                "--seeds",
                "2",
                "--output",
                folder,
                "--workers",
                "1",
            ]
            with contextlib.redirect_stdout(io.StringIO()):
                command.main(argv)
            results = sorted((output / "runs").glob("*/result.json"))
            self.assertEqual(len(results), 8)
            self.assertFalse(list((output / "runs").rglob("*.tmp")))
            for name in (
                "exp1_curves.csv",
                "exp1_curves.png",
                "exp1_goals.png",
                "report.md",
                "statistics.json",
            ):
                self.assertGreater((output / name).stat().st_size, 100, name)
            lines = (output / "exp1_curves.csv").read_text().splitlines()
            self.assertEqual(len(lines), 1 + 8 * 3)
            statistics = json.loads((output / "statistics.json").read_text())["1"]
            self.assertTrue(
                all(row["p_value"] is None or 0.0 <= row["p_value"] <= 1.0 for row in statistics)
            )
            self.assertIn("SAGG-RIAC vs SAGG-Random", (output / "report.md").read_text())
            before = [path.stat().st_mtime_ns for path in results]
            with contextlib.redirect_stdout(io.StringIO()):
                command.main(argv)  # Every run has its result: none runs again.
            self.assertEqual([path.stat().st_mtime_ns for path in results], before)


if __name__ == "__main__":
    unittest.main()
