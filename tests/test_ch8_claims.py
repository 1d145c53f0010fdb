"""The ch. 8 claims table from constructed result files (issue 33): each claim's mark follows
the constructed runs, paired by seed, under each setting."""

import re
import unittest

import numpy as np

from mobee_drake.experiments import ch8_claims as claims
from mobee_drake.experiments.ch8_reaching import ReachRun
from mobee_drake.experiments.statistics import ComparePaired, RatioOfMeans

STAGES = (100, 800, 1600)
PROBLEMS = 3
# Per strategy, a try's reach reward at each stage (intrinsic: worst first, best from 800).
REWARDS = {
    "random": {100: 0.5, 800: 0.5, 1600: 0.5},
    "greedy": {100: 0.5, 800: 0.55, 1600: 0.6},
    "intrinsic": {100: 0.2, 800: 0.8, 1600: 0.9},
}
HOURS = {"random": 3.0, "greedy": 1.0, "intrinsic": 1.0}
# Robot time of every run's evaluations (of its HOURS).
EVALUATION_HOURS = 0.5


def _Log(strategy: str, tries: int, rng) -> list[list[float]]:
    """Reaches 4-7 (4 transitions, 4 states): greedy on reach 4 alone, the others spread; random
    fails a transition before every reach."""
    log = []
    for t in range(tries):
        reach = 4 if strategy == "greedy" else 4 + int(rng.integers(4))
        if strategy == "random" and rng.random() < 0.8:
            log.append([t, t % PROBLEMS, 0, 0, 0, 0.0, -10.0, 0, 0, 0])
        log.append([t, t % PROBLEMS, reach, reach - 4, reach - 4, 1.0, 0.5, 0, 0, 0])
    return log


def _Run(strategy: str, seed: int, rule: str = "strict", shift: float = 0.0) -> dict:
    rng = np.random.default_rng([seed, len(strategy)])
    # The seed's shared luck (the same for every strategy), and the run's own.
    noise = 0.01 * (seed % 3) + 0.01 * rng.standard_normal()
    evaluations = {
        str(stage): [
            [
                dict(problem=p, actions=1, reward=REWARDS[strategy][stage] + noise + shift,
                     reach=4, failed_transitions=0)
                for p in range(PROBLEMS)
            ]
            for _ in range(2)
        ]
        for stage in STAGES
    }  # fmt: skip
    return ReachRun.FromJson(dict(
        settings=dict(
            strategy=strategy, seed=seed, problem_tries=STAGES[-1], stages=list(STAGES),
            evaluations=2, checkpoint_every=50, plateau_rule=rule, distance_unit=0.03,
            reach_force=300.0, mdp_seed=seed % 2,
        ),
        evaluations=evaluations,
        log=_Log(strategy, STAGES[-1], rng),
        simulated_seconds=3600.0 * HOURS[strategy] * (1 + 0.03 * rng.standard_normal()),
        evaluation_seconds=3600.0 * EVALUATION_HOURS,
        wall_seconds=1.0,
        penetrating_steps=0,
        num_transitions=4,
        num_states=4,
    ))  # fmt: skip


def _Marks(results) -> dict[tuple[int, str], str]:
    verdicts = claims.Verdicts(results)
    n = len(claims.CLAIMS)
    return {(i % n, v.setting): v.mark for i, v in enumerate(verdicts)}


