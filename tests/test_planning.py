"""The curious MDP planner's core against the dissertation's tables and closed forms."""

import json
import unittest

import numpy as np
from scipy import sparse

from mobee_drake.planning.curiosity import KlDivergence, SetProbabilityRow, TransitionCounts
from mobee_drake.planning.explorers import Explorer, ExplorerConfig
from mobee_drake.planning.state_space import FromSamples, Lattice
from mobee_drake.planning.strategies import STRATEGIES, RegisterStrategy
from mobee_drake.planning.value_iteration import ValueIteration


class TestKlDivergence(unittest.TestCase):
    def test_uniform_initialisation_examples(self):
        # Eq. 6.6-6.9 (unnormalised counts, normalised before the divergence).
        self.assertAlmostEqual(KlDivergence([1, 2, 1], [1, 1, 1]), 0.0589, places=4)
        self.assertAlmostEqual(KlDivergence([2, 1, 1], [1, 1, 1]), 0.0589, places=4)
        self.assertAlmostEqual(KlDivergence([1, 1, 2, 1, 1], [1] * 5), 0.0487, places=4)
        self.assertAlmostEqual(KlDivergence([1, 1, 1, 2, 1, 1, 1], [1] * 7), 0.0398, places=4)


class TestObserve(unittest.TestCase):
    """Alg. 6 on one state-action with goal state g = 1, from state i = 0."""

    def _Run(self, outcomes):
        counts = TransitionCounts(1, 10)
        return [round(counts.Observe(0, s), 4) for s in outcomes], counts

    def test_table_6_1_initialisation(self):
        rewards, counts = self._Run([0, 1])
        self.assertEqual(rewards, [0.0, 0.0589])
        np.testing.assert_array_equal(counts.counts[0, :2], [2, 2])

    def test_table_7_1_sixty_forty(self):
        rewards, counts = self._Run([0, 1, 1])
        self.assertEqual(rewards, [0.0, 0.0589, 0.0201])
        np.testing.assert_allclose(counts.Probabilities()[0, :2], [0.4, 0.6])

    def test_table_6_2_predictable_success(self):
        rewards, _ = self._Run([0, 1, 1, 1, 1])
        self.assertEqual(rewards[1:], [0.0589, 0.0201, 0.0095, 0.0052])

    def test_table_6_3_surprising_outcome(self):
        rewards, _ = self._Run([0, 1, 5, 5, 5])
        self.assertEqual(rewards[1:], [0.0589, 0.0487, 0.0196, 0.0103])

    def test_table_6_4_unpredictable(self):
        a, b, c, g = 5, 6, 7, 1
        rewards, _ = self._Run([0, g, a, b, c, g, a, b])
        # The first two rows follow Alg. 6, D(P || T), like every other table ...
        self.assertEqual(rewards[1:3], [0.0589, 0.0487])
        # ... the later rows were printed with the arguments swapped, D(T || P): each printed
        # value is that of the swapped divergence of the printed T and P, to four decimals, and
        # Alg. 6 gives what it says instead.
        printed = [  # (T, P, R) of Table 6.4, rows 3-7
            ([2, 2, 2, 1], [2, 2, 2, 2], 0.0345),
            ([2, 2, 2, 2, 1], [2, 2, 2, 2, 2], 0.0283),
            ([2, 2, 2, 2, 2], [2, 3, 2, 2, 2], 0.0142),
            ([2, 3, 2, 2, 2], [2, 3, 3, 2, 2], 0.0133),
            ([2, 3, 3, 2, 2], [2, 3, 3, 3, 2], 0.0125),
        ]
        for (t, p, r), ours in zip(printed, rewards[3:]):
            self.assertAlmostEqual(KlDivergence(t, p), r, delta=1e-4)
            self.assertEqual(ours, round(KlDivergence(p, t), 4))


