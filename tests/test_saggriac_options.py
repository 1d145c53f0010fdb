"""Issue 23's additions to SAGG-RIAC: the reachable-area test set and the new measures, the
goal-selection options (stall, model-error trigger, explauto's split), the drift-free "set"
reading of the actuator baselines, their diagnostics, and the experiment's variants."""

import contextlib
import io
import itertools
import pathlib
import tempfile
import unittest
from unittest import mock

import numpy as np
from scipy import stats
from test_figures import FigureTest

from mobee_drake.experiments import saggriac as experiments
from mobee_drake.experiments import saggriac_command as command
from mobee_drake.experiments import saggriac_figures as figures
from mobee_drake.experiments import saggriac_report as report
from mobee_drake.goal_babbling.baselines import ActuatorRandom, ActuatorRiac, SaggRandom
from mobee_drake.goal_babbling.competence import Interest
from mobee_drake.goal_babbling.config import (
    ActuatorConfig,
    ConfigFromDict,
    ConfigToDict,
    Experiment1Config,
    Experiment2Config,
    InterestConfig,
    LowLevelConfig,
)
from mobee_drake.goal_babbling.evaluation import (
    MEASURES,
    Evaluator,
    MakeTestSet,
    ReachablePostures,
    TrueJacobians,
)
from mobee_drake.goal_babbling.planar_arm import ForwardKinematics, LinkLengths
from mobee_drake.goal_babbling.regions import BestSplit


class TestTestSets(unittest.TestCase):
    def test_true_jacobian_matches_finite_differences(self):
        config = Experiment1Config()
        lengths = LinkLengths(config.arm)
        angles = np.random.default_rng(0).uniform(-1, 1, (3, 15))
        jacobians = TrueJacobians(angles, lengths)
        step = 1e-6
        for joint in range(15):
            moved = angles.copy()
            moved[:, joint] += step
            numeric = (
                ForwardKinematics(moved, lengths) - ForwardKinematics(angles, lengths)
            ) / step
            np.testing.assert_allclose(jacobians[:, :, joint], numeric, atol=1e-4)

    def test_reachable_set_covers_the_half_disc_and_the_old_sets_stay(self):
        config = Experiment2Config()
        test_set = MakeTestSet(config)
        # The postures reach their goals.
        misses = np.linalg.norm(test_set.reachable_positions - test_set.reachable_goals, axis=1)
        self.assertLess(misses.max(), config.evaluation.tolerance / 10 + 1e-9)
        np.testing.assert_allclose(
            ForwardKinematics(test_set.reachable_configurations, LinkLengths(config.arm)),
            test_set.reachable_positions,
        )
        # Their tips spread over the half-disc; the near-rest tips sit on its rim.
        radii = np.linalg.norm(test_set.reachable_positions, axis=1)
        self.assertLess(np.percentile(radii, 10), 20.0)
        self.assertGreater(np.percentile(radii, 90), 45.0)
        self.assertGreater(np.linalg.norm(test_set.positions, axis=1).min(), 40.0)
        # The test goals and near-rest configurations are the earlier evaluation's.
        rng = np.random.default_rng(config.evaluation.test_set_seed)
        radii = 50.0 * np.sqrt(rng.uniform(0.0, 1.0, 100))
        angles = rng.uniform(-np.pi / 2, np.pi / 2, 100)
        np.testing.assert_array_equal(
            test_set.goals, np.stack([radii * np.cos(angles), radii * np.sin(angles)], axis=1)
        )
        np.testing.assert_array_equal(test_set.configurations, rng.uniform(-0.3, 0.3, (100, 15)))
        # Cached and read-only, shared by runs of other seeds and goal spaces.
        self.assertIs(MakeTestSet(Experiment1Config(seed=4)), test_set)
        with self.assertRaises(ValueError):
            test_set.goals[0, 0] = 1.0

    def test_postures_from_the_singular_rest_pose(self):
        goals = np.array([[20.0, 1e-3], [49.0, 0.0], [5.0, -30.0]])
        postures = ReachablePostures(goals, Experiment1Config())
        tips = ForwardKinematics(postures, LinkLengths(Experiment1Config().arm))
        # Straight in from the singular rest pose along x: J^+ cannot move the tip there.
        self.assertLess(np.linalg.norm(tips[0] - goals[0]), 0.01)
        self.assertGreater(np.linalg.norm(tips[1] - goals[1]), 0.5)
        self.assertLess(np.linalg.norm(tips[2] - goals[2]), 0.01)

    def test_evaluator_measures(self):
        config = Experiment1Config(seed=2, budget=1500)
        config.evaluation.num_checkpoints = 1
        evaluator = Evaluator(config)
        learner = SaggRandom(config, evaluator).Run()
        final = learner.curve[-1]
        self.assertEqual(set(final), {"time_step", *MEASURES})
        errors = evaluator.reaching_errors
        self.assertAlmostEqual(final["reaching_error"], errors.mean())
        self.assertAlmostEqual(final["reaching_error_median"], np.median(errors))
        self.assertAlmostEqual(final["reached_share"], np.mean(errors <= 1.0))
        # Before learning: nothing moves and the rest tip is every prediction.
        first = learner.curve[0]
        test_set = evaluator.test_set
        np.testing.assert_allclose(
            first["prediction_error"],
            np.linalg.norm(test_set.reachable_positions - [50.0, 0.0], axis=1).mean(),
        )
        np.testing.assert_allclose(
            first["reaching_error"],
            np.linalg.norm(test_set.goals[0::2] - [50, 0], axis=1).mean() * 0.5
            + 0.5 * np.linalg.norm(test_set.goals[1::2] - [50, 0], axis=1).mean(),
        )