class TestClaims(unittest.TestCase):
    def setUp(self):
        self.strict = [_Run(s, k) for s in REWARDS for k in range(6)]

    def test_marks_follow_the_constructed_runs(self):
        marks = _Marks(self.strict)
        setting = "unit0.03_force300"
        self.assertEqual(
            [marks[i, setting] for i in range(len(claims.CLAIMS))],
            [
                claims.REPRODUCED,  # least competent at 100 (the source's sum)
                claims.REPRODUCED,  # the same, reaches only
                claims.REPRODUCED,  # improves
                claims.REPRODUCED,  # more than the others
                claims.REPRODUCED,  # best from 800 (both sums)
                claims.REPRODUCED,
                claims.NOT_REPRODUCED,  # 3 times the robot time, not the source's 1.86
                claims.NOT_REPRODUCED,  # 5 times without the evaluations
                claims.REPRODUCED,  # random's failed transitions
                claims.REPRODUCED,  # greedy's lines
            ],
        )
        # The trend is tested against 0 within the MDPs, as the other claims are.
        trends = [claims._Trend(True, list(STAGES))(r) for r in self.strict
                  if r.strategy == "intrinsic"]  # fmt: skip
        blocks = [k % 2 for k in range(6)]
        expected = ComparePaired(trends, np.zeros(6), blocks)
        improves = claims.Verdicts(self.strict)[2].evidence
        self.assertEqual(improves, f"per doubling, minus 0 {expected.Text()}")
        self.assertIn("over 2 MDPs", improves)

    def test_a_setting_where_intrinsic_is_level_is_marked_on_its_own(self):
        level = [
            _Run(s, k, rule="arrival", shift=0.5 - REWARDS[s][100])
            for s in REWARDS
            for k in range(6)
        ]
        for run in level:  # every strategy 0.5 at every stage
            for evaluations in run.evaluations.values():
                for evaluation in evaluations:
                    for t in evaluation:
                        t["reward"] = 0.5 + 0.01 * (run.settings.seed % 3)
                        t["reward"] += 0.01 * np.sin(run.simulated_seconds)  # the run's own
        marks = _Marks(self.strict + level)
        arrival = "unit0.03_force300_rule-arrival"
        self.assertEqual(marks[0, arrival], claims.NOT_REPRODUCED)
        self.assertEqual(marks[4, arrival], claims.NOT_REPRODUCED)
        self.assertEqual(marks[0, "unit0.03_force300"], claims.REPRODUCED)
        table = claims.ClaimsTables(self.strict + level)
        row = next(line for line in table if line.startswith("| intrinsic motivation is the least"))
        self.assertTrue(row.endswith("| reproduced | not reproduced | unit0.03_force300 |"))

    def test_one_pair_per_mdp_is_tested_without_separating_the_mdps(self):
        # Seeds 0 and 1 on MDPs 0 and 1: no pair shares an MDP, so there is no error within
        # them; the plain paired t-test is used, and the evidence says so.
        few = [_Run(s, k) for s in REWARDS for k in range(2)]
        verdict = claims.Verdicts(few)[0]
        self.assertIn("(one pair per MDP, MDPs not separated)", verdict.evidence)
        self.assertNotIn("over 2 MDPs", verdict.evidence)

    def test_a_claim_with_nothing_to_compare_is_not_testable(self):
        alone = [r for r in self.strict if r.strategy == "intrinsic"]
        marks = _Marks(alone)
        for i in (0, 3, 4, 6, 7, 8, 9):
            self.assertEqual(marks[i, "unit0.03_force300"], claims.NOT_TESTABLE, i)

    def test_a_claim_against_the_others_needs_both(self):
        # A unit swept with greedy and intrinsic alone: intrinsic far ahead of greedy at every
        # stage is not "the best" (nor the least competent, nor more improving) of the three.
        pair = [_Run(s, k, shift=5.0 if s == "intrinsic" else 0.0)
                for s in ("greedy", "intrinsic") for k in range(6)]  # fmt: skip
        marks = _Marks(pair)
        for i in (0, 1, 3, 4, 5, 8):
            self.assertEqual(marks[i, "unit0.03_force300"], claims.NOT_TESTABLE, i)
        self.assertIn("both other strategies", claims.Verdicts(pair)[4].evidence)
        # Greedy's lines compare greedy with intrinsic alone: still marked.
        self.assertNotEqual(marks[9, "unit0.03_force300"], claims.NOT_TESTABLE)

    def test_the_ratio_and_a_missing_stage(self):
        verdicts = claims.Verdicts(self.strict)
        ratio = next(v for v in verdicts if v.claim.startswith("random exploration needs"))
        by = {s: {r.settings.seed: r for r in self.strict if r.settings.strategy == s}
              for s in REWARDS}  # fmt: skip
        random = [by["random"][k].simulated_seconds / 3600 for k in range(6)]
        others = [
            np.mean([by[s][k].simulated_seconds / 3600 for s in ("greedy", "intrinsic")])
            for k in range(6)
        ]
        value, low, high = RatioOfMeans(random, others, [k % 2 for k in range(6)])
        self.assertTrue(ratio.evidence.startswith(f"{value:.2f} times [{low:.2f}, {high:.2f}]"))
        self.assertGreater(low, claims.SOURCE_TIME_RATIO)
        # Random at the source's ratio of the others' time, run by run: reproduced.
        for run in self.strict:
            if run.settings.strategy == "random":
                seed = run.settings.seed
                run.simulated_seconds = claims.SOURCE_TIME_RATIO * np.mean(
                    [by[s][seed].simulated_seconds for s in ("greedy", "intrinsic")]
                )
        self.assertEqual(_Marks(self.strict)[6, "unit0.03_force300"], claims.REPRODUCED)
        late = [r for r in self.strict]
        for run in late:
            run.evaluations.pop(100)
        marks = _Marks(late)
        self.assertEqual(marks[0, "unit0.03_force300"], claims.NOT_TESTABLE)

    def test_the_ratio_says_which_tries_ran_out_of_actions(self):
        """Random's extra time may be tries that run out of actions (no reach): the evidence
        gives each strategy's share of them, from the logs."""
        by = {s: {r.settings.seed: r for r in self.strict if r.settings.strategy == s}
              for s in REWARDS}  # fmt: skip
        for run in by["random"].values():  # every fourth try loses its reach
            run.log = [row for row in run.log if not (row[2] >= 4 and row[0] % 4 == 0)]
        _, evidence = claims.RandomTakesLonger(by)
        self.assertTrue(evidence.endswith("random 25.0%, greedy 0.0%, intrinsic 0.0%"), evidence)

    def test_the_ratio_of_the_exploration_alone(self):
        """The same ratio without each run's evaluation time, over the seeds whose runs all
        timed their evaluations (the ratio with them over every seed)."""
        by = {s: {r.settings.seed: r for r in self.strict if r.settings.strategy == s}
              for s in REWARDS}  # fmt: skip

        def Exploration(run):
            return (run.simulated_seconds - run.evaluation_seconds) / 3600

        random = [Exploration(by["random"][k]) for k in range(6)]
        others = [
            np.mean([Exploration(by[s][k]) for s in ("greedy", "intrinsic")]) for k in range(6)
        ]
        value, low, high = RatioOfMeans(random, others, [k % 2 for k in range(6)])
        mark, evidence = claims.RandomTakesLonger(by, exploration_only=True)
        self.assertEqual(mark, claims.NOT_REPRODUCED)
        self.assertTrue(evidence.startswith(f"{value:.2f} times [{low:.2f}, {high:.2f}]"))
        self.assertAlmostEqual(value, 5.0, delta=0.3)  # (2.5 h against 0.5 h)
        # Random's exploration at the source's ratio of the others', its evaluations as theirs:
        # reproduced without the evaluations, not with them.
        for seed, run in by["random"].items():
            mean = np.mean([Exploration(by[s][seed]) for s in ("greedy", "intrinsic")])
            run.simulated_seconds = run.evaluation_seconds + 3600 * claims.SOURCE_TIME_RATIO * mean
        self.assertEqual(claims.RandomTakesLonger(by, True)[0], claims.REPRODUCED)
        self.assertEqual(claims.RandomTakesLonger(by)[0], claims.NOT_REPRODUCED)
        # Runs from before the evaluations were timed: their seeds are left out of this ratio.
        by["greedy"][3].evaluation_seconds = None
        by["random"][3].simulated_seconds *= 10  # (would move the ratio, were seed 3 counted)
        seeds = [0, 1, 2, 4, 5]
        random = [Exploration(by["random"][k]) for k in seeds]
        others = [np.mean([Exploration(by[s][k]) for s in ("greedy", "intrinsic")]) for k in seeds]
        value, low, high = RatioOfMeans(random, others, [k % 2 for k in seeds])
        mark, evidence = claims.RandomTakesLonger(by, exploration_only=True)
        self.assertEqual(mark, claims.REPRODUCED)
        self.assertTrue(evidence.startswith(f"{value:.2f} times [{low:.2f}, {high:.2f}]"))
        self.assertIn("over 5 seeds in 2 MDPs, leaving out 1 with untimed runs", evidence)
        for k in (0, 1, 2, 4):
            by["intrinsic"][k].evaluation_seconds = None
        self.assertEqual(claims.RandomTakesLonger(by, True)[0], claims.NOT_TESTABLE)

    def test_the_report_gives_the_evaluations_robot_time(self):
        from mobee_drake.experiments.ch8_report import _EffortSection

        by_strategy = {s: [r for r in self.strict if r.strategy == s] for s in REWARDS}
        hours = sum(r.simulated_seconds for r in by_strategy["random"]) / 3600
        evaluation = 6 * EVALUATION_HOURS
        (row,) = [line for line in _EffortSection(by_strategy) if line.startswith("| random")]
        self.assertIn(f"| {hours:.1f} | {evaluation:.1f} ({evaluation / hours:.0%}) |", row)
        by_strategy["random"][2].evaluation_seconds = None  # (a run from before the timing)
        (row,) = [line for line in _EffortSection(by_strategy) if line.startswith("| random")]
        self.assertIn(f"| {hours:.1f} | - |", row)

    def test_parameter_tuning_across_distance_units(self):
        # Greedy loses 0.3 per try in the coarser unit, intrinsic keeps its level.
        def Swept(unit, greedy_shift):
            runs = []
            for strategy in ("greedy", "intrinsic"):
                for k in range(4):
                    run = _Run(strategy, k, shift=greedy_shift if strategy == "greedy" else 0.0)
                    run.settings.distance_unit = unit
                    runs.append(run)
            return runs

        results = Swept(0.03, 0.0) + Swept(0.1, -0.3)
        ((group, mark, evidence),) = claims.LessTuning(results)
        self.assertEqual((group, mark), ("force300", claims.REPRODUCED), evidence)
        # The same seed's runs in the two units differ by the shift alone: the units' means lie
        # 0.3 x 27 problems apart for greedy, not at all for intrinsic.
        spread = re.search(
            r"mean sums \(not marked\): greedy ([\d.]+), intrinsic ([\d.]+), greedy minus "
            r"intrinsic \+([\d.]+) \[\+([\d.]+), \+([\d.]+)\]",
            evidence,
        )
        greedy, intrinsic, difference, low, high = map(float, spread.groups())
        np.testing.assert_allclose(
            [greedy, intrinsic, difference], [0.3 * PROBLEMS, 0, 0.3 * PROBLEMS]
        )
        self.assertTrue(0 < low <= difference <= high, evidence)
        # Each unit's mean: greedy's 0.3 x 27 lower in the coarser unit, intrinsic's the same.
        means = re.search(
            r"mean sums, greedy / intrinsic: 0.03 m ([-+][\d.]+) / ([-+][\d.]+), "
            r"0.1 m ([-+][\d.]+) / ([-+][\d.]+)$",
            evidence,
        )
        greedy_fine, intrinsic_fine, greedy_coarse, intrinsic_coarse = map(float, means.groups())
        self.assertAlmostEqual(greedy_coarse - greedy_fine, -0.3 * PROBLEMS, places=1)
        self.assertAlmostEqual(intrinsic_coarse, intrinsic_fine, places=2)
        reversed_ = (
            Swept(0.03, 0.0)
            + [r for r in Swept(0.1, 0.0) if r.strategy == "greedy"]
            + [_Run("intrinsic", k, shift=-0.3) for k in range(4)]
        )
        for run in reversed_[-4:]:
            run.settings.distance_unit = 0.1
        self.assertEqual(claims.LessTuning(reversed_)[0][1], claims.NOT_REPRODUCED)
        self.assertEqual(claims.LessTuning(self.strict)[0][1], claims.NOT_TESTABLE)
        # Runs of another force are another group, not a unit's effect.
        other = Swept(0.03, 0.0)
        for run in other:
            run.settings.reach_force = 100.0
        groups = claims.LessTuning(results + other)
        self.assertEqual(
            [g[:2] for g in groups],
            [("force300", claims.REPRODUCED), ("force100", claims.NOT_TESTABLE)],
        )
        table = claims.ClaimsTables(self.strict)
        self.assertTrue(any(line.startswith("| intrinsic motivation alleviates") for line in table))


if __name__ == "__main__":
    unittest.main()
