"""Reward predictors of ch. 8 against their closed forms (eq. 8.1-8.7)."""

import contextlib
import dataclasses
import io
import itertools
import json
import pathlib
import tempfile
import unittest
from unittest import mock

import numpy as np

from mobee_drake.reaching.predictors import (
    FAILED_TRANSITION_REWARD,
    PREDICTORS,
    PredictorConfig,
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

    def test_predictions_of_many_are_each_ones(self):
        # Empty and recorded histories of transitions and reaches, both predictors.
        for kind in PREDICTORS:
            h = RewardHistories([False, True, False, True], PredictorConfig(kind))
            h.Record(2, [1, 0, 0], 0.0, FAILED_TRANSITION_REWARD)
            h.Record(3, [0, 1, 0], 0.9, 0.5)
            target = [0.5, 0.5, 0]
            each = [h.Predict(sa, target) for sa in range(4)]
            self.assertEqual(h.PredictEach(range(4), target).tolist(), each)
            self.assertEqual(each[:2], [0.0, 1.0])

    def test_rewards(self):
        self.assertEqual(ReachReward([0, 0, 0], [0, 0, 0]), 1.0)  # eq. 8.4
        self.assertAlmostEqual(ReachReward([0.3, 0, 0.4], [0, 0, 0]), 1 / 1.5)
        self.assertEqual(TransitionReward(0.2, 0.3), 0.0)
        self.assertEqual(TransitionReward(0.3, 0.3), FAILED_TRANSITION_REWARD)
        # Equal but for the rounding of a sum taken in another order: no climb.
        self.assertEqual(TransitionReward(0.3, 0.1 + 0.2), FAILED_TRANSITION_REWARD)
        self.assertGreater(0.1 + 0.2, 0.3)
        self.assertEqual(TransitionReward(0.3, 0.3 + 1e-9), 0.0)
        self.assertEqual(TransitionReward(-5.0, -5.0 + 5e-13), FAILED_TRANSITION_REWARD)
        self.assertEqual(TransitionReward(-5.0, -5.0 + 2e-12), 0.0)

    def test_distance_unit(self):
        from mobee_drake.reaching.predictors import PredictorConfig

        # In centimetres a 5 cm miss is worth 1/6, not 1/1.05 (eq. 8.4).
        self.assertAlmostEqual(ReachReward([0.05, 0, 0], [0, 0, 0], unit=0.01), 1 / 6)
        h = RewardHistories([True], PredictorConfig(distance_unit=0.01))
        h.Record(0, [0, 0, 0], 1.0, 0.5)
        w = 1 / (1 + 3.0)  # a target 3 cm away
        self.assertAlmostEqual(h.Predict(0, [0, 0.03, 0]), (1 + w * 0.5) / (1 + w))  # eq. 8.5
        with self.assertRaisesRegex(ValueError, "distance_unit must be > 0, got 0"):
            RewardHistories([True], PredictorConfig(distance_unit=0.0))


if __name__ == "__main__":
    unittest.main()


class FakeRobot:
    """A robot on a 2 x 2 lattice: transitions reach their goal unless the edge is blocked (by
    the robot's own body, or by an ``obstacles`` edge, where the fields feel the target), and a
    reach from state s puts the palm at ``palms[s]``."""

    def __init__(self, space, palms, blocked=(), state=0, obstacles=()):
        self.space, self.palms, self.blocked, self.state = space, palms, set(blocked), state
        self.obstacles = set(obstacles)
        self.reaches, self.felt = 0, False

    def SetProblem(self, target):
        self.target = target

    def EndProblem(self):
        self.target = None

    def State(self):
        return self.state

    def Transition(self, goal):
        edge = (self.state, goal)
        self.felt = edge in self.obstacles
        if edge not in self.blocked | self.obstacles:
            self.state = goal
        return self.state

    def Reach(self, target):
        self.reaches, self.felt = self.reaches + 1, False
        return self.palms[self.state]

    def FeltObject(self):
        return self.felt

    def MarkerPosition(self):
        return self.palms[self.state]

    def LearningFrame(self, target):
        return target


def _Learner(
    strategy="greedy",
    seed=0,
    targets=None,
    max_actions=10,
    predictor="weighted",
    learn_mdp=False,
    goals=None,
    distance_unit=1.0,
):
    from mobee_drake.planning.state_space import Lattice
    from mobee_drake.reaching.learner import ReachLearner, ReachLearningConfig
    from mobee_drake.reaching.predictors import PredictorConfig

    space = Lattice([0.25, 0.75], 2)  # states 0=(0,0) 1=(0,1) 2=(1,0) 3=(1,1)
    T = np.zeros((space.num_state_actions, space.num_states))
    T[np.arange(space.num_state_actions), space.action_goal] = 1.0
    targets = (
        np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
        if targets is None
        else targets
    )
    return space, ReachLearner(
        space,
        T,
        targets,
        ReachLearningConfig(
            strategy=strategy,
            seed=seed,
            max_actions=max_actions,
            predictor=PredictorConfig(predictor, distance_unit=distance_unit),
            learn_mdp=learn_mdp,
            **({} if goals is None else dict(goals=goals)),
        ),
    )


PALMS = np.array([[0.3, 0, 0], [0.2, 0, 0], [0.1, 0, 0], [0.0, 0, 0]], dtype=float)


class TestReachLearner(unittest.TestCase):
    def test_source_numbering_of_reaches(self):
        from mobee_drake.planning.state_space import Lattice
        from mobee_drake.reaching.learner import ReachLearner

        space = Lattice([0.25, 0.5, 0.75], 4)
        learner = ReachLearner(space, np.zeros((432, 81)), np.zeros((1, 3)))
        self.assertEqual(learner.Reach(57), 489)
        self.assertEqual(learner.Reach(77), 509)
        self.assertEqual(learner.num_state_actions, 513)

    def test_a_reach_ends_the_policy(self):
        space, learner = _Learner()
        rewards = np.zeros(learner.num_state_actions)
        rewards[learner.Reach(3)] = 1.0
        q, v = learner.Values(rewards)
        gamma = learner.config.gamma
        # V(3) = 1 (the reach is terminal, not repeated), one step away gamma, two gamma^2.
        np.testing.assert_allclose(v, [gamma**2, gamma, gamma, 1.0], atol=1e-3)
        self.assertAlmostEqual(q[learner.Reach(3)], 1.0)

    def test_fresh_optimist_reaches_at_once(self):
        # Every reach predicts 1 (eq. 8.5, e_1 = 1) and a move is discounted: reach from here.
        space, learner = _Learner()
        robot = FakeRobot(space, PALMS, state=2)
        result = learner.Explore(robot)
        self.assertEqual((result.actions, result.reach), (1, learner.Reach(2)))
        target = learner.targets[result.problem]
        self.assertAlmostEqual(result.reward, 1 / (1 + np.linalg.norm(PALMS[2] - target)))
        np.testing.assert_array_equal(learner.histories.History(learner.Reach(2))[1], [1.0])

    def test_failed_transition_is_penalised_and_avoided(self):
        space, learner = _Learner()
        target = learner.targets[0]
        for s in range(3):  # Bad reaches from states 0-2 for this target; state 3 untried.
            for _ in range(20):
                learner.histories.Record(learner.Reach(s), target, 1.0, 0.1)
        robot = FakeRobot(space, PALMS, blocked={(0, 1)}, state=0)
        learner.problem_tries[1:] = 1  # problem 0 is the least tried
        result = learner.Explore(robot)
        self.assertEqual(result.reach, learner.Reach(3))
        tried = [row[2] for row in learner.log]
        blocked = int(np.flatnonzero((space.action_state == 0) & (space.action_goal == 1))[0])
        self.assertLessEqual(tried.count(blocked), 1)
        self.assertEqual(result.failed_transitions, tried.count(blocked))
        if blocked in tried:
            self.assertEqual(learner.histories.History(blocked)[2].tolist(), [-10.0])
            self.assertEqual(result.actions, 4)
        else:
            self.assertEqual(result.actions, 3)

    def test_timeout(self):
        space, learner = _Learner(max_actions=1)
        target = learner.targets[0]
        for _ in range(20):
            learner.histories.Record(learner.Reach(0), target, 1.0, 0.1)
        learner.problem_tries[1:] = 1
        result = learner.Explore(FakeRobot(space, PALMS, state=0))
        self.assertIsNone(result.reward)
        self.assertEqual((result.actions, result.reach), (1, -1))

    def test_least_tried_problems_first(self):
        for strategy in ("random", "greedy", "intrinsic"):
            space, learner = _Learner(strategy)
            robot = FakeRobot(space, PALMS)
            for round_ in range(1, 4):
                for _ in range(3):
                    learner.Explore(robot)
                np.testing.assert_array_equal(learner.problem_tries, [round_] * 3)

    def test_evaluation_leaves_the_learner_alone(self):
        space, learner = _Learner("intrinsic")
        robot = FakeRobot(space, PALMS)
        for _ in range(6):
            learner.Explore(robot)
        before = (
            list(learner.log),
            learner.problem_tries.copy(),
            learner.rng.bit_generator.state,
            [learner.histories.History(sa)[2].copy() for sa in range(learner.num_state_actions)],
        )
        results = learner.Evaluate(robot, seed=7)
        self.assertEqual(sorted(r.problem for r in results), [0, 1, 2])
        self.assertTrue(all(r.reward is None or 0 < r.reward <= 1 for r in results))
        self.assertEqual(learner.log, before[0])
        np.testing.assert_array_equal(learner.problem_tries, before[1])
        self.assertEqual(learner.rng.bit_generator.state, before[2])
        for sa, rewards in enumerate(before[3]):
            np.testing.assert_array_equal(learner.histories.History(sa)[2], rewards)

    def test_a_try_that_runs_out_of_actions_ends_its_problem(self):
        """One action a try, random's drawn reach elsewhere: the try runs out of actions, and
        its target leaves the world as a reach's does (an evaluation's walk is not to go around
        it)."""
        space, learner = _Learner("random", max_actions=1)
        robot = FakeRobot(space, PALMS)
        timed_out = 0
        for _ in range(6):
            if learner.Explore(robot).reward is None:
                timed_out += 1
                self.assertIsNone(robot.target)
        self.assertGreater(timed_out, 0)

    def test_the_walk_to_the_start_takes_transitions_only(self):
        """An evaluation walks to its start state by transitions. Where no transition's value
        leads there (this MDP's moves all stay put, so from the far corner every move and the
        reach are worth 0), ties drawn at random (``random-tie``) still never pick the reach."""
        from mobee_drake.reaching.learner import ReachLearner, ReachLearningConfig

        space, _ = _Learner()
        stays = np.zeros((space.num_state_actions, space.num_states))
        stays[np.arange(space.num_state_actions), space.action_state] = 1.0
        config = ReachLearningConfig(strategy="greedy", plateau_rule="random-tie")
        learner = ReachLearner(space, stays, PALMS[:1], config)
        for seed in range(20):
            robot = FakeRobot(space, PALMS, state=3 - int(np.random.default_rng(seed).integers(4)))
            learner.Evaluate(robot, seed=seed)  # (an IndexError if the walk drew the reach)

    def test_exact_resume(self):
        for strategy, predictor, learn_mdp in [
            ("random", "weighted", False),
            ("greedy", "weighted", False),
            ("intrinsic", "weighted", False),
            ("intrinsic", "gaussian_process", False),
            ("random", "weighted", True),
            ("intrinsic", "weighted", True),
            ("goal_babbling", "weighted", False),
        ]:
            space, whole = _Learner(strategy, seed=3, predictor=predictor, learn_mdp=learn_mdp)

            def Robot(space=space):
                return FakeRobot(space, PALMS, blocked={(0, 2), (3, 1)}, obstacles={(1, 3)})

            robot = Robot()
            for _ in range(12):
                whole.Explore(robot)
            _, first = _Learner(strategy, seed=3, predictor=predictor, learn_mdp=learn_mdp)
            robot = Robot()
            for _ in range(6):
                first.Explore(robot)
            arrays, data = first.ToArrays()
            _, resumed = _Learner(strategy, seed=3, predictor=predictor, learn_mdp=learn_mdp)
            resumed.LoadArrays(arrays, data)
            for _ in range(6):
                resumed.Explore(robot)
            self.assertEqual(resumed.log, whole.log)
            np.testing.assert_array_equal(resumed.model.counts, whole.model.counts)
            with self.assertRaisesRegex(ValueError, "configuration"):
                _Learner("random" if strategy != "random" else "greedy", seed=3)[1].LoadArrays(
                    arrays, data
                )

    def test_a_save_older_than_an_option_resumes_at_its_default(self):
        """A checkpoint written before an option existed resumes when the option is at its
        default, and is refused when it is not (a different configuration)."""
        space, first = _Learner("intrinsic", seed=3)
        robot = FakeRobot(space, PALMS, blocked={(0, 2)}, obstacles={(1, 3)})
        for _ in range(3):
            first.Explore(robot)
        arrays, data = first.ToArrays()
        older = json.loads(json.dumps(data))
        del older["config"]["goals"]["interest"]["region_measure"]  # (added by issue 34)
        del older["config"]["plateau_rule"]
        _, resumed = _Learner("intrinsic", seed=3)
        resumed.LoadArrays(arrays, older)
        self.assertEqual(resumed.log, first.log)
        _, other = _Learner("intrinsic", seed=3)
        other.config.plateau_rule = "arrival"
        with self.assertRaisesRegex(ValueError, "configuration"):
            other.LoadArrays(arrays, older)

    def test_learned_mdp_tells_model_updates_from_penalties(self):
        # Ch. 9.4.1: from state 0, the edge to 1 is blocked by the robot's own body (a model
        # update, no penalty), the edge to 2 by the target (felt: -10, the model untouched).
        space, learner = _Learner(targets=np.zeros((1, 3)), learn_mdp=True)
        target = learner.targets[0]
        for s in range(3):  # Bad reaches from states 0-2; state 3 untried (optimistic).
            for _ in range(5):
                learner.histories.Record(learner.Reach(s), target, 1.0, 0.1)
        robot = FakeRobot(space, PALMS, blocked={(0, 1)}, obstacles={(0, 2)})
        initial = learner.model.counts.copy()
        for _ in range(4):
            learner.Explore(robot)
        edge = {
            g: int(np.flatnonzero((space.action_state == 0) & (space.action_goal == g))[0])
            for g in (1, 2)
        }
        tried = [row[2] for row in learner.log]
        n1, n2 = tried.count(edge[1]), tried.count(edge[2])
        self.assertGreaterEqual(min(n1, n2), 1)
        # Self-blocked: rewards 0; the counts learned "stays in 0" n1 times (a new bin starts at
        # 1, Alg. 6), so T(0 -> 1) fell from 1 to 1 / (2 + n1).
        self.assertEqual(learner.histories.History(edge[1])[2].tolist(), [0.0] * n1)
        expected = initial[edge[1]].copy()
        expected[0] = 1 + n1
        np.testing.assert_array_equal(learner.model.counts[edge[1]], expected)
        # Rewarding that edge alone: V(0) = 1 + gamma (p_stay V(0) + p_go V(1)), V(1) = gamma V(0).
        _, v = learner.Values(np.eye(learner.num_state_actions)[edge[1]])
        gamma, p_go = learner.config.gamma, 1 / (2 + n1)
        self.assertAlmostEqual(v[0], 1 / (1 - gamma * (1 - p_go) - gamma**2 * p_go), delta=0.01)
        # Blocked by the target: penalised, model unchanged; nothing else was learned.
        self.assertEqual(learner.histories.History(edge[2])[2].tolist(), [-10.0] * n2)
        changed = np.flatnonzero(np.any(learner.model.counts != initial, axis=1))
        self.assertEqual(changed.tolist(), [edge[1]])
        # Evaluations do not teach the model.
        counts = learner.model.counts.copy()
        learner.Evaluate(FakeRobot(space, PALMS, blocked={(0, 1), (2, 3)}), seed=1)
        np.testing.assert_array_equal(learner.model.counts, counts)

    def test_goal_babbling(self):
        from mobee_drake.goal_babbling.competence import Competence
        from mobee_drake.goal_babbling.config import InterestConfig
        from mobee_drake.reaching.goals import ReachGoalsConfig

        # Small regions so the goal space splits within the test (g_max 6, zeta 4).
        interest = InterestConfig(max_region_goals=6, window=4, min_child_goals=2)
        space, learner = _Learner(
            "goal_babbling", seed=2, goals=ReachGoalsConfig(interest, margin=0.1)
        )
        robot = FakeRobot(space, PALMS, state=1)
        starts = []
        for _ in range(40):
            starts.append(robot.MarkerPosition())
            learner.Explore(robot)
        babbler, log = learner.babbler, np.array(learner.log)
        goals = np.array(babbler.goals)
        # Goals in the targets' box grown by the margin; each counted on its nearest problem.
        low, high = learner.targets.min(axis=0) - 0.1, learner.targets.max(axis=0) + 0.1
        self.assertTrue(np.all((goals >= low) & (goals <= high)))
        nearest = np.argmin(np.linalg.norm(goals[:, None] - learner.targets[None], axis=2), axis=1)
        np.testing.assert_array_equal(learner.problem_tries, np.bincount(nearest, minlength=3))
        # Every try is planned for its goal; its competence is eq. 7 clipped (Sec. II-D-1), with
        # x_start the palm where the try began.
        reaches = log[log[:, 2] >= learner.num_transitions]
        self.assertEqual(len(reaches), 40)
        np.testing.assert_array_equal(reaches[:, 7:], goals)
        for goal, start, reach, competence in zip(goals, starts, reaches, babbler.competences):
            final = PALMS[int(reach[3])]
            cost = -np.linalg.norm(goal - final) / np.linalg.norm(goal - start)
            self.assertAlmostEqual(competence, Competence(cost, -0.05, -1.0))
        self.assertGreater(len(babbler.tree.leaves), 1)
        # A try without a reach gets min_C.
        _, timid = _Learner("goal_babbling", max_actions=1)
        for _ in range(20):
            timid.histories.Record(timid.Reach(0), np.zeros(3), 1.0, 0.01)
        timid.babbler.Select = lambda rng: np.zeros(3)
        self.assertIsNone(timid.Explore(FakeRobot(space, PALMS, state=0)).reward)
        self.assertEqual(timid.babbler.competences, [-1.0])

    def test_rewards_in_the_distance_unit(self):
        # A fresh greedy learner reaches at once from state 0, its palm 30 cm from the target.
        for unit, reward in ((1.0, 1 / 1.3), (0.01, 1 / 31)):
            space, learner = _Learner(targets=np.zeros((1, 3)), distance_unit=unit)
            result = learner.Explore(FakeRobot(space, PALMS, state=0))
            self.assertAlmostEqual(result.reward, reward)

    def test_bad_configuration(self):
        with self.assertRaisesRegex(ValueError, "unknown reach-learning strategy 'curious'"):
            _Learner("curious")


class TestGaussianProcessPredictor(unittest.TestCase):
    def setUp(self):
        from mobee_drake.reaching.predictors import PredictorConfig

        self.config = PredictorConfig("gaussian_process", length_scale=0.1, noise_ratio=0.25)
        self.histories = RewardHistories([False, True], self.config)

    def test_closed_forms(self):
        h, rho = self.histories, 0.25
        self.assertEqual(h.Predict(1, [0, 0, 0]), 1.0)  # the prior: optimistic
        h.Record(1, [0, 0, 0], 1.0, 0.6)
        # One record: prior + (v - prior) k / (1 + rho).
        self.assertAlmostEqual(h.Predict(1, [0, 0, 0]), 1 - 0.4 / (1 + rho))
        d = 0.05
        self.assertAlmostEqual(
            h.Predict(1, [d, 0, 0]), 1 - 0.4 * np.exp(-(d**2) / (2 * 0.1**2)) / (1 + rho)
        )
        # Far from every record the prediction returns to the prior (eq. 8.5 approaches it only
        # as 1 / distance).
        self.assertAlmostEqual(h.Predict(1, [2, 0, 0]), 1.0, places=9)
        # Two records at one target pool: their mean, with half the noise.
        h.Record(1, [0, 0, 0], 0.9, 0.8)
        self.assertAlmostEqual(h.Predict(1, [0, 0, 0]), 1 - 0.3 / (1 + rho / 2))
        # The intrinsic prediction fits the errors e - r = 0.4, 0.1 the same way.
        self.assertAlmostEqual(h.PredictIntrinsic(1, [0, 0, 0]), 1 - 0.75 / (1 + rho / 2))
        # Transitions: prior 0.
        h.Record(0, [0, 0, 0], 0.0, FAILED_TRANSITION_REWARD)
        self.assertAlmostEqual(h.Predict(0, [0, 0, 0]), -10 / (1 + rho))

    def test_local_unlike_the_weighted_average(self):
        # A good reach at one target and a bad one 30 cm away: the GP keeps them apart, eq. 8.5
        # blurs them (ch. 8.5).
        weighted = RewardHistories([True])
        for h in (self.histories, weighted):
            for _ in range(10):
                h.Record(0 if h is weighted else 1, [0, 0, 0], 1.0, 0.95)
                h.Record(0 if h is weighted else 1, [0.3, 0, 0], 1.0, 0.5)
        self.assertGreater(self.histories.Predict(1, [0, 0, 0]), 0.9)
        self.assertLess(self.histories.Predict(1, [0.3, 0, 0]), 0.6)
        self.assertLess(weighted.Predict(0, [0, 0, 0]), 0.9)
        self.assertGreater(weighted.Predict(0, [0.3, 0, 0]), 0.6)

    def test_bad_config(self):
        from mobee_drake.reaching.predictors import PredictorConfig

        with self.assertRaisesRegex(ValueError, "unknown reward predictor 'net'"):
            RewardHistories([True], PredictorConfig("net"))
        with self.assertRaisesRegex(ValueError, "length_scale"):
            RewardHistories([True], PredictorConfig("gaussian_process", length_scale=0.0))


class TestDiscounting(unittest.TestCase):
    """Issue 23, point 5: when a greedy planner moves, closed form against value iteration."""

    def test_closed_form_against_value_iteration(self):
        from mobee_drake.planning.state_space import Lattice
        from mobee_drake.reaching.discounting import (
            MoveThreshold,
            PathRatio,
            StepRatio,
            Steps,
        )
        from mobee_drake.reaching.learner import ReachLearner, ReachLearningConfig

        # The rank-3 lattice of ch. 8 with every transition succeeding with p, else staying.
        gamma, p = 0.9, 0.81
        space = Lattice([0.25, 0.5, 0.75], 4)
        T = np.zeros((space.num_state_actions, space.num_states))
        rows = np.arange(space.num_state_actions)
        T[rows, space.action_goal] = p
        T[rows, space.action_state] = 1 - p
        learner = ReachLearner(
            space, T, np.zeros((1, 3)), ReachLearningConfig(gamma=gamma, delta=1e-10)
        )
        self.assertAlmostEqual(StepRatio(gamma, p), (1 - 0.9 * 0.19) / (0.9 * 0.81))
        self.assertAlmostEqual(StepRatio(gamma, p), 1.137, places=3)
        steps = Steps(learner, [57])
        self.assertEqual(steps[57], 0)
        for d in (1, 2, 3, 4):
            start = int(np.flatnonzero(steps == d)[0])
            self.assertAlmostEqual(
                MoveThreshold(learner, start, [57]), PathRatio(gamma, p, d), delta=1e-5
            )
        # Never worth it from state 57 itself; p = 1 leaves only the discount.
        self.assertAlmostEqual(StepRatio(gamma, 1.0), 1 / gamma)

    def test_predicted_spread(self):
        from mobee_drake.reaching.discounting import PredictedSpread

        # Fresh: every reach predicts 1 (eq. 8.5), nobody moves.
        _, learner = _Learner(targets=np.zeros((1, 3)))
        ratios, moving = PredictedSpread(learner)
        np.testing.assert_array_equal(ratios, [1.0])
        np.testing.assert_array_equal(moving, [0.0])
        # A reach of state 0 that paid 0.5 at the target predicts (1 + 0.5) / 2 = 0.75 there;
        # its neighbours' reaches (worth 0.9 from state 0, transitions never fail) beat it.
        learner.histories.Record(learner.Reach(0), np.zeros(3), 1.0, 0.5)
        ratios, moving = PredictedSpread(learner)
        np.testing.assert_allclose(ratios, [1 / 0.75])
        np.testing.assert_allclose(moving, [1 / 4])

    def test_reward_ratio_of_misses(self):
        from mobee_drake.reaching.discounting import RewardRatio

        self.assertAlmostEqual(RewardRatio(0.01, 0.33, 1.0), 1.33 / 1.01)  # metres: 1.32
        self.assertAlmostEqual(RewardRatio(0.01, 0.33, 0.01), 34 / 2)  # centimetres: 17
        with self.assertRaisesRegex(ValueError, "need 0 <= miss_min <= miss_max"):
            RewardRatio(0.3, 0.1, 1.0)
        from mobee_drake.reaching.discounting import StepRatio

        with self.assertRaisesRegex(ValueError, "need 0 < gamma < 1 and 0 < p <= 1"):
            StepRatio(0.9, 0.0)

    def test_best_over_own(self):
        from mobee_drake.reaching.discounting import BestOverOwn

        # Problem 0: misses 0.1 and 0.3 m; in metres rewards 1/1.1 and 1/1.3, in units of
        # 0.1 m 1/2 and 1/4. Problem 1: the second state was not reached.
        misses = np.array([[0.1, 0.2], [0.3, np.nan]])
        np.testing.assert_allclose(BestOverOwn(misses, 1.0), [[1.0, 1.0], [1.3 / 1.1, np.nan]])
        np.testing.assert_allclose(BestOverOwn(misses, 0.1), [[1.0, 1.0], [2.0, np.nan]])
        with self.assertRaisesRegex(ValueError, "need misses >= 0"):
            BestOverOwn([[-0.1]], 1.0)

    def test_discounting_command_names_a_missing_model(self):
        from mobee_drake.experiments.ch8_discounting import main

        stderr = io.StringIO()
        with contextlib.redirect_stderr(stderr), self.assertRaises(SystemExit) as exit:
            main(["--model", "/nonexistent/model"])
        self.assertEqual(exit.exception.code, 2)
        self.assertIn(
            "--model: /nonexistent/model/right_arm.npz: no saved model", stderr.getvalue()
        )

    def test_reach_misses_on_the_robot(self):
        from mobee_drake.experiments.ch8_discounting import ReachMisses
        from mobee_drake.planning.state_space import Lattice
        from mobee_drake.reaching.targets import LoadTargetGrid

        # The same full reach (300 N) for the grid's first target from the lattice's centre
        # state and from its corner: the attractor holds the arm at each state's centre while
        # the palm is pulled, so the misses differ (4 and 12 cm when this was written).
        space = Lattice([0.25, 0.5, 0.75], 4)
        grid = LoadTargetGrid()
        misses = ReachMisses(space, 300.0, [40, 0], grid.Centres()[:1], grid.radius)
        self.assertEqual(misses.shape, (2, 1))
        self.assertTrue(np.all(np.isfinite(misses)))
        self.assertGreater(abs(misses[0, 0] - misses[1, 0]), 0.03)


class _DrawnReach:
    """The random strategy with the drawn reach fixed: state 3's."""

    babbles_goals = False

    def StartTry(self, num_states, rng):
        return 3

    def ReachRewards(self, histories, target, reaches, drawn):
        return (np.arange(len(reaches)) == drawn).astype(float)


class TestReadings(unittest.TestCase):
    """Issue 33: the source's ambiguities as named options, each against its closed form."""

    def test_a_move_across_a_plateau_fails_only_under_the_strict_rule(self):
        # Penalties on every transition into state 3 cut its drawn reach off: V = 0 in states
        # 0-2. From state 0 the first 0-valued state-action is the move to state 1 (transitions
        # come before the reach); it arrives where it was sent, and V(1) = V(0) = 0.
        from mobee_drake.reaching.strategies import REACH_STRATEGIES

        for rule, expected in (("strict", -10.0), ("arrival", 0.0)):
            with self.subTest(rule), mock.patch.dict(REACH_STRATEGIES, drawn=_DrawnReach()):
                space, learner = _Learner("drawn", max_actions=1)
                learner.config.plateau_rule = rule
                target = learner.targets[0]
                for sa in np.flatnonzero(space.action_goal == 3):
                    learner.histories.Record(int(sa), target, 0.0, -10.0)
                learner.problem_tries[1:] = 1
                robot = FakeRobot(space, PALMS, state=0)
                learner.Explore(robot)
                (entry,) = learner.log
                move = int(space.Actions(0)[0])
                self.assertEqual((entry[2], entry[4]), (move, space.action_goal[move]))
                self.assertEqual(entry[6], expected)

    def test_random_tie_breaks_ties_at_random(self):
        space, learner = _Learner("random")
        learner.config.plateau_rule = "random-tie"
        q = np.zeros(learner.num_state_actions)
        rng = np.random.default_rng(0)
        chosen = {learner._Greedy(q, 0, rng) for _ in range(60)}
        self.assertEqual(chosen, set(learner.Actions(0).tolist()))

    def test_eq81_as_its_prose_reads_fades_with_distance(self):
        from mobee_drake.reaching.predictors import PredictorConfig

        printed = RewardHistories([False, True])
        prose = RewardHistories([False, True], PredictorConfig(eq81="prose"))
        for h in (printed, prose):
            h.Record(0, [0, 0, 0], 0.0, FAILED_TRANSITION_REWARD)
            h.Record(1, [0, 0, 0], 1.0, 0.5)
        for distance in (0.0, 3.0, 30.0):
            w = 1 / (1 + distance)
            target = [distance, 0, 0]
            self.assertAlmostEqual(printed.Predict(0, target), -10.0)  # as printed: everywhere
            self.assertAlmostEqual(prose.Predict(0, target), -10.0 * w / (1 + w))
            # Reaches keep eq. 8.5 under either reading.
            self.assertAlmostEqual(prose.Predict(1, target), printed.Predict(1, target))
        self.assertEqual(prose.Predict(0, [0, 0, 0]), -5.0)
        empty = RewardHistories([False], PredictorConfig(eq81="prose"))
        self.assertEqual(empty.Predict(0, [0, 0, 0]), 0.0)  # eq. 8.3
        with self.assertRaisesRegex(ValueError, "unknown reading of eq. 8.1 'both'"):
            PredictorConfig(eq81="both").Validate()

    def test_an_evaluation_never_writes_to_the_learner(self):
        for history in ("per-problem", "per-evaluation"):
            with self.subTest(history):
                space, learner = _Learner("greedy")
                learner.config.evaluation_history = history
                with mock.patch.object(learner, "_Try", wraps=learner._Try) as tries:
                    learner.Evaluate(FakeRobot(space, PALMS), seed=1)
                used = {id(call.args[4]) for call in tries.call_args_list}
                self.assertEqual(len(used), 3)  # a scratch copy per problem-try
                self.assertNotIn(id(learner.histories), used)
                self.assertEqual(sum(len(learner.histories.History(sa)[2]) for sa in range(8)), 0)

    def test_a_failure_is_remembered_by_the_next_problem_per_evaluation(self):
        # Reach 1 is the only good one (eq. 8.5: 1 against about 0.04) and edge 0 -> 1 is
        # blocked; a reach puts the robot back in state 0. A problem-try from state 0 fails the
        # edge once, then goes round by 2 and 3 (gamma^3 = 0.73). Per evaluation, the problems
        # after the first predict -10 for the edge (eq. 8.1 as printed) and go round at once.
        failed = {}
        for history in ("per-problem", "per-evaluation"):
            space, learner = _Learner("greedy")
            learner.config.evaluation_history = history
            for s, target in itertools.product(range(4), learner.targets):
                for _ in range(1 if s == 1 else 20):
                    learner.histories.Record(learner.Reach(s), target, 1.0, float(s == 1))
            robot = FakeRobot(space, PALMS, blocked={(0, 1)}, state=0)
            robot.Reach = lambda target, robot=robot: (setattr(robot, "state", 0), PALMS[1])[1]
            blocked = int(np.flatnonzero((space.action_state == 0) & (space.action_goal == 1))[0])
            seen = []  # per problem-try, its copy's records of the edge and of reach 1 at the start

            reach = learner.Reach(1)

            def Try(*args, real=learner._Try, seen=seen, edge=blocked, reach=reach, **kwargs):
                histories = args[4]
                seen.append((len(histories.History(edge)[2]), len(histories.History(reach)[2])))
                return real(*args, **kwargs)

            learner._Try = Try
            results = learner.Evaluate(robot, seed=2)
            if history == "per-evaluation":  # the failure carried over, the reaches' records not
                self.assertEqual([edge for edge, _ in seen], [0, 1, 1])
                self.assertEqual({reach for _, reach in seen}, {3})  # the learner's own 3
            self.assertTrue(all(r.reach == learner.Reach(1) for r in results))
            failed[history] = sum(r.failed_transitions for r in results)
        self.assertGreaterEqual(failed["per-problem"], 2)  # once per try from state 0
        self.assertEqual(failed["per-evaluation"], 1)

    def test_bad_readings(self):
        from mobee_drake.reaching.learner import ReachLearningConfig

        with self.assertRaisesRegex(ValueError, "unknown plateau_rule 'lax'; choose one of strict"):
            ReachLearningConfig(plateau_rule="lax").Validate()
        with self.assertRaisesRegex(ValueError, "unknown evaluation_history 'never'"):
            ReachLearningConfig(evaluation_history="never").Validate()
        with self.assertRaisesRegex(ValueError, "random-tie' breaks ties at random already"):
            ReachLearningConfig(plateau_rule="random-tie", tie_break="random").Validate()
        from mobee_drake.reaching.predictors import PredictorConfig

        with self.assertRaisesRegex(ValueError, "eq81 'prose' is a reading of the weighted"):
            ReachLearningConfig(
                predictor=PredictorConfig(kind="gaussian_process", eq81="prose")
            ).Validate()


class TestTieBreak(unittest.TestCase):
    def test_first_takes_the_lowest_state_action(self):
        # From state 0 of the 2 x 2 lattice the drawn reach of state 3 lies two steps away by
        # two equal paths (via 1 or via 2): "first" always takes the first transition.
        space, learner = _Learner("random")
        rewards = np.zeros(learner.num_state_actions)
        rewards[learner.Reach(3)] = 1.0
        q, _ = learner.Values(rewards)
        actions = space.Actions(0)
        self.assertAlmostEqual(q[actions[0]], q[actions[1]])
        rng = np.random.default_rng(0)
        chosen = {learner._Greedy(q, 0, rng) for _ in range(20)}
        self.assertEqual(chosen, {int(actions[0])})
        _, drawing = _Learner("random")
        drawing.config.tie_break = "random"
        chosen = {drawing._Greedy(q, 0, rng) for _ in range(40)}
        self.assertEqual(chosen, set(actions[:2].tolist()))

    def test_bad_tie_break(self):
        from mobee_drake.reaching.learner import ReachLearningConfig

        with self.assertRaisesRegex(
            ValueError, "unknown tie_break 'last'; choose one of first, random"
        ):
            ReachLearningConfig(tie_break="last").Validate()


def _Try(problem, reward, reach, failed, actions=1):
    return dict(
        problem=problem, actions=actions, reward=reward, reach=reach, failed_transitions=failed
    )


def _SyntheticRun(strategy, seed, log, evaluations, hours=1.0, problems=3):
    """A battery result on a lattice of 4 transitions and 2 states (reaches 4 and 5)."""
    from mobee_drake.experiments.ch8_reaching import ReachRun

    return ReachRun.FromJson(_SyntheticResult(strategy, seed, log, evaluations, hours, problems))


def _SyntheticResult(strategy, seed, log, evaluations, hours=1.0, problems=3):
    """:func:`_SyntheticRun` as its result file holds it."""
    settings = dict(
        strategy=strategy,
        seed=seed,
        problem_tries=int(max(r[0] for r in log)) + 1,
        stages=sorted(int(s) for s in evaluations),
        evaluations=len(next(iter(evaluations.values()))),
        checkpoint_every=50,
    )
    return dict(
        settings=settings,
        evaluations=evaluations,
        log=[list(r) + [0.0] * (10 - len(r)) for r in log],
        simulated_seconds=3600.0 * hours,
        wall_seconds=1.0,
        penetrating_steps=0,
        num_transitions=4,
        num_states=2,
    )


def _BatteryArguments(*argv):
    """The settings and seeds ``mobee-drake experiment ch8 ARGV`` would run (nothing runs)."""
    from mobee_drake.experiments import ch8_command as ch8

    captured = {}

    def Fake(output, strategies, seeds, settings, mdp_tries, backend, mdps=1):
        captured["settings"], captured["seeds"], captured["mdps"] = settings, seeds, mdps
        raise SystemExit(0)

    with (
        tempfile.TemporaryDirectory() as folder,
        mock.patch.object(ch8, "RunReachBattery", Fake),
        contextlib.suppress(SystemExit),
    ):
        ch8.main(["--output", folder, *argv])
    return captured["settings"], captured["seeds"]


class TestEvaluationSums(unittest.TestCase):
    """Issue 23, points 7 and 8: the source's sum, fingerprints and run-level report."""

    def test_sum_with_and_without_penalties(self):
        from mobee_drake.experiments.ch8_figures import EvaluationSum

        evaluation = [_Try(0, 0.5, 4, 0), _Try(1, None, -1, 2, actions=10), _Try(2, 0.25, 5, 1)]
        self.assertAlmostEqual(EvaluationSum(evaluation, penalties=False), 0.75)
        self.assertAlmostEqual(EvaluationSum(evaluation), 0.75 - 30.0)

    def test_fingerprints_closed_form(self):
        from mobee_drake.experiments.ch8_measures import FAVOURITES, Fingerprints

        self.assertEqual(FAVOURITES, 2)
        # try, problem, state-action: tries 0-1 reach from states 0 and 1 (problems 0, 1), try 2
        # moves (transition 0) then reaches from 1 on problem 2, try 3 reaches from 0 again.
        log = [(0, 0, 4), (1, 1, 5), (2, 2, 0), (2, 2, 5), (3, 0, 4)]
        evaluation = [_Try(0, 0.5, 4, 0), _Try(1, 0.5, 4, 0, actions=2), _Try(2, 0.5, 5, 0)]
        run = _SyntheticRun("greedy", 0, log, {"2": [evaluation], "4": [evaluation]}, hours=2.0)
        f = Fingerprints(run)
        # Two states only, so the two favourites hold every reach.
        self.assertEqual((f["favourite_share"], f["reach_states"]), (1.0, 2))
        self.assertEqual(f["favourite_reaches"], [4, 5])
        self.assertAlmostEqual(f["evaluation_actions"], 4 / 3)
        # Coverage: before try 2 the pairs (0, 4), (1, 5) of 3 x 2; before 4 also (2, 5).
        self.assertEqual(f["coverage"], {2: 2 / 6, 4: 3 / 6})
        self.assertEqual(f["line_share"], {2: 1.0, 4: 1.0})
        self.assertEqual(f["robot_hours"], 2.0)

    def test_report_tests_runs_not_evaluations(self):
        from mobee_drake.experiments.ch8_report import Report
        from mobee_drake.experiments.statistics import CompareRuns

        log = [(0, 0, 4), (1, 1, 5)]
        results = []
        # Two runs per strategy, five identical evaluations each: run means 1, 3 (intrinsic),
        # 2, 4 (random and greedy); the intrinsic runs' evaluations fail a transition each.
        for strategy, means, failed in (("random", (2, 4), 0), ("greedy", (2, 4), 0)) + (
            ("intrinsic", (1, 3), 1),
        ):
            for seed, mean in enumerate(means):
                evaluation = [_Try(0, mean, 4, failed), _Try(1, 0.0, 4, 0), _Try(2, 0.0, 5, 0)]
                results.append(
                    _SyntheticRun(strategy, seed, log, {"2": [evaluation] * 5}, hours=1 + seed)
                )
        with tempfile.TemporaryDirectory() as folder:
            report = Report(pathlib.Path(folder), results)
        reaches_only = CompareRuns([1.0, 3.0], [2.0, 4.0]).Text()
        self.assertIn(
            f"reaches only, after 2 problem-tries, intrinsic minus random {reaches_only}", report
        )
        with_penalties = CompareRuns([-9.0, -7.0], [2.0, 4.0]).Text()
        self.assertIn(
            f"the source's sum, after 2 problem-tries, intrinsic minus random {with_penalties}",
            report,
        )
        self.assertIn("2 vs 2 runs", report)
        # The source's sum per run: -9 and -7 (mean -8, sd sqrt(2)).
        self.assertIn("| intrinsic | 2 | -8.00 ± 1.41 |", report)
        self.assertIn("1.00 times the robot time", report)

    def test_report_tests_each_runs_trend(self):
        from mobee_drake.experiments.ch8_report import Report
        from mobee_drake.experiments.statistics import CompareRuns, CompareToZero

        log = [(0, 0, 4), (1, 1, 5)]
        # A run's reach rewards at 2 and 4 problem-tries: its trend is their difference (one
        # doubling). Intrinsic runs: 1 and 3; the others': 0 and 1.
        rewards = {"intrinsic": ((0.0, 1.0), (0.0, 3.0)), "random": ((0.0, 0.0), (0.0, 1.0))}
        rewards["greedy"] = rewards["random"]
        results = [
            _SyntheticRun(
                strategy,
                seed,
                log,
                {
                    str(stage): [[_Try(0, r, 4, 0), _Try(1, 0.0, 4, 0), _Try(2, 0.0, 5, 0)]]
                    for stage, r in zip((2, 4), pair)
                },
            )
            for strategy, pairs in rewards.items()
            for seed, pair in enumerate(pairs)
        ]
        with tempfile.TemporaryDirectory() as folder:
            report = Report(pathlib.Path(folder), results)
        self.assertIn(
            "reaches only, change per doubling of the problem-tries (per run, the slope of its "
            f"stage means over log2 of 2...4): intrinsic {CompareToZero([1.0, 3.0]).Text()}; "
            f"intrinsic minus random {CompareRuns([1.0, 3.0], [0.0, 1.0]).Text()}",
            report,
        )

    def test_sweep_names_and_report(self):
        from mobee_drake.experiments import ch8_reaching as ch8
        from mobee_drake.experiments.ch8_report import Report

        settings = [
            ch8.RunSettings("random", 0, 4, [4], 1, 2, distance_unit=unit) for unit in (0.01, 0.1)
        ]
        jobs = []
        with mock.patch.object(ch8, "RunBattery", lambda j, *a, **k: jobs.extend(j) or {}):
            ch8.RunReachBattery(
                pathlib.Path("unused"), ["random", "greedy"], range(2), settings, 5, None
            )
        names = [j.name for j in jobs]
        self.assertIn("mdp_tries5", names)
        self.assertIn("greedy_unit0.01_force300_seed1", names)
        self.assertIn("random_unit0.1_force300_seed0", names)
        self.assertEqual(len(names), 1 + 2 * 2 * 2)
        with self.assertRaisesRegex(ValueError, "settings repeat"):
            ch8.RunReachBattery(pathlib.Path("unused"), ["random"], range(1), settings * 2, 5, None)
        # A report of two settings: a fingerprint row each, figures in a folder each.
        log = [(0, 0, 4), (1, 1, 5)]
        results = [
            _SyntheticRun(s, seed, log, {"2": [[_Try(p, 0.5, 4, 0) for p in range(3)]] * 2})
            for s in ("random", "greedy", "intrinsic")
            for seed in (0, 1)
        ]
        swept = [
            dataclasses.replace(r, settings=dataclasses.replace(r.settings, distance_unit=u))
            for u in (0.01, 0.1)
            for r in results
        ]
        with tempfile.TemporaryDirectory() as folder:
            report = Report(pathlib.Path(folder), swept)
            self.assertTrue(
                (pathlib.Path(folder) / "unit0.01_force300" / "8.7_problem_tries.png").is_file()
            )
        self.assertIn("| unit0.01_force300 | 1.00 | 1.00 ± 0.00 |", report)
        self.assertIn("# unit0.1_force300", report)

    def test_a_sweep_of_readings_over_independent_mdps(self):
        """Issue 33: every combination of the readings is a setting; seed k's runs use MDP
        k mod --mdps, learned on a robot with the setting's noise."""
        from mobee_drake.experiments import ch8_reaching as ch8

        settings, seeds = _BatteryArguments(
            "--seeds", "4", "--plateau-rule", "strict", "arrival",
            "--transition-noise", "0", "0.05",
        )  # fmt: skip
        self.assertEqual(
            [(s.plateau_rule, s.transition_noise) for s in settings],
            [("strict", 0.0), ("strict", 0.05), ("arrival", 0.0), ("arrival", 0.05)],
        )
        jobs = []
        with mock.patch.object(ch8, "RunBattery", lambda j, *a, **k: jobs.extend(j) or {}):
            ch8.RunReachBattery(pathlib.Path("unused"), ["random"], seeds, settings, 5, None, 3)
        runs = {j.name: j.kwargs for j in jobs if j.function is ch8.ReachJob}
        mdps = [j.name for j in jobs if j.function is ch8.MdpJob]
        self.assertEqual(
            mdps,
            ["mdp_tries5", "mdp_tries5_seed1", "mdp_tries5_seed2"]
            + ["mdp_tries5_noise0.05", "mdp_tries5_seed1_noise0.05", "mdp_tries5_seed2_noise0.05"],
        )
        self.assertEqual(len(runs), 4 * 4)
        run = runs["random_unit0.03_force300_rule-arrival_noise0.05_seed3"]
        self.assertEqual(run["mdp"], "mdp_tries5_noise0.05")  # seed 3 on MDP 0
        self.assertEqual(run["settings"]["mdp_seed"], 0)
        self.assertEqual(runs["random_unit0.03_force300_seed2"]["mdp"], "mdp_tries5_seed2")

    def test_command_line_sweep(self):
        settings, seeds = _BatteryArguments(
            "--first-seed", "100", "--seeds", "2", "--distance-unit", "0.01", "0.03", "0.1",
            "--tie-break", "random",
        )  # fmt: skip
        self.assertEqual([s.distance_unit for s in settings], [0.01, 0.03, 0.1])
        self.assertEqual(list(seeds), [100, 101])
        self.assertTrue(all(s.tie_break == "random" for s in settings))

    def test_command_line_presets(self):
        from mobee_drake.experiments.ch8_reaching import REACH_PRESETS

        def UnitAndForce(*argv):
            settings, _ = _BatteryArguments(*argv)
            return settings.distance_unit, settings.reach_force

        # The default is the calibrated preset; the first reading is named; flags override.
        calibrated = REACH_PRESETS["calibrated"]
        self.assertEqual(UnitAndForce(), (calibrated.distance_unit, calibrated.reach_force))
        self.assertEqual(UnitAndForce("--preset", "metres"), (1.0, 300.0))
        self.assertEqual(UnitAndForce("--preset", "metres", "--reach-force", "30"), (1.0, 30.0))

    def test_report_only(self):
        import json

        from mobee_drake.experiments import ch8_command as ch8

        log = [(0, 0, 4), (1, 1, 5)]
        with tempfile.TemporaryDirectory() as folder:
            (pathlib.Path(folder) / ".mobee-drake").write_text('{"kind": "battery"}')
            for strategy in ("random", "greedy", "intrinsic"):
                for seed in (0, 1):
                    run = pathlib.Path(folder) / "runs" / f"{strategy}_seed{seed}"
                    run.mkdir(parents=True)
                    result = _SyntheticResult(
                        strategy, seed, log, {"2": [[_Try(p, 0.5, 4, 0) for p in range(3)]]}
                    )
                    (run / "result.json").write_text(json.dumps(result))
            (pathlib.Path(folder) / "runs" / "mdp_tries5").mkdir()
            (pathlib.Path(folder) / "runs" / "mdp_tries5" / "result.json").write_text("{}")
            with contextlib.redirect_stdout(io.StringIO()):
                ch8.main(["--output", folder, "--report-only"])
            report = (pathlib.Path(folder) / "report.md").read_text()
            self.assertIn("| greedy | 2 | 1.50 ± 0.00 |", report)
            # Runs from before the tie-break option drew ties at random.
            self.assertIn("Ties of value broken by: random.", report)
            # --doc writes the claims table into the doc's generated block, naming the command.
            doc = pathlib.Path(folder) / "doc.md"
            doc.write_text(
                "before\n<!-- generated: ch8-claims, by x -->\nSTALE-TABLE\n"
                "<!-- end generated: ch8-claims -->\nafter\n"
            )
            with contextlib.redirect_stdout(io.StringIO()):
                ch8.main(["--output", folder, "--report-only", "--doc", str(doc)])
            text = doc.read_text()
            self.assertIn(f"by mobee-drake experiment ch8 --report-only --output {folder}", text)
            self.assertIn("| the source's claim | value compared | unit1_force300 |", text)
            self.assertNotIn("STALE-TABLE", text)
            self.assertTrue(text.startswith("before") and text.endswith("after\n"))
            with contextlib.redirect_stderr(io.StringIO()), self.assertRaises(SystemExit):
                ch8.main(["--output", folder, "--report-only", "--doc", str(folder)])
            # --doc-table names another block of the same doc; the first is left alone.
            doc.write_text(
                text + "<!-- generated: other, by x -->\nOLD\n<!-- end generated: other -->\n"
            )
            with contextlib.redirect_stdout(io.StringIO()):
                ch8.main(
                    ["--output", folder, "--report-only", "--doc", str(doc), "--doc-table", "other"]
                )
            both = doc.read_text()
            self.assertTrue(both.startswith(text))
            self.assertNotIn("OLD", both)
            self.assertIn(f"--doc {doc} --doc-table other -->", both)
        with tempfile.TemporaryDirectory() as folder, contextlib.redirect_stderr(io.StringIO()):
            with self.assertRaises(SystemExit):
                ch8.main(["--output", folder, "--report-only"])