class TestSparseProbabilities(unittest.TestCase):
    def test_a_row_set_after_each_observation_is_the_dense_t(self):
        # Observations that add bins (the row's stored entries grow) and that do not.
        rng = np.random.default_rng(0)
        counts = TransitionCounts(30, 12)
        counts.counts[np.arange(30), rng.integers(12, size=30)] = 2.0
        T = sparse.csr_array(counts.Probabilities())
        for _ in range(400):
            sa = int(rng.integers(30))
            counts.Observe(sa, int(rng.integers(12)))
            SetProbabilityRow(T, sa, counts.counts[sa])
            np.testing.assert_array_equal(T.toarray(), counts.Probabilities())
        self.assertEqual(T.nnz, np.count_nonzero(counts.counts))

    def test_any_row_set_to_any_counts(self):
        # Rows that grow, shrink, empty and fill again, the first and the last among them.
        rng = np.random.default_rng(1)
        counts = rng.integers(0, 3, size=(8, 6)).astype(float)
        T = sparse.csr_array(counts / np.maximum(counts.sum(axis=1, keepdims=True), 1))
        for row in [0, 7, 3, 0, 7] + list(rng.integers(8, size=200)):
            counts[row] = rng.integers(0, 3, size=6) * (rng.random() > 0.2)
            SetProbabilityRow(T, row, counts[row])
            T.check_format(full_check=True)
            totals = counts.sum(axis=1, keepdims=True)
            dense = np.divide(counts, totals, out=np.zeros_like(counts), where=totals > 0)
            np.testing.assert_array_equal(T.toarray(), dense)
            self.assertEqual(T.nnz, np.count_nonzero(counts))


class TestStateActionSpaces(unittest.TestCase):
    def test_sizes_of_the_dissertation_spaces(self):
        cases = [
            (Lattice([0.25, 0.75], 4), 16, 64),
            (Lattice([0.25, 0.5, 0.75], 4), 81, 432),
            (Lattice([0.25, 0.5, 0.75], 4, k=16), 81, 1296),
            (Lattice([0.2, 0.4, 0.6, 0.8], 4), 256, 1536),
            (Lattice([0.125, 0.375, 0.625, 0.875], 4), 256, 1536),
            (Lattice([0.25, 0.5, 0.75], 3, k=8), 27, 216),
        ]
        for space, states, state_actions in cases:
            self.assertEqual((space.num_states, space.num_state_actions), (states, state_actions))

    def test_a_centre_at_a_limit_is_on_it(self):
        """Issue 31, item 6: ``levels: [0, 1]`` put a centre a rounding error past a limit
        (lower + 1 * (upper - lower) > upper for these two), and MoBeE refused the attractor."""
        lower, upper = np.array([-2.877079428191416]), np.array([1.668729436108269])
        space = Lattice([0.0, 1.0], 1)
        centres = [space.Centre(s, lower, upper)[0] for s in range(space.num_states)]
        self.assertEqual(sorted(centres), [lower[0], upper[0]])

    def test_equidistant_neighbours_of_the_rank_3_lattice(self):
        space = Lattice([0.25, 0.5, 0.75], 4)
        counts = np.bincount(space.action_state)
        self.assertEqual((counts.min(), counts.max()), (4, 8))  # corners 4, centre 8
        centre = space.StateOf(np.full(4, 0.5))
        goals = space.action_goal[space.Actions(centre)]
        np.testing.assert_allclose(np.abs(space.centres[goals] - 0.5).sum(axis=1), 0.25)

    def test_state_lookup_is_the_nearest_centre(self):
        space = FromSamples(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]))
        self.assertEqual(space.StateOf(np.array([0.6, 0.1])), 1)
        self.assertEqual(space.StateOf(np.array([0.1, 0.4])), 0)
        with self.assertRaisesRegex(ValueError, "samples must be"):
            FromSamples(np.array([0.0, 1.0]))


