"""Issue 34's controls for SAGG-RIAC: the competence spread and the variance-only selector, the
interest's permutation null, and the marks made from them."""

import math
import unittest

import numpy as np

from mobee_drake.experiments import saggriac as experiments
from mobee_drake.experiments import saggriac_interest as interest
from mobee_drake.goal_babbling.competence import CompetenceSpread, Interest
from mobee_drake.goal_babbling.config import ConfigFromDict, ConfigToDict, InterestConfig
from mobee_drake.goal_babbling.interest_null import InterestNullP, LeafInterests
from mobee_drake.goal_babbling.regions import RegionTree


class TestSpreadAndSelector(unittest.TestCase):
    def test_spread_is_the_windows_standard_deviation(self):
        # The last 4 of [-1, -1, 0, -0.5, 0, -0.5]: sd of (0, -0.5, 0, -0.5) = 0.25.
        self.assertAlmostEqual(CompetenceSpread([-1, -1, 0, -0.5, 0, -0.5], 4), 0.25)
        # Blind to time order, unlike eq. 2.
        rising, shuffled = [-1, -1, 0, 0], [-1, 0, -1, 0]
        self.assertAlmostEqual(CompetenceSpread(rising, 4), CompetenceSpread(shuffled, 4))
        self.assertNotAlmostEqual(Interest(rising, 4), Interest(shuffled, 4))
        self.assertEqual(CompetenceSpread([-0.3], 20), 0.0)

    def test_the_tree_draws_by_the_configured_measure(self):
        values = [-1.0, 0.0] * 15  # no trend, the largest spread
        for measure, expected in (("progress", Interest(values[-20:], 20)), ("variance", 0.5)):
            tree = RegionTree([0.0], [1.0], InterestConfig(region_measure=measure))
            for value in values:
                tree.Add(np.array([0.5]), value)
            self.assertAlmostEqual(tree.leaves[0].interest, expected, msg=measure)
        # The children of a split are measured the same way.
        tree = RegionTree([0.0], [1.0], InterestConfig(region_measure="variance"))
        rng = np.random.default_rng(0)
        for k in range(51):
            tree.Add(rng.uniform([0.0], [1.0]), -float(k % 2))
        self.assertEqual(len(tree.leaves), 2)
        for leaf in tree.leaves:
            self.assertAlmostEqual(leaf.interest, CompetenceSpread(leaf.values, 20))

    def test_bad_measure_or_window_is_refused_in_one_line(self):
        for field, make in (
            ("region_measure", lambda: InterestConfig(region_measure="curiosity")),
            ("window", lambda: InterestConfig(window=1)),
        ):
            with self.assertRaisesRegex(ValueError, f"^{field}[^\n]*$"):
                make()
        data = ConfigToDict(experiments.MakeConfig(experiments.RunSpec(2, "SAGG-RIAC", 0, 9, 1)))
        data["interest"]["region_measure"] = "curiosity"
        with self.assertRaisesRegex(ValueError, "region_measure"):
            ConfigFromDict(data)

    def test_variants_change_only_their_field(self):
        reference = ConfigToDict(
            experiments.MakeConfig(experiments.RunSpec(2, "SAGG-RIAC", 0, 9, 1))
        )
        for variant, field, value in (
            ("variance-only", "region_measure", "variance"),
            ("window-10", "window", 10),
            ("window-80", "window", 80),
        ):
            config = ConfigToDict(
                experiments.MakeConfig(experiments.RunSpec(2, "SAGG-RIAC", 0, 9, 1, variant))
            )
            self.assertEqual(config["interest"][field], value)
            config["interest"][field] = reference["interest"][field]
            self.assertEqual(config, reference, variant)


class TestInterestNull(unittest.TestCase):
    def test_progress_beats_the_null_and_noise_does_not(self):
        rng = np.random.default_rng(0)
        # A step inside the window: 30 failures, then 10 successes.
        step = np.r_[np.full(30, -1.0), np.zeros(10)]
        self.assertLess(InterestNullP(step, 20, rng), 0.01)
        # No value differs: the observed order is as good as any.
        self.assertEqual(InterestNullP(np.full(40, -0.99), 20, rng), 1.0)
        self.assertEqual(InterestNullP(np.array([-0.5]), 20, rng), 1.0)

    def test_without_a_trend_the_p_value_is_uniform(self):
        # Competences without any time order: about 5 % of leaves under 0.05, whatever the
        # spread (the binomial sd of 400 draws at 0.05 is 0.011; allow 3 of them).
        rng = np.random.default_rng(1)
        for spread in (0.05, 0.4):
            p = [
                InterestNullP(rng.normal(-0.5, spread, 40), 20, rng, permutations=199)
                for _ in range(400)
            ]
            self.assertAlmostEqual(np.mean(np.array(p) < 0.05), 0.05, delta=0.033)

    def test_leaf_interests_describe_every_leaf(self):
        tree = RegionTree([0.0], [1.0], InterestConfig())
        rng = np.random.default_rng(2)
        for k in range(120):
            point = rng.uniform([0.0], [1.0])
            tree.Add(point, -1.0 if point[0] > 0.5 else -1.0 + k / 120)
        leaves = LeafInterests(tree, seed=0)
        self.assertEqual(len(leaves), len(tree.leaves))
        self.assertGreater(len(leaves), 1)
        for leaf, region in zip(leaves, tree.leaves, strict=True):
            self.assertEqual(leaf.goals, len(region.values))
            self.assertAlmostEqual(leaf.interest, Interest(region.values[-20:], 20))
            self.assertAlmostEqual(leaf.mean_competence, np.mean(region.values))
            self.assertEqual(leaf.low, region.low.tolist())
        # The leaves of constant competence have no interest and a p of 1.
        flat = [leaf for leaf in leaves if leaf.low[0] >= 0.5]
        self.assertTrue(flat)
        for leaf in flat:
            self.assertEqual((leaf.interest, leaf.null_p, leaf.spread), (0.0, 1.0, 0.0))