def _CrampedLearner(trigger: str, stall_steps: int) -> SaggRandom:
    """A learner whose reaching steps cannot move the tip (joint steps capped at 1e-5 rad), with
    a local model learnt around a bent posture (exploration steps of 1e-4 rad: its jitter moves
    the tip by less than stall_progress)."""
    config = Experiment1Config(seed=0, budget=2000)
    config.low_level.max_joint_step = 1e-5
    config.low_level.exploration_joint_step = 1e-4
    config.low_level.exploration_trigger = trigger
    config.low_level.stall_steps = stall_steps
    learner = SaggRandom(config)
    learner.arm.SetJointAngles(np.full(15, 0.1))
    learner.Explore()
    learner.Explore()
    return learner


class TestOptions(unittest.TestCase):
    def test_model_error_trigger_skips_impossible_steps(self):
        goal = np.array([20.0, 30.0])
        counts = {}
        for trigger in ("task", "model"):
            learner = _CrampedLearner(trigger, 0)
            before, started = learner.exploration_steps, learner.time_steps
            learner.ReachGoal(goal)
            counts[trigger] = learner.exploration_steps - before
            self.assertGreater(learner.time_steps - started, 50)  # ran to its timeout
        # The desired step of v is never made (task error ~v): every step explores; the model
        # predicts the tiny step it made: no step explores.
        self.assertGreater(counts["task"], 0)
        self.assertEqual(counts["model"], 0)

    def test_stall_ends_an_attempt_without_progress(self):
        for trigger, explorations in (("model", 0), ("task", 1)):
            learner = _CrampedLearner(trigger, 2)
            before, started = learner.exploration_steps, learner.time_steps
            learner.ReachGoal(np.array([20.0, 30.0]))
            self.assertEqual(learner.stalled_attempts, 1)
            # Two reaching steps (and the one exploration phase the first one starts).
            q = learner.config.low_level.exploration_actions
            self.assertEqual(learner.time_steps - started, 2 + explorations * q)
            self.assertEqual(learner.exploration_steps - before, explorations * q)

    def test_stall_keeps_attempts_that_progress(self):
        config = Experiment1Config(seed=0, budget=4000)
        config.low_level.stall_steps = 2
        learner = SaggRandom(config)
        for goal in ([47.0, 8.0], [45.0, -12.0], [44.0, 10.0]):
            learner.arm.Reset()
            learner.ReachGoal(np.array(goal))
        self.assertEqual(learner.num_attempts, 3)
        self.assertLess(learner.stalled_attempts, 3)

    def test_weighted_split_is_explautos_criterion(self):
        rng = np.random.default_rng(1)
        for trial in range(5):
            points = rng.uniform(0, 1, (51, 2))
            values = -rng.uniform(0, 1, 51) * (points[:, 0] > 0.8)
            for weighted in (False, True):
                best, best_score = None, -1.0
                for dimension in range(2):
                    coordinates = np.unique(points[:, dimension])
                    for cut in 0.5 * (coordinates[:-1] + coordinates[1:]):
                        lower = points[:, dimension] < cut
                        if min(lower.sum(), (~lower).sum()) < 3:
                            continue
                        score = abs(Interest(values[lower], 20) - Interest(values[~lower], 20))
                        if weighted:
                            score *= lower.sum() * (~lower).sum()
                        if score > best_score + 1e-12:
                            best, best_score = (dimension, cut), score
                found = BestSplit(points, values, 20, 3, weighted=weighted)
                self.assertEqual(found[0], best[0], (trial, weighted))
                self.assertAlmostEqual(found[1], best[1], msg=(trial, weighted))

    def test_weighted_split_in_the_tree(self):
        config = Experiment1Config(seed=3, budget=3000)
        config.interest = InterestConfig(
            max_region_goals=10, window=6, min_child_goals=3, split_criterion="weighted"
        )
        learner = experiments.METHODS["SAGG-RIAC"](config).Run()
        self.assertGreater(len(learner.tree.leaves), 2)