class TestValueIteration(unittest.TestCase):
    def test_closed_form_of_a_deterministic_cycle(self):
        # Two states, one action each, going to the other state; rewards 1 and 0.
        # V0 = 1 + g V1, V1 = g V0  =>  V0 = 1 / (1 - g^2), V1 = g / (1 - g^2).
        gamma = 0.9
        T = np.array([[0.0, 1.0], [1.0, 0.0]])
        q, v = ValueIteration(T, np.array([1.0, 0.0]), np.array([0, 1]), 2, gamma, delta=1e-12)
        np.testing.assert_allclose(v, [1 / (1 - gamma**2), gamma / (1 - gamma**2)], rtol=1e-9)
        np.testing.assert_allclose(q, v)

    def test_max_over_actions_and_stochastic_outcomes(self):
        # State 0 has two actions: a sure reward 1 staying put, or 50 % to reach the goal state 1
        # (absorbing, reward 2). V1 = 2 / (1 - g); the second action is worth 0.5 g (V0 + V1).
        gamma = 0.5
        T = np.array([[1.0, 0.0], [0.5, 0.5], [0.0, 1.0]])
        R = np.array([1.0, 0.0, 2.0])
        v1 = 2 / (1 - gamma)
        v0 = max(1 / (1 - gamma), 0.5 * gamma * v1 / (1 - 0.5 * gamma))
        for given in (T, sparse.csr_array(T)):  # (the reach learner's T is sparse)
            q, v = ValueIteration(given, R, np.array([0, 0, 1]), 2, gamma, delta=1e-12)
            np.testing.assert_allclose(v, [v0, v1], rtol=1e-9)

    def test_stops_at_delta(self):
        T = np.array([[1.0]])
        q, _ = ValueIteration(T, np.array([1.0]), np.array([0]), 1, 0.9, delta=1e-3)
        # The geometric series to 10 stops once a sweep adds less than 1e-3.
        self.assertLess(10 - q[0], 1e-3 / (1 - 0.9) + 1e-12)
        self.assertGreater(10 - q[0], 0)


class TestExplorers(unittest.TestCase):
    def _Explore(self, strategy, steps, seed=0, fail=()):
        """Explores the hypercube in a world where the state-actions in ``fail`` stay put."""
        space = Lattice([0.25, 0.75], 4)
        agent = Explorer(space, ExplorerConfig(strategy=strategy), seed)
        state, first_tried = 0, {}
        for step in range(steps):
            sa = agent.ChooseAction(state)
            outcome = state if sa in fail else int(space.action_goal[sa])
            agent.Observe(sa, outcome)
            first_tried.setdefault(sa, step)
            state = outcome
        return agent, first_tried

    def test_curious_agent_tries_everything_and_prefers_failing_actions(self):
        agent, first = self._Explore("curious", 400, fail={5})
        self.assertEqual(len(first), 64)
        # A surprising state-action stays more interesting: it is tried more than the median.
        self.assertGreater(agent.tries[5], np.median(agent.tries))

    def test_same_seed_same_run(self):
        a, _ = self._Explore("curious", 100, seed=3)
        b, _ = self._Explore("curious", 100, seed=3)
        np.testing.assert_array_equal(a.tries, b.tries)

    def test_least_tried_breaks_ties_at_random_and_covers(self):
        agent, first = self._Explore("least_tried", 300)
        self.assertEqual(len(first), 64)
        agent, _ = self._Explore("random", 50)
        self.assertEqual(agent.tries.sum(), 50)

    def test_a_strategy_of_ones_own(self):
        class HighestGoal:
            """Always the action to the state of the highest index."""

            seeks_goal = False

            def Scores(self, explorer, actions):
                return explorer.space.action_goal[actions].astype(float)

        RegisterStrategy("highest_goal", HighestGoal())
        self.addCleanup(STRATEGIES.pop, "highest_goal")
        space = Lattice([0.25, 0.75], 3)
        agent, state = Explorer(space, ExplorerConfig(strategy="highest_goal")), 0
        for _ in range(5):
            action = agent.ChooseAction(state)
            self.assertEqual(
                space.action_goal[action], space.action_goal[space.Actions(state)].max()
            )
            state = int(space.action_goal[action])
        with self.assertRaisesRegex(ValueError, "named 'random' exists already"):
            RegisterStrategy("random", HighestGoal())

    def test_bad_configuration(self):
        space = Lattice([0.25, 0.75], 2)
        with self.assertRaisesRegex(ValueError, "strategy must be one of .*, got 'bold'"):
            Explorer(space, ExplorerConfig(strategy="bold"))
        with self.assertRaisesRegex(ValueError, "initialization must be .*, got '70-30'"):
            Explorer(space, ExplorerConfig(initialization="70-30"))