def _Run(method: str, seed: int, error: float, variant: str = "paper", **fields):
    """A constructed run of experiment 2 (a 50-unit arm, S' = [0, 150] x [-150, 150])."""
    spec = experiments.RunSpec(2, method, seed, budget=200, num_checkpoints=1, variant=variant)
    config = {
        "arm": {"total_length": 50.0},
        "goal_space_low": [0.0, -150.0],
        "goal_space_high": [150.0, 150.0],
    }
    defaults = dict(
        config=config,
        wall_time_s=1.0,
        time_steps=200,
        curve=[{"time_step": 200, "reaching_error": error}],
        final_reaching_errors=[],
        diagnostics={"unreachable_share": 0.8},
        tip_sample=[],
    )
    return experiments.BabblingRun(spec=spec, **(defaults | fields))


def _Groups(reference, random, variance) -> list:
    noise = (-0.2, -0.1, 0.0, 0.1, 0.2, 0.0)
    return [
        _Run(method, seed, mean + noise[seed], variant)
        for method, variant, mean in (
            ("SAGG-RIAC", "paper", reference),
            ("SAGG-Random", "paper", random),
            ("SAGG-RIAC", "variance-only", variance),
        )
        for seed in range(len(noise))
    ]


class TestMarks(unittest.TestCase):
    def test_mechanism_marks(self):
        for (reference, random, variance), mark in (
            ((2.0, 4.0, 2.1), "competence variance"),  # variance-only keeps the gain
            ((2.0, 4.0, 3.9), "learning progress"),  # variance-only loses it
            ((2.0, 4.0, 3.0), "undecided"),  # half of it: better than random, worse than RIAC
            ((4.0, 2.0, 2.0), "no gain to explain"),  # SAGG-Random is better
        ):
            found, evidence = interest.MechanismMark(_Groups(reference, random, variance))
            self.assertEqual(found, mark, evidence)
        _, evidence = interest.MechanismMark(_Groups(2.0, 4.0, 3.0))
        # The share of the gain kept: (4 - 3) / (4 - 2).
        self.assertIn("share of the gain kept by variance-only 0.50 [", evidence)
        self.assertEqual(interest.MechanismMark(_Groups(2.0, 4.0, 3.0)[:6])[0], "not testable")

    def test_goals_focus_mark(self):
        def Goals(inside: int, outside: int) -> list:
            # Goal rows (mode 1): `inside` at 30 units from the base, `outside` at 100.
            rows = [[k, 30.0, 0.0, -0.1, 1, k, k] for k in range(inside)]
            return rows + [[k, 100.0, 0.0, -1.0, 1, k, k] for k in range(outside)]

        def Runs(reference_inside: tuple, random_inside: tuple) -> list:
            return [
                _Run(method, seed, 1.0, goal_log=Goals(inside, 10 - inside))
                for method, insides in (
                    ("SAGG-RIAC", reference_inside),
                    ("SAGG-Random", random_inside),
                )
                for seed, inside in enumerate(insides)
            ]

        mark, evidence = interest.GoalsFocusMark(Runs((8, 7, 9, 8), (1, 0, 1, 2)))
        self.assertEqual(mark, "reproduced", evidence)
        self.assertIn("SAGG-RIAC 0.80 [", evidence)
        self.assertIn(f"uniform {math.pi * 2500 / 2 / 45000:.3f}", evidence)
        mark, _ = interest.GoalsFocusMark(Runs((2, 3, 2, 3), (1, 0, 1, 0)))
        self.assertEqual(mark, "more than uniform, not a focus")
        mark, _ = interest.GoalsFocusMark(Runs((1, 0, 1, 0), (1, 0, 1, 0)))
        self.assertEqual(mark, "not reproduced")

    def test_interest_table_counts_the_leaves(self):
        def Leaf(p: float, competence: float, spread: float, value: float) -> dict:
            return dict(
                low=[0.0], high=[1.0], goals=20, mean_competence=competence, spread=spread,
                interest=value, null_p=p,
            )  # fmt: skip

        leaves = [
            Leaf(0.01, -0.5, 0.3, 0.2),
            Leaf(0.5, -0.99, 0.01, 0.001),
            Leaf(0.2, -0.4, 0.2, 0.1),
            Leaf(0.3, -0.3, 0.1, 0.05),
        ]
        runs = [_Run("SAGG-RIAC", seed, 1.0, leaf_interests=leaves) for seed in range(2)]
        lines = interest.InterestTable(runs, ["SAGG-RIAC", "SAGG-Random"])
        self.assertEqual(len(lines), 3)  # header, rule, the one group with leaves
        cells = [cell.strip() for cell in lines[2].strip("|").split("|")]
        self.assertEqual(cells[:4], ["SAGG-RIAC", "2", "4.0", "2 of 8 (25.0 %)"])
        self.assertEqual(cells[4], "1.0, 0.0010")
        # The interests rise with the spreads in every run: rho = 1 (an interval of zero width).
        self.assertEqual(cells[5], "1.00 [1.00, 1.00]")


if __name__ == "__main__":
    unittest.main()