class TestActuatorReadings(unittest.TestCase):
    def Config(self, reading: str, budget: int = 1500):
        config = Experiment1Config(seed=1, budget=budget)
        config.interest = InterestConfig(max_region_goals=10, window=6, min_child_goals=3)
        config.actuator = ActuatorConfig(reading=reading, posture_range=0.2)
        config.evaluation.num_checkpoints = 1
        return config

    def test_set_reading_draws_postures_in_the_box(self):
        for learner_class in (ActuatorRandom, ActuatorRiac):
            learner = learner_class(self.Config("set")).Run()
            memory = learner.memory
            angles = memory.joint_angles[: memory.size]
            self.assertLessEqual(np.abs(angles).max(), 0.2)
            # Each sample starts from a drawn posture, not from where the last one ended.
            ended = angles[:-1] + memory.joint_steps[: memory.size - 1]
            self.assertTrue(np.all(np.linalg.norm(angles[1:] - ended, axis=1) > 1e-6))

    def test_set_reading_slots_follow_the_tree(self):
        learner = ActuatorRiac(self.Config("set", budget=2500)).Run()
        leaves = learner.tree.leaves
        self.assertGreater(len(leaves), 10)
        self.assertEqual({id(leaf) for leaf in leaves}, set(learner._slots))
        for leaf in leaves:
            slot = learner._slots[id(leaf)]
            self.assertIs(learner._slot_leaves[slot], leaf)
            self.assertEqual(learner._interests[slot], leaf.interest)
            self.assertAlmostEqual(learner._mean_competences[slot], leaf.MeanCompetence())
        root = learner.tree.root
        self.assertLessEqual(np.abs(root.high[:15]).max(), 0.2)

    def test_walk_reading_drifts_and_diagnostics(self):
        runs = {}
        for learner_class, reading in itertools.product(
            (ActuatorRandom, ActuatorRiac), ("walk", "set")
        ):
            config = self.Config(reading, budget=4 * Experiment1Config().ActuatorResetPeriod())
            evaluator = Evaluator(config)
            learner = learner_class(config, evaluator).Run()
            runs[learner_class.name, reading] = experiments.Diagnostics(learner, evaluator)
        # An unbiased random walk has a drift ratio near 1.
        self.assertAlmostEqual(runs["ACTUATOR-Random", "walk"]["drift_ratio"], 1.0, delta=0.25)
        # A run shorter than one reset period is one shorter window.
        config = self.Config("walk", budget=100)
        evaluator = Evaluator(config)
        short = experiments.Diagnostics(ActuatorRandom(config, evaluator).Run(), evaluator)
        self.assertAlmostEqual(short["drift_ratio"], 1.0, delta=0.5)
        for diagnostics in runs.values():
            self.assertTrue(0.0 <= diagnostics["tip_coverage"] <= 1.0)
            self.assertGreater(diagnostics["tip_spread"], 0.0)

    def test_goal_space_diagnostics(self):
        config = Experiment2Config(seed=0, budget=3000)
        config.evaluation.num_checkpoints = 1
        evaluator = Evaluator(config)
        learner = SaggRandom(config, evaluator).Run()
        diagnostics = experiments.Diagnostics(learner, evaluator)
        self.assertAlmostEqual(
            diagnostics["exploration_share"], learner.exploration_steps / learner.time_steps
        )
        self.assertTrue(0.0 <= diagnostics["unreachable_share"] <= 1.0)
        self.assertEqual(diagnostics["attempts"], learner.num_attempts)
        self.assertEqual(diagnostics["stalled_share"], 0.0)