class TestPlanner(unittest.TestCase):
    def test_plans_around_an_action_that_fails(self):
        from mobee_drake.planning.planner import GreedyPlan

        # A 3 x 3 lattice (states 0..8, row-major in the first coordinate); the direct step from
        # the middle-left state 3 to the centre 4 was always seen to fail (e.g. an obstacle).
        space = Lattice([0.0, 0.5, 1.0], 2)
        agent = Explorer(space, ExplorerConfig())
        for sa, (s, g) in enumerate(zip(space.action_state, space.action_goal)):
            blocked = (s, g) == (3, 4)
            for _ in range(10):
                agent.Observe(sa, s if blocked else g)
        path = GreedyPlan(agent, start=3, goal=5)
        self.assertEqual((path[0], path[-1]), (3, 5))
        self.assertNotIn((3, 4), list(zip(path, path[1:])))
        self.assertEqual(len(path), 5)  # a detour of four steps instead of two

    def test_unknown_goal(self):
        from mobee_drake.planning.planner import PlanValues

        agent = Explorer(Lattice([0.0, 1.0], 1))
        with self.assertRaisesRegex(ValueError, "goal state 7 is not a state"):
            PlanValues(agent, {7: 1.0})


class TestActuationNoise(unittest.TestCase):
    def test_the_noise_is_gaussian_in_each_joints_range_and_repeats_for_a_time(self):
        from mobee_drake.planning.actuation_noise import NoisyPosture

        centre, lower, upper = np.array([0.5, 2.0]), np.array([0.0, 0.0]), np.array([1.0, 4.0])
        draws = np.array(
            [NoisyPosture(centre, lower, upper, 0.05, 3, 0, 0.02 * k) for k in range(4000)]
        )
        z = (draws - centre) / (0.05 * (upper - lower))
        np.testing.assert_allclose(z.mean(axis=0), 0.0, atol=0.05)  # 3.2 standard errors
        np.testing.assert_allclose(z.std(axis=0), 1.0, atol=0.05)
        # On the rank-3 lattice a joint leaves its state (0.125 of its range away) with
        # probability 2 Phi(-2.5) = 1.24 % at sd 0.05.
        left = np.mean(np.abs(draws[:, 0] - 0.5) > 0.125)
        self.assertAlmostEqual(left, 0.0124, delta=0.006)
        np.testing.assert_array_equal(
            NoisyPosture(centre, lower, upper, 0.05, 3, 0, 1.5),
            NoisyPosture(centre, lower, upper, 0.05, 3, 0, 1.5),
        )
        self.assertFalse(
            np.array_equal(
                NoisyPosture(centre, lower, upper, 0.05, 3, 0, 1.5),
                NoisyPosture(centre, lower, upper, 0.05, 3, 1, 1.5),  # another agent
            )
        )
        at_limit = NoisyPosture(np.array([1.0, 4.0]), lower, upper, 0.4, 0, 0, 0.0)
        self.assertTrue(np.all((at_limit >= lower) & (at_limit <= upper)))
        np.testing.assert_array_equal(NoisyPosture(centre, lower, upper, 0.0, 3, 0, 1.5), centre)