class TestConfigChecks(unittest.TestCase):
    def test_bad_values_are_refused_in_one_line(self):
        for make, field in (
            (lambda: LowLevelConfig(exploration_trigger="always"), "exploration_trigger"),
            (lambda: LowLevelConfig(stall_steps=-1), "stall_steps"),
            (lambda: InterestConfig(split_criterion="median"), "split_criterion"),
            (lambda: ActuatorConfig(reading="teleport"), "reading"),
            (lambda: ActuatorConfig(posture_range=0.0), "posture_range"),
        ):
            with self.assertRaisesRegex(ValueError, f"^{field}[^\n]*$"):
                make()
        data = ConfigToDict(Experiment1Config())
        data["interest"]["split_criterion"] = "median"
        with self.assertRaisesRegex(ValueError, "split_criterion"):
            ConfigFromDict(data)
        config = Experiment1Config()
        config.actuator.reading = "teleport"  # set after construction: the learner refuses it
        with self.assertRaisesRegex(ValueError, "reading"):
            ActuatorRandom(config)

    def test_old_configurations_load_with_the_papers_defaults(self):
        data = ConfigToDict(Experiment2Config())
        for part, field in (
            ("low_level", "exploration_trigger"),
            ("low_level", "stall_steps"),
            ("interest", "split_criterion"),
        ):
            del data[part][field]
        del data["actuator"]
        config = ConfigFromDict(data)
        self.assertEqual(config.low_level.exploration_trigger, "task")
        self.assertEqual(config.low_level.stall_steps, 0)
        self.assertEqual(config.interest.split_criterion, "difference")
        self.assertEqual(config.actuator.reading, "walk")


class TestVariants(unittest.TestCase):
    def test_variants_set_their_options_only(self):
        reference = ConfigToDict(
            experiments.MakeConfig(experiments.RunSpec(2, "SAGG-RIAC", 0, 9, 1))
        )
        changed = {
            "stall": ("low_level", "stall_steps", 2),
            "model-error": ("low_level", "exploration_trigger", "model"),
            "weighted-split": ("interest", "split_criterion", "weighted"),
            "set": ("actuator", "reading", "set"),
        }
        for variant, (part, field, value) in changed.items():
            config = ConfigToDict(
                experiments.MakeConfig(experiments.RunSpec(2, "SAGG-RIAC", 0, 9, 1, variant))
            )
            self.assertEqual(config[part][field], value)
            config[part][field] = reference[part][field]
            self.assertEqual(config, reference, variant)

    def test_names_labels_and_pairs(self):
        specs = [
            experiments.RunSpec(2, method, 3, 100, 1, variant)
            for variant, method in itertools.product(experiments.VARIANTS, experiments.METHODS)
        ]
        self.assertEqual(len({spec.Name() for spec in specs}), len(specs))
        self.assertEqual(specs[0].Name(), "exp2_SAGG-RIAC_seed03_budget100")  # as before
        spec = experiments.RunSpec(2, "SAGG-RIAC", 3, 100, 1, "stall+model-error")
        self.assertEqual(spec.Label(), "SAGG-RIAC [stall+model-error]")
        pairs = report.Pairs(
            ["SAGG-RIAC", "SAGG-RIAC [stall]", "ACTUATOR-RIAC [set]", "ACTUATOR-Random [set]"]
        )
        self.assertEqual(
            pairs,
            [
                ("SAGG-RIAC", "ACTUATOR-Random [set]", "1"),
                ("ACTUATOR-RIAC [set]", "ACTUATOR-Random [set]", "2"),
                ("SAGG-RIAC [stall]", "SAGG-RIAC", "option"),
            ],
        )

    def test_command_line_refuses_in_one_line(self):
        with tempfile.TemporaryDirectory() as folder:
            for argv, message in (
                (["--variants", "turbo"], "invalid choice: 'turbo'"),
                (["--methods", "ACTUATOR-Random", "--variants", "stall"], "no run: none of"),
                (["--seeds", "0"], "must be a whole number >= 1"),
            ):
                stderr = io.StringIO()
                with contextlib.redirect_stderr(stderr), self.assertRaises(SystemExit):
                    command.main([*argv, "--output", str(pathlib.Path(folder) / "x")])
                self.assertIn(message, stderr.getvalue())
                self.assertEqual(len(stderr.getvalue().strip().splitlines()), 1, stderr.getvalue())

    def test_smoke_sets_only_the_sizes_the_flags_do_not_give(self):
        """Issue 31, item 11: ``--smoke`` silently overrode ``--budget-exp1``."""

        class Ran(Exception):
            pass

        def Specs(argv: list[str]) -> list:
            with mock.patch.object(command, "RunAll", side_effect=Ran) as run_all:
                with self.assertRaises(Ran):
                    command.main([*argv, "--experiments", "1", "--methods", "SAGG-RIAC"])
            return run_all.call_args.args[0]

        smoke = Specs(["--smoke"])
        self.assertEqual(len(smoke), experiments.SMOKE["seeds"])
        self.assertEqual({s.budget for s in smoke}, {experiments.SMOKE["budget_exp1"]})
        given = Specs(["--smoke", "--budget-exp1", "700", "--seeds", "1"])
        self.assertEqual([(s.budget, s.num_checkpoints) for s in given],
                         [(700, experiments.SMOKE["checkpoints"])])  # fmt: skip
        self.assertEqual({s.budget for s in Specs([])}, {experiments.FULL["budget_exp1"]})

    def test_smoke_battery_of_the_options(self):
        with tempfile.TemporaryDirectory() as folder:
            argv = ["--smoke", "--experiments", "2", "--output", folder, "--workers", "1"]
            argv += ["--methods", "SAGG-RIAC", "ACTUATOR-Random", "--variants", "paper", "stall"]
            argv += ["set"]
            with (
                contextlib.redirect_stdout(io.StringIO()),
                contextlib.redirect_stderr(io.StringIO()),
            ):
                command.main(argv)
            output = pathlib.Path(folder)
            self.assertEqual(len(list(output.glob("runs/*/result.json"))), 2 * 4)
            report = (output / "report.md").read_text()
            for text in ("SAGG-RIAC [stall] vs SAGG-RIAC", "ACTUATOR-Random [set]", "power"):
                self.assertIn(text, report)
            for name in ("exp2_effects.png", "exp2_tips.png", "exp2_goals.png"):
                self.assertGreater((output / name).stat().st_size, 1000, name)
            # --doc writes the interest tables and marks into the doc's block, naming the command
            # that rewrites it without running anything.
            doc = output / "doc.md"
            doc.write_text(
                "<!-- generated: saggriac-interest, by x -->\nOLD\n"
                "<!-- end generated: saggriac-interest -->\n"
            )
            with contextlib.redirect_stdout(io.StringIO()):
                command.main([*argv, "--analyse-only", "--doc", str(doc)])
            text = doc.read_text()
            self.assertNotIn("OLD", text)
            self.assertIn("--analyse-only --doc", text)
            self.assertIn("| SAGG-RIAC | 2 |", text)
            self.assertIn("The paper's gain (SAGG-RIAC over SAGG-Random): **not testable**", text)