class TestSupervisor(unittest.TestCase):
    """The exploration loop as a Drake system, with the robot state fixed by the test."""

    def _Dut(self, **timing):
        from mobee_drake.planning.supervisor import ActionTiming, Agent, ExplorationSupervisor

        space = Lattice([0.25, 0.75], 2)
        agent = Agent(name="arm", joints=["b", "c"], space=space)
        dut = ExplorationSupervisor(
            agents=[agent],
            joints=["a", "b", "c"],
            lower=np.array([-1.0, 0.0, 0.0]),
            upper=np.array([1.0, 2.0, 4.0]),
            home=np.array([0.5, 0.5, 1.0]),
            timing=ActionTiming(**timing),
            period=0.2,
        )
        return dut, space

    def test_an_action_runs_until_the_robot_settles(self):
        dut, space = self._Dut(settle_time=0.5, min_duration=0.5, timeout=20.0)
        context = dut.CreateDefaultContext()
        # The robot at the centre of state 0: b = 0.5 (25 % of [0, 2]), c = 1 (25 % of [0, 4]).
        q = np.array([0.3, 0.5, 1.0])
        dut.GetInputPort("robot_state").FixValue(context, np.concatenate([q, np.zeros(3)]))
        dut.ExecuteInitializationEvents(context)
        (record,) = dut.Records(context)
        self.assertEqual(record.state, 0)
        goal = space.action_goal[record.state_action]
        expected = np.array([0.5, *(np.array([0, 0]) + space.centres[goal] * [2, 4])])
        np.testing.assert_allclose(dut.GetOutputPort("attractor").Eval(context), expected)
        # Polling while the robot is still: the action ends 0.5 s after it started being still.
        times = [0.2, 0.4, 0.6, 0.8]
        done = []
        for t in times:
            context.SetTime(t)
            state = context.get_mutable_state()
            dut.CalcForcedUnrestrictedUpdate(context, state)
            done.append(dut.Records(context)[0].actions_done)
        self.assertEqual(done, [0, 0, 0, 1])  # slow since 0.2 s, settled at 0.7 s or later
        # The robot never moved: the action failed, and the agent observed state 0 again.
        counts = dut.Records(context)[0].explorer.transitions.counts[record.state_action]
        self.assertEqual(counts[0], 3)  # the initialisation's failure, plus this one
        self.assertEqual(dut.Records(context)[0].explorer.tries[record.state_action], 1)

    def test_transition_noise_moves_the_attractor_off_the_goals_centre(self):
        """Issue 33: a stochastic robot's attractor is the goal's centre plus the actuation noise
        of the action's start (NoisyPosture's closed form), the centre without noise."""
        from mobee_drake.planning.actuation_noise import NoisyPosture
        from mobee_drake.planning.supervisor import Agent, ExplorationSupervisor

        space = Lattice([0.25, 0.75], 2)
        lower, upper = np.array([-1.0, 0.0, 0.0]), np.array([1.0, 2.0, 4.0])
        attractors = {}
        for noise in (0.0, 0.1):
            dut = ExplorationSupervisor(
                agents=[Agent(name="arm", joints=["b", "c"], space=space, seed=5)],
                joints=["a", "b", "c"],
                lower=lower,
                upper=upper,
                home=np.array([0.5, 0.5, 1.0]),
                transition_noise=noise,
            )
            context = dut.CreateDefaultContext()
            dut.GetInputPort("robot_state").FixValue(context, np.r_[0.3, 0.5, 1.0, np.zeros(3)])
            dut.ExecuteInitializationEvents(context)
            record = dut.Records(context)[0]
            attractors[noise] = dut.GetOutputPort("attractor").Eval(context)
        centre = space.centres[space.action_goal[record.state_action]] * [2, 4]
        np.testing.assert_allclose(attractors[0.0], [0.5, *centre])
        noisy = NoisyPosture(centre, lower[1:], upper[1:], 0.1, 5, 0, record.started)
        np.testing.assert_allclose(attractors[0.1], [0.5, *noisy])
        self.assertGreater(np.abs(noisy - centre).min(), 0.0)
        with self.assertRaisesRegex(ValueError, "transition_noise must be in \\[0, 1\\)"):
            ExplorationSupervisor(
                agents=[], joints=["a"], lower=lower[:1], upper=upper[:1], home=[0.0],
                transition_noise=-0.1,
            )  # fmt: skip

    def test_timeout_and_polling_copies_nothing(self):
        import copy

        dut, _ = self._Dut(timeout=1.0)
        context = dut.CreateDefaultContext()
        moving = np.concatenate([[0.3, 0.5, 1.0], [0.0, 1.0, 0.0]])
        dut.GetInputPort("robot_state").FixValue(context, moving)
        dut.ExecuteInitializationEvents(context)
        record = dut.Records(context)[0]
        self.assertIs(copy.deepcopy(record), record)
        for t in (0.2, 0.4, 0.6, 0.8):
            context.SetTime(t)
            dut.CalcForcedUnrestrictedUpdate(context, context.get_mutable_state())
            self.assertIs(dut.Records(context)[0], record)  # nothing changed, nothing built
        context.SetTime(1.0)
        dut.CalcForcedUnrestrictedUpdate(context, context.get_mutable_state())
        self.assertEqual(dut.Records(context)[0].actions_done, 1)  # timed out while moving

    def test_planner_takes_new_goals(self):
        """The shipped planner, and (issue 32) a goal-seeking strategy registered by a user:
        arrival is the strategy's property, not its name's."""
        from mobee_drake.planning.strategies import STRATEGIES, Planner, RegisterStrategy

        class MyPlanner(Planner):
            pass

        RegisterStrategy("my_planner", MyPlanner())
        self.addCleanup(STRATEGIES.pop, "my_planner")
        for strategy in ("planner", "my_planner"):
            with self.subTest(strategy):
                self._TakesNewGoals(strategy)
        with self.assertRaisesRegex(TypeError, "strategy 'vague' must say whether it seeks_goal"):
            RegisterStrategy("vague", object())

    def _TakesNewGoals(self, strategy: str) -> None:
        from mobee_drake.planning.supervisor import Agent, ExplorationSupervisor

        # A 2 x 2 lattice over joints b, c; the planner starts in state 0 heading for state 3.
        space = Lattice([0.25, 0.75], 2)
        agent = Agent(
            name="arm",
            joints=["b", "c"],
            space=space,
            explorer=ExplorerConfig(strategy=strategy, goal_state=3),
        )
        dut = ExplorationSupervisor(
            agents=[agent], joints=["b", "c"], lower=np.zeros(2), upper=np.ones(2), home=np.zeros(2)
        )
        context = dut.CreateDefaultContext()
        dut.GetInputPort("robot_state").FixValue(context, [0.25, 0.25, 0.0, 0.0])
        dut.ExecuteInitializationEvents(context)
        # A goal one step away: the first action goes straight there.
        dut.SetPlannerGoal(context, "arm", 2)
        (record,) = dut.Records(context)
        self.assertEqual((record.state, record.explorer.config.goal_state), (0, 2))
        self.assertEqual(space.action_goal[record.state_action], 2)
        np.testing.assert_allclose(dut.GetOutputPort("attractor").Eval(context), space.centres[2])
        self.assertFalse(record.arrived)
        # The goal it is in already: it has arrived and stays.
        dut.SetPlannerGoal(context, "arm", 0)
        self.assertTrue(dut.Records(context)[0].arrived)
        with self.assertRaisesRegex(ValueError, "goal state 4 is not a state"):
            dut.SetPlannerGoal(context, "arm", 4)
        with self.assertRaisesRegex(ValueError, "unknown agent 'leg'"):
            dut.SetPlannerGoal(context, "leg", 1)

    def test_where_each_action_ended_is_kept(self):
        """An agent on joints c and a (of a, b, c, each with its own limits) keeps, per
        action, where its joints were when the action ended, in fractions of their ranges and
        in its own joint order: through a planner's arrival and a new goal."""
        from mobee_drake.planning.supervisor import ActionTiming, Agent, ExplorationSupervisor

        space = Lattice([0.25, 0.75], 2)
        agent = Agent(
            name="arm",
            joints=["c", "a"],
            space=space,
            explorer=ExplorerConfig(strategy="planner", goal_state=3),
        )
        dut = ExplorationSupervisor(
            agents=[agent], joints=["a", "b", "c"], lower=np.array([-1.0, 0.0, 2.0]),
            upper=np.array([1.0, 2.0, 4.0]), home=np.array([0.0, 1.0, 3.0]),
            timing=ActionTiming(settle_time=0.0, min_duration=0.0),
        )  # fmt: skip
        context = dut.CreateDefaultContext()

        def At(c: float, a: float) -> None:  # (fractions of the ranges; at rest)
            q = [-1.0 + 2.0 * a, 1.0, 2.0 + 2.0 * c]
            dut.GetInputPort("robot_state").FixValue(context, q + [0.0] * 3)

        At(0.25, 0.75)  # state 1; the goal, 3, is one action away
        dut.ExecuteInitializationEvents(context)
        self.assertEqual(dut.Records(context)[0].settled, ())
        At(0.7, 0.8)
        context.SetTime(0.2)
        dut.CalcForcedUnrestrictedUpdate(context, context.get_mutable_state())
        (record,) = dut.Records(context)
        self.assertTrue(record.arrived)
        np.testing.assert_allclose(record.settled, [[0.7, 0.8]])
        dut.SetPlannerGoal(context, "arm", 0)
        np.testing.assert_allclose(dut.Records(context)[0].settled, [[0.7, 0.8]])
        At(0.2, 0.3)
        context.SetTime(0.4)
        dut.CalcForcedUnrestrictedUpdate(context, context.get_mutable_state())
        np.testing.assert_allclose(dut.Records(context)[0].settled, [[0.7, 0.8], [0.2, 0.3]])

    def test_bad_agents(self):
        from mobee_drake.planning.supervisor import Agent, ExplorationSupervisor

        space = Lattice([0.25, 0.75], 2)
        kwargs = dict(joints=["a", "b"], lower=np.zeros(2), upper=np.ones(2), home=np.zeros(2))
        with self.assertRaisesRegex(ValueError, "agent 'x': unknown joints \\['z'\\]"):
            ExplorationSupervisor(agents=[Agent("x", ["a", "z"], space)], **kwargs)
        with self.assertRaisesRegex(ValueError, "share a joint"):
            ExplorationSupervisor(
                agents=[Agent("x", ["a", "b"], space), Agent("y", ["b", "a"], space)], **kwargs
            )
        with self.assertRaisesRegex(ValueError, "2 dimensions for 1 joints"):
            ExplorationSupervisor(agents=[Agent("x", ["a"], space)], **kwargs)