def _Run(method: str, seed: int, curve: list[dict], variant: str = "paper", **fields):
    """A constructed run of experiment 1 (a 50-unit arm) with the given evaluations."""
    spec = experiments.RunSpec(1, method, seed, budget=200, num_checkpoints=2, variant=variant)
    defaults = dict(
        config={"arm": {"total_length": 50.0}},
        wall_time_s=1.0,
        time_steps=200,
        final_reaching_errors=[],
        diagnostics={},
        tip_sample=[],
    )
    return experiments.BabblingRun(spec=spec, curve=curve, **(defaults | fields))


class TestCheckpointTable(unittest.TestCase):
    def test_rows_give_each_checkpoint_difference_and_welch_p(self):
        # Two groups of three runs whose values at checkpoint k are k * (1, 2, 4) and k * (2, 3, 7):
        # the difference of the means is -k * 5 / 3, and Welch's t on the same values gives p.
        first, second = (1.0, 2.0, 4.0), (2.0, 3.0, 7.0)
        runs = [
            _Run(method, seed, [{"time_step": 100 * k, "a": k * value, "b": -k * value}
                                for k in range(3)])
            for method, values in (("SAGG-RIAC", first), ("SAGG-Random", second))
            for seed, value in enumerate(values)
        ]  # fmt: skip
        lines = report.CheckpointTable(runs, "SAGG-RIAC", "SAGG-Random", ("a", "b"))
        self.assertEqual(len(lines), 2 + 2)  # header, rule, checkpoints 100 and 200
        self.assertIn("a: SAGG-RIAC - SAGG-Random (Welch p)", lines[0])
        p_value = stats.ttest_ind(first, second, equal_var=False).pvalue
        for k, line in ((1, lines[2]), (2, lines[3])):
            cells = [cell.strip() for cell in line.strip("|").split("|")]
            self.assertEqual(cells[0], str(100 * k))
            self.assertEqual(cells[1], f"{-k * 5 / 3:+.2f} ({p_value:.2g})")
            self.assertEqual(cells[2], f"{k * 5 / 3:+.2f} ({p_value:.2g})")

    def test_no_rows_with_fewer_than_two_runs_per_group(self):
        runs = [_Run("SAGG-RIAC", 0, [{"time_step": 0, "a": 1.0}])]
        runs += [_Run("SAGG-Random", seed, [{"time_step": 0, "a": 2.0}]) for seed in range(2)]
        self.assertEqual(report.CheckpointTable(runs, "SAGG-RIAC", "SAGG-Random", ("a",)), [])


class TestFigures(FigureTest):
    def test_new_figures_read_alone(self):
        rng = np.random.default_rng(0)
        groups = ["SAGG-RIAC", "SAGG-RIAC [stall]", "ACTUATOR-RIAC [set]"]
        runs = []
        for group, seed in itertools.product(groups, range(3)):
            method, _, variant = group.partition(" [")
            curve = [
                {"time_step": t, **{m: float(rng.uniform(1, 10)) for m in MEASURES}}
                for t in (0, 100, 200)
            ]
            runs.append(
                _Run(
                    method,
                    seed,
                    curve,
                    variant=variant.rstrip("]") or "paper",
                    tip_sample=rng.uniform(-50, 50, (100, 2)).tolist(),
                    diagnostics={"tip_spread": 9.0, "tip_coverage": 0.3, "drift_ratio": 1.1},
                )
            )
        self.assertReadable(figures.CurvesFigure(runs, groups, 2), "curves, 5 measures")
        self.assertReadable(figures.TipsFigure(runs, groups), "tips")
        statistics = report.Statistics(runs, groups)
        figure = figures.EffectsFigure(
            report._NoNan(statistics), 2, ["reaching_error", "prediction_error"]
        )
        self.assertReadable(figure, "effects")


if __name__ == "__main__":
    unittest.main()