class TestExperimentsSmoke(unittest.TestCase):
    """The ch. 7 experiment scripts on tiny budgets: they run the robot and write their files."""

    def test_coverage_rank_4_and_three_agents(self):
        import pathlib
        import tempfile

        from mobee_drake.experiments import ch7_command as experiments

        output = pathlib.Path(tempfile.mkdtemp())
        experiments.main(
            ["--experiment", "7.2", "--output", str(output), "--runs", "1", "--transitions", "3"]
        )
        for strategy in ("curious", "random", "least_tried"):
            result = json.loads(
                (output / "runs" / f"7.2_{strategy}_run0" / "result.json").read_text()
            )
            self.assertEqual(result["labels"]["strategy"], strategy)
            self.assertGreaterEqual(result["actions"][0], 3)  # the run's stop condition
            # The report's row holds the run's own numbers (issue 32: wrong numbers passed).
            transitions, tried = result["coverage"][-1]
            # Stopped by the cap before every state-action was tried: censored.
            self.assertIn(
                f"| {strategy} | 0 | {transitions} | {tried} | > {transitions} |",
                (output / "report_7.2.md").read_text(),
            )
        self.assertTrue((output / "7.2_coverage.png").is_file())
        experiments.main(["--experiment", "7.3", "--output", str(output), "--transitions", "2"])
        report = (output / "report_7.3.md").read_text()
        self.assertIn("| 20-80 |", report)
        self.assertIn("| 12.5-87.5 |", report)
        experiments.main(["--experiment", "7.4", "--output", str(output), "--transitions", "6"])
        report = (output / "report_7.4.md").read_text()
        three = json.loads(next((output / "runs").glob("7.4*/result.json")).read_text())
        right, left = (np.array(t, dtype=float) for t in three["tries"][:2])
        self.assertIn(
            "correlation of the right and the left arm's tries per state-action: "
            f"{np.corrcoef(right, left)[0, 1]:.3f}",
            report,
        )
        self.assertIn(f"- transitions: {sum(three['actions'])} ({three['actions']}", report)
        self.assertIn("hand-table contact", report)
        self.assertTrue((output / "7.4_three_agents.png").is_file())
        experiments.main(
            ["--experiment", "7.4.1", "--output", str(output), "--transitions", "4", "--runs", "1"]
        )
        self.assertIn("| moving_box |", (output / "report_7.4.1.md").read_text())

    def test_detour_problems(self):
        from mobee_drake.experiments import ch7_model_learning as experiments

        # The square 0-1-3-2 (equidistant neighbours): with 0->1 unreliable, 0 -> 3 (over 1 or 2)
        # and 2 -> 1 (over 0 or 3) have one risky and one safe shortest route; 3 -> 0 and 1 -> 2
        # have two safe ones.
        space = Lattice([0.0, 1.0], 2)
        unreliable = np.array(
            [(s, g) == (0, 1) for s, g in zip(space.action_state, space.action_goal)]
        )
        self.assertEqual(experiments.DetourProblems(space, unreliable), [(0, 3), (2, 1)])
        self.assertEqual(experiments.DetourProblems(space, np.zeros_like(unreliable)), [])


if __name__ == "__main__":
    unittest.main()
