"""A state-action space that reshapes itself (ch. 9.4.5): each rule and the carried-over model
against closed forms on small spaces."""

import json
import pathlib
import unittest
from unittest import mock

import numpy as np

from mobee_drake.planning import space_maintenance
from mobee_drake.planning.explorers import (
    INITIALIZATIONS,
    Explorer,
    ExplorerConfig,
    MissShares,
    ObservedOutcomes,
)
from mobee_drake.planning.space_maintenance import (
    CarryExplorer,
    EditSpace,
    Maintenance,
    MaintenanceConfig,
    SpaceTooLarge,
    VisitedStates,
)
from mobee_drake.planning.state_space import FromGraph, Lattice
from mobee_drake.planning.supervisor import SavedSettled

# The square: states 0 (0.25, 0.25), 1 (0.25, 0.75), 2 (0.75, 0.25), 3 (0.75, 0.75); actions
# 0: 0->1, 1: 0->2, 2: 1->0, 3: 1->3, 4: 2->0, 5: 2->3, 6: 3->1, 7: 3->2.
SQUARE = Lattice([0.25, 0.75], 2)


def _Action(space, state: int, goal: int) -> int:
    (action,) = [a for a in space.Actions(state) if space.action_goal[a] == goal]
    return int(action)


def _Tried(explorer: Explorer, state_action: int, outcome: int, times: int) -> None:
    for _ in range(times):
        explorer.Observe(state_action, outcome)


class TestTheModelsStatistics(unittest.TestCase):
    def test_observed_outcomes_and_misses(self):
        """A fresh model has observed nothing; then exactly what was observed, a first outcome
        in a new bin counted once (its bin's own 1 is not an observation)."""
        explorer = Explorer(SQUARE)
        self.assertFalse(ObservedOutcomes(explorer).toarray().any())
        _Tried(explorer, 0, 1, 2)  # arrived twice
        _Tried(explorer, 0, 0, 1)  # stayed once
        _Tried(explorer, 0, 3, 1)  # a new outcome
        observed = ObservedOutcomes(explorer).toarray()
        np.testing.assert_array_equal(observed[0], [1, 2, 0, 1])
        self.assertFalse(observed[1:].any())
        self.assertAlmostEqual(MissShares(explorer)[0], 0.5)
        self.assertEqual(MissShares(explorer)[1], 0.0)  # (untried)

    def test_observed_outcomes_are_the_formula_on_every_count(self):
        """Sparse, they are what the formula gives on the whole array, for any counts (even
        below the initialisation's) and either initialisation."""
        space, rng = Lattice([0.1, 0.5, 0.9], 2), np.random.default_rng(2)
        every = np.arange(space.num_state_actions)
        for initialization in INITIALIZATIONS:
            explorer = Explorer(space, ExplorerConfig(initialization=initialization))
            counts = explorer.transitions.counts
            counts[...] = rng.integers(0, 4, size=counts.shape) * (rng.random(counts.shape) < 0.3)
            initial = np.zeros_like(counts)
            initial[every, space.action_state] = 2.0
            initial[every, space.action_goal] = 1.0 + INITIALIZATIONS[initialization]
            formula = np.rint(counts - initial - ((counts > 0) & (initial == 0))).astype(int)
            self.assertTrue((formula < 0).any())  # (counts below the initialisation's)
            np.testing.assert_array_equal(ObservedOutcomes(explorer).toarray(), formula)


class TestEditSpace(unittest.TestCase):
    def test_drop_a_state_add_one_and_actions(self):
        """Drop state 3 of the square, add a state (index 4 before the drop) joined to 1 and
        a shortcut 0 -> 4: the remaining actions, renumbered, sorted by state then goal."""
        edit = EditSpace(
            SQUARE,
            drop_states=[3],
            drop_actions=[1],  # 0 -> 2
            new_centres=[[0.5, 0.75]],
            new_actions=[(4, 1), (1, 4), (0, 4)],
        )
        edited = edit.space
        np.testing.assert_array_equal(edit.state_index, [0, 1, 2, -1])
        np.testing.assert_allclose(edited.centres, [*SQUARE.centres[:3], [0.5, 0.75]])
        pairs = list(zip(edited.action_state.tolist(), edited.action_goal.tolist()))
        self.assertEqual(pairs, [(0, 1), (0, 3), (1, 0), (1, 3), (2, 0), (3, 1)])
        # 0->1 stays first, 0->2 is dropped, 1->0 third, 1->3 and 2->3 went with state 3 ...
        np.testing.assert_array_equal(edit.action_index, [0, -1, 2, -1, 4, -1, -1, -1])

    def test_the_model_is_carried_over(self):
        """Kept state-actions keep counts (columns renumbered), rewards and tries; new ones
        start as a fresh model's; the generator carries on."""
        explorer = Explorer(SQUARE, seed=3)
        _Tried(explorer, 0, 1, 3)
        _Tried(explorer, 4, 2, 2)  # 2 -> 0 missed twice
        explorer.rng.random()
        edit = EditSpace(
            SQUARE, drop_states=[3], new_centres=[[0.5, 0.75]], new_actions=[(4, 1), (1, 4)]
        )
        carried = CarryExplorer(explorer, edit)
        edited, action_index = edit.space, edit.action_index
        fresh = Explorer(edited)
        for old, new in enumerate(action_index):
            if new < 0:
                continue
            np.testing.assert_array_equal(
                carried.transitions.counts[new, :3], explorer.transitions.counts[old, :3]
            )
            self.assertEqual(carried.tries[new], explorer.tries[old])
            self.assertEqual(carried.rewards[new], explorer.rewards[old])
        added = np.setdiff1d(np.arange(edited.num_state_actions), action_index)
        self.assertEqual(len(added), 2)
        np.testing.assert_array_equal(
            carried.transitions.counts[added], fresh.transitions.counts[added]
        )
        np.testing.assert_array_equal(carried.rewards[added], fresh.rewards[added])
        np.testing.assert_array_equal(
            ObservedOutcomes(carried).toarray()[action_index[0]], [0, 3, 0, 0]
        )
        self.assertEqual(carried.rng.random(), _Generator(3, skip=1).random())


def _Generator(seed: int, skip: int) -> np.random.Generator:
    rng = np.random.default_rng(seed)
    for _ in range(skip):
        rng.random()
    return rng


class TestTheRules(unittest.TestCase):
    def test_an_unreachable_state_is_pruned_and_its_boundary_grown(self):
        """Every try into state 3 stays where it started: after prune_after of them state 3
        goes, with its 4 actions, and a state grows halfway between it and each of 1 and 2,
        joined both ways to the states within a side of it (1 or 2, and each other)."""
        explorer = Explorer(SQUARE)
        _Tried(explorer, 3, 1, 3)  # 1 -> 3 stayed in 1
        _Tried(explorer, 5, 2, 2)  # 2 -> 3 stayed in 2
        maintenance = Maintenance(MaintenanceConfig(rules=["prune", "grow"], prune_after=6), 4)
        same, state = maintenance.Apply(explorer, 0, 5)
        self.assertIs(same, explorer)  # 5 tries: not yet
        _Tried(explorer, 5, 2, 1)
        reshaped, state = maintenance.Apply(explorer, 0, 6)
        self.assertEqual(state, 0)
        np.testing.assert_allclose(reshaped.space.centres[3:], [[0.5, 0.75], [0.75, 0.5]])
        pairs = set(zip(reshaped.space.action_state.tolist(), reshaped.space.action_goal.tolist()))
        grown = {(1, 3), (3, 1), (2, 4), (4, 2), (3, 4), (4, 3)}
        self.assertEqual(pairs, {(0, 1), (0, 2), (1, 0), (2, 0)} | grown)
        self.assertEqual(
            [(c.rule, c.states) for c in maintenance.changes],
            [("prune", (3,)), ("grow", (3, 1)), ("grow", (3, 2))],
        )
        # The 3 tries of 1 -> 3, now 1 -> (0.5, 0.75), are not carried: a new action.
        self.assertEqual(reshaped.tries.sum(), 0)
        # With max_states the space grows while it has fewer, state 3 pruned: 3 + 2 under 5,
        # 3 + 1 under 4.
        for max_states, size in ((5, 5), (4, 4)):
            config = MaintenanceConfig(
                rules=["prune", "grow"], prune_after=6, max_states=max_states
            )
            self.assertEqual(Maintenance(config, 4).Apply(explorer, 0, 6)[0].space.num_states, size)

    def test_the_robots_state_is_never_pruned(self):
        """Nor a state it was in: the start, left by an action that arrived elsewhere."""
        explorer = Explorer(SQUARE)
        _Tried(explorer, 3, 1, 6)  # 1 -> 3 stayed in 1, 6 times
        reshaped, state = Maintenance(MaintenanceConfig(rules=["prune"]), 4).Apply(explorer, 3, 6)
        self.assertIs(reshaped, explorer)
        self.assertEqual(state, 3)
        _Tried(explorer, 6, 1, 1)  # 3 -> 1 arrived: the robot started in 3
        reshaped, state = Maintenance(MaintenanceConfig(rules=["prune"]), 4).Apply(explorer, 1, 7)
        self.assertIs(reshaped, explorer)
        self.assertEqual(state, 1)

    def test_a_state_the_robot_was_in_stays_when_the_model_forgets_it(self):
        """0 -> 1 arrived once and missed 4 times, 1 -> 3 missed 5 times: round 1 drops both
        and the model no longer shows the robot in 1 (1 -> 0, never tried, stays). 3 -> 1 then
        misses 6 times: state 1 is not pruned, as the robot was there."""
        config = MaintenanceConfig(rules=["prune", "drop"], prune_after=6)
        explorer, maintenance = Explorer(SQUARE), Maintenance(config, 4)

        def Tried(state: int, goal: int, outcome: int, times: int) -> None:
            state_action = _Action(explorer.space, state, goal)
            for _ in range(times):
                explorer.Observe(state_action, outcome)
                maintenance.Observe(explorer.space, state, state_action, outcome)

        Tried(0, 1, 1, 1)
        Tried(0, 1, 0, 4)
        Tried(1, 3, 1, 5)
        explorer, _ = maintenance.Apply(explorer, 0, 10)
        self.assertEqual([c.states for c in maintenance.changes], [(0, 1), (1, 3)])
        self.assertFalse(VisitedStates(explorer)[1])
        Tried(3, 1, 3, 6)
        explorer, _ = maintenance.Apply(explorer, 0, 16)
        self.assertEqual(explorer.space.num_states, 4)
        self.assertEqual([c.rule for c in maintenance.changes], ["drop"] * 3)  # (3 -> 1)
        np.testing.assert_array_equal(maintenance.entered, [True, True, False, True])
        restored = Maintenance.FromData(config, *maintenance.ToData())
        np.testing.assert_array_equal(restored.entered, maintenance.entered)

    def test_the_tries_of_a_dropped_transition_still_count_for_prune(self):
        """1 -> 3 stays in 1 five times: round 1 drops it (state 3, 5 tries into it, is not yet
        prunable at 6). One more try into 3, 2 -> 3, staying in 2: round 2 prunes state 3,
        its 6 tries counted."""
        config = MaintenanceConfig(rules=["prune", "drop"], prune_after=6)
        explorer, maintenance = Explorer(SQUARE), Maintenance(config, 4)
        _Tried(explorer, _Action(SQUARE, 1, 3), 1, 5)
        explorer, _ = maintenance.Apply(explorer, 0, 5)
        self.assertEqual([(c.rule, c.states) for c in maintenance.changes], [("drop", (1, 3))])
        np.testing.assert_array_equal(maintenance.dropped_tries, [0, 0, 0, 5])
        restored = Maintenance.FromData(config, *maintenance.ToData())
        np.testing.assert_array_equal(restored.dropped_tries, [0, 0, 0, 5])
        _Tried(explorer, _Action(explorer.space, 2, 3), 2, 1)
        explorer, _ = maintenance.Apply(explorer, 0, 6)
        self.assertEqual(maintenance.changes[-1].rule, "prune")
        self.assertEqual(maintenance.changes[-1].states, (3,))
        self.assertEqual(explorer.space.num_states, 3)
        np.testing.assert_array_equal(maintenance.dropped_tries, [0, 0, 0])

    def test_an_often_infeasible_transition_is_dropped_but_not_a_states_last(self):
        """0 -> 1 missed 4 of 5: dropped. 2's both actions missed every time: the one that
        missed least stays."""
        explorer = Explorer(SQUARE)
        _Tried(explorer, 0, 0, 4)
        _Tried(explorer, 0, 1, 1)
        _Tried(explorer, 4, 2, 5)
        _Tried(explorer, 5, 2, 4)
        _Tried(explorer, 5, 3, 1)
        maintenance = Maintenance(MaintenanceConfig(rules=["drop"]), 4)
        reshaped, _ = maintenance.Apply(explorer, 0, 10)
        self.assertEqual([c.states for c in maintenance.changes], [(0, 1), (2, 0)])
        pairs = set(zip(reshaped.space.action_state.tolist(), reshaped.space.action_goal.tolist()))
        self.assertEqual(pairs, {(0, 2), (1, 0), (1, 3), (2, 3), (3, 1), (3, 2)})

    def test_a_chain_often_taken_gets_a_shortcut(self):
        """0 -> 1 -> 3, each arriving, 5 times: an action 0 -> 3 (the diagonal), optimistic.
        A chain broken by a miss, or whose second action does not start where the first
        arrived, does not count."""
        maintenance = Maintenance(MaintenanceConfig(rules=["shortcut"], shortcut_after=5), 4)
        for _ in range(4):
            maintenance.Observe(SQUARE, 0, 0, 1)
            maintenance.Observe(SQUARE, 1, 3, 3)
        maintenance.Observe(SQUARE, 0, 0, 0)  # missed
        maintenance.Observe(SQUARE, 0, 1, 2)  # 0 -> 2 arrived, but the robot was moved to 1:
        maintenance.Observe(SQUARE, 1, 3, 3)  # no chain 0 -> 3
        self.assertEqual(maintenance.chains[0, 3], 4)
        maintenance.Observe(SQUARE, 0, 0, 1)
        maintenance.Observe(SQUARE, 1, 3, 3)
        explorer = Explorer(SQUARE)
        reshaped, _ = maintenance.Apply(explorer, 3, 20)
        self.assertEqual([c.states for c in maintenance.changes], [(0, 3)])
        shortcut = reshaped.space.Actions(0)[-1]
        self.assertEqual(reshaped.space.action_goal[shortcut], 3)
        self.assertEqual(reshaped.rewards[shortcut], Explorer(reshaped.space).rewards[shortcut])
        self.assertFalse(maintenance.chains.any())  # (it became an action: counted afresh)

    def test_a_favoured_state_is_developed(self):
        """The learner favours state 0: states grow halfway to its neighbours 1 and 2, at
        (0.25, 0.5) and (0.5, 0.25), each joined both ways to the states within a side of it
        (0 and its own neighbour, and each other), the rest as it was."""
        maintenance = Maintenance(MaintenanceConfig(rules=["develop"]), 4)
        edit = maintenance.Plan(Explorer(SQUARE), 3, 10, favoured=[0])
        np.testing.assert_allclose(edit.space.centres[4:], [[0.25, 0.5], [0.5, 0.25]])
        pairs = set(zip(edit.space.action_state.tolist(), edit.space.action_goal.tolist()))
        new = {(4, 0), (0, 4), (4, 1), (1, 4), (5, 0), (0, 5), (5, 2), (2, 5), (4, 5), (5, 4)}
        old = set(zip(SQUARE.action_state.tolist(), SQUARE.action_goal.tolist()))
        self.assertEqual(pairs, old | new)
        self.assertEqual([c.states for c in maintenance.changes], [(1, 0), (2, 0)])
        self.assertIsNone(
            Maintenance(MaintenanceConfig(rules=["develop"]), 4).Plan(Explorer(SQUARE), 3, 10)
        )  # (nothing favoured, nothing developed)
        # Joined within half a side (the action's ends): not to each other, 0.35 apart.
        local = Maintenance(MaintenanceConfig(rules=["develop"], join_within=0.5), 4)
        edit = local.Plan(Explorer(SQUARE), 3, 10, favoured=[0])
        pairs = set(zip(edit.space.action_state.tolist(), edit.space.action_goal.tolist()))
        self.assertEqual(pairs, old | new - {(4, 5), (5, 4)})

    def test_a_space_too_large_for_the_memory_is_refused_by_name(self):
        """With less memory available than the developed space's counts need (6 states by 18
        state-actions, 864 bytes a copy, three copies), the round is refused naming its step,
        the sizes and the bounds, and the maintenance is left as it was; with enough, it is
        made."""
        maintenance = Maintenance(MaintenanceConfig(rules=["develop"]), 4)
        with mock.patch.object(space_maintenance, "AvailableMemory", return_value=3 * 864 - 1):
            with self.assertRaisesRegex(
                SpaceTooLarge,
                r"^space maintenance after 10 actions \(or problem-tries\): the round planned 6 "
                r"states and 18 state-actions, whose outcome counts need 0\.0 GiB a copy, and a "
                r"round holds about 3: more than the 0\.0 GiB available; bound the space "
                r"\(max_states, or a smaller join_within\)$",
            ):
                maintenance.Plan(Explorer(SQUARE), 3, 10, favoured=[0])
        self.assertEqual(maintenance.changes, [])
        with mock.patch.object(space_maintenance, "AvailableMemory", return_value=3 * 864):
            self.assertEqual(
                maintenance.Plan(Explorer(SQUARE), 3, 10, favoured=[0]).space.num_states, 6
            )
        available = space_maintenance.AvailableMemory()  # (None where the system does not say)
        self.assertTrue(available is None or available > 2**20)

    def test_the_memory_available_is_the_systems_or_its_cgroups(self):
        """MemAvailable and free swap (kB), or the room under the cgroup's limit if less."""
        import tempfile

        with tempfile.TemporaryDirectory() as folder:
            root = pathlib.Path(folder)
            meminfo = root / "meminfo"
            meminfo.write_text("MemTotal: 9000 kB\nMemAvailable: 1000 kB\nSwapFree: 24 kB\n")
            available = space_maintenance.AvailableMemory(str(meminfo), str(root / "none"))
            self.assertEqual(available, 1024 * 1024)
            (root / "memory.max").write_text("500000\n")
            (root / "memory.current").write_text("100000\n")
            self.assertEqual(space_maintenance.AvailableMemory(str(meminfo), folder), 400000)
            (root / "memory.max").write_text("max\n")
            self.assertEqual(space_maintenance.AvailableMemory(str(meminfo), folder), 1024 * 1024)
            meminfo.write_text("MemTotal: 9000 kB\n")
            self.assertIsNone(space_maintenance.AvailableMemory(str(meminfo), folder))

    def test_settings_are_checked(self):
        with self.assertRaisesRegex(ValueError, "unknown rule 'trim'"):
            Maintenance(MaintenanceConfig(rules=["trim"]), 4)
        with self.assertRaisesRegex(ValueError, "drop_miss_share"):
            Maintenance(MaintenanceConfig(drop_miss_share=0.0), 4)
        self.assertTrue(Maintenance(MaintenanceConfig(every=50), 4).Due(100))
        self.assertFalse(Maintenance(MaintenanceConfig(every=0), 4).Due(100))
        until = Maintenance(MaintenanceConfig(every=50, until=100), 4)
        self.assertEqual([until.Due(n) for n in (50, 100, 150)], [True, False, False])
        with self.assertRaisesRegex(ValueError, "until must be >= 0"):
            Maintenance(MaintenanceConfig(until=-1), 4)
        with self.assertRaisesRegex(ValueError, "develop_min_targets must be >= 1"):
            Maintenance(MaintenanceConfig(develop_min_targets=0), 4)
        with self.assertRaisesRegex(ValueError, r"join_within must be >= 0.5 .*got 0.4"):
            Maintenance(MaintenanceConfig(join_within=0.4), 4)

    def test_a_dropped_transition_never_comes_back_as_a_shortcut(self):
        """On a line 0 - 1 - 2 with a direct 0 -> 2: 0 -> 2 missed 5 of 5 and is dropped; the
        chains 0 -> 1 -> 2 then taken 5 times do not bring it back (nor after a checkpoint)."""
        line = FromGraph([[0.0], [0.5], [1.0]], [(0, 1), (1, 2), (0, 2)])
        explorer = Explorer(line)
        zero_two = _Action(line, 0, 2)
        _Tried(explorer, zero_two, 0, 5)
        config = MaintenanceConfig(rules=["drop", "shortcut"], shortcut_after=5)
        maintenance = Maintenance(config, 3)
        explorer, _ = maintenance.Apply(explorer, 0, 100)
        self.assertEqual([(c.rule, c.states) for c in maintenance.changes], [("drop", (0, 2))])
        space = explorer.space
        for _ in range(5):
            maintenance.Observe(space, 0, _Action(space, 0, 1), 1)
            maintenance.Observe(space, 1, _Action(space, 1, 2), 2)
        self.assertEqual(maintenance.chains[0, 2], 5)
        chains, data = maintenance.ToData()
        resumed = Maintenance.FromData(config, chains, json.loads(json.dumps(data)))
        for m in (maintenance, resumed, maintenance.Continued()):
            self.assertIsNone(m.Plan(explorer, 0, 200))


class TestARoadmapSpace(unittest.TestCase):
    def test_growth_stops_at_the_spacing(self):
        """On a line 0 - 1 whose state 1 is unreachable, growth halves the gap each round
        until a new state would be nearer than min_spacing; then the last unreachable state
        stays, as 0's only action goes to it."""
        space = FromGraph([[0.0], [0.8]], [(0, 1)])
        explorer = Explorer(space)
        maintenance = Maintenance(
            MaintenanceConfig(rules=["prune", "grow"], prune_after=1, min_spacing=0.15), 2
        )
        centres = []
        for round_ in range(6):
            _Tried(explorer, explorer.space.Actions(0)[0], 0, 1)
            explorer, _ = maintenance.Apply(explorer, 0, round_)
            centres.append(explorer.space.centres[:, 0].tolist())
        self.assertEqual(centres, [[0.0, 0.4], [0.0, 0.2]] + 4 * [[0.0, 0.2]])


class TestOnTheSupervisor(unittest.TestCase):
    """The supervisor with the robot's state fixed by the test: a robot that never moves."""

    def test_a_planner_cannot_reshape_its_space(self):
        """A goal state's number would change with the space: refused, naming the agent."""
        from mobee_drake.planning.explorers import ExplorerConfig
        from mobee_drake.planning.supervisor import Agent, ExplorationSupervisor

        agent = Agent(
            name="arm",
            joints=["a"],
            space=FromGraph([[0.0], [1.0]], [(0, 1)]),
            explorer=ExplorerConfig(strategy="planner", goal_state=1),
            maintenance=MaintenanceConfig(),
        )
        with self.assertRaisesRegex(ValueError, "agent 'arm': a space that reshapes itself"):
            ExplorationSupervisor(
                agents=[agent], joints=["a"], lower=np.array([-1.0]), upper=np.array([1.0]),
                home=np.array([0.0]),
            )  # fmt: skip

    def test_an_exploring_agent_cannot_develop(self):
        """``develop`` grows states beside those a learner favours; the exploring agent
        favours none, so the rule would do nothing: refused, naming the agent."""
        from mobee_drake.planning.explorers import ExplorerConfig
        from mobee_drake.planning.supervisor import Agent, ExplorationSupervisor

        agent = Agent(
            name="arm",
            joints=["a"],
            space=FromGraph([[0.0], [1.0]], [(0, 1), (1, 0)]),
            explorer=ExplorerConfig(),
            maintenance=MaintenanceConfig(rules=["prune", "develop"]),
        )
        with self.assertRaisesRegex(ValueError, "agent 'arm': the rule 'develop' needs"):
            ExplorationSupervisor(
                agents=[agent], joints=["a"], lower=np.array([-1.0]), upper=np.array([1.0]),
                home=np.array([0.0]),
            )  # fmt: skip

    def _Dut(self, maintenance=None):
        from mobee_drake.planning.explorers import ExplorerConfig
        from mobee_drake.planning.supervisor import ActionTiming, Agent, ExplorationSupervisor

        line = FromGraph([[0.0], [0.5], [1.0]], [(0, 1), (1, 2)])
        agent = Agent(
            name="arm",
            joints=["a"],
            space=line,
            explorer=ExplorerConfig(strategy="least_tried"),
            maintenance=maintenance
            or MaintenanceConfig(every=4, rules=["prune", "grow"], prune_after=2),
        )
        return ExplorationSupervisor(
            agents=[agent],
            joints=["a"],
            lower=np.array([-1.0]),
            upper=np.array([1.0]),
            home=np.array([0.0]),
            timing=ActionTiming(settle_time=0.0, min_duration=0.0),
        )

    def _Poll(self, dut, context, actions: int, follow: bool = False) -> None:
        """Polls that each end an action (the robot is still); with ``follow`` the robot is
        where the attractor sends it, so each action arrives."""
        for _ in range(actions):
            if follow:
                attractor = dut.GetOutputPort("attractor").Eval(context)
                dut.GetInputPort("robot_state").FixValue(context, [attractor[0], 0.0])
            context.SetTime(context.get_time() + 0.2)
            dut.CalcForcedUnrestrictedUpdate(context, context.get_mutable_state())

    def test_the_space_closes_in_on_a_robot_that_never_moves(self):
        """The robot stays at 0.5 (state 1): every try misses. After 4 actions (least-tried:
        each neighbour twice) both neighbours go and states grow halfway to them, joined to
        the robot's state and to each other (within the 0.5 they grew from); 4 actions later
        the same again at a quarter. The data log counts the space and its changes."""
        dut = self._Dut()
        context = dut.CreateDefaultContext()
        dut.GetInputPort("robot_state").FixValue(context, [0.0, 0.0])  # (0.5 of [-1, 1])
        dut.ExecuteInitializationEvents(context)
        self._Poll(dut, context, 4)
        (record,) = dut.Records(context)
        np.testing.assert_allclose(record.explorer.space.centres[:, 0], [0.5, 0.25, 0.75])
        self.assertEqual(record.state, 0)
        self.assertEqual(record.settled, 4 * ((0.5,),))  # (where each action ended)
        np.testing.assert_array_equal(record.maintenance.entered, [True, False, False])
        np.testing.assert_allclose(dut.GetOutputPort("data_log").Eval(context)[3:], [3, 6, 4])
        goal = record.explorer.space.action_goal[record.state_action]
        attractor = dut.GetOutputPort("attractor").Eval(context)
        self.assertAlmostEqual(attractor[0], -1 + 2 * record.explorer.space.centres[goal, 0])
        self._Poll(dut, context, 4)
        (record,) = dut.Records(context)
        np.testing.assert_allclose(record.explorer.space.centres[:, 0], [0.5, 0.375, 0.625])
        self.assertEqual(
            [c.rule for c in record.maintenance.changes], 2 * ["prune", "prune", "grow", "grow"]
        )
        self.assertEqual(
            [name for name, _ in dut.DataLogColumns()][3:],
            ["agent.arm.states", "agent.arm.state_actions", "agent.arm.space_changes"],
        )

    def _Resumed(self, maintenance, actions: int, follow: bool):
        """(the run not interrupted, the run saved after ``actions`` and read into a new
        supervisor), each ``actions`` more; and the maintenance as it was saved."""
        import tempfile

        straight, resumed = self._Dut(maintenance), self._Dut(maintenance)
        contexts = []
        for dut in (straight, resumed):
            context = dut.CreateDefaultContext()
            dut.GetInputPort("robot_state").FixValue(context, [0.0, 0.0])
            dut.ExecuteInitializationEvents(context)
            contexts.append(context)
        self._Poll(straight, contexts[0], actions, follow)
        (saved,) = straight.Records(contexts[0])
        settled, saved = saved.settled, saved.maintenance.ToData()
        with tempfile.TemporaryDirectory() as folder:
            straight.WriteCheckpoint(contexts[0], pathlib.Path(folder))
            resumed.ReadCheckpoint(contexts[1], pathlib.Path(folder))
            np.testing.assert_array_equal(SavedSettled(folder, "arm"), settled)
        contexts[1].SetTime(contexts[0].get_time())
        where = straight.GetInputPort("robot_state").Eval(contexts[0])  # (the robot stays)
        resumed.GetInputPort("robot_state").FixValue(contexts[1], where)
        for dut, context in zip((straight, resumed), contexts):
            self._Poll(dut, context, actions, follow)
        (a,), (b,) = (dut.Records(c) for dut, c in zip((straight, resumed), contexts))
        np.testing.assert_array_equal(a.explorer.space.centres, b.explorer.space.centres)
        np.testing.assert_array_equal(a.explorer.transitions.counts, b.explorer.transitions.counts)
        np.testing.assert_array_equal(a.maintenance.chains, b.maintenance.chains)
        np.testing.assert_array_equal(a.maintenance.entered, b.maintenance.entered)
        self.assertEqual(a.maintenance.changes, b.maintenance.changes)
        self.assertEqual((len(a.settled), a.settled), (2 * actions, b.settled))
        return a, saved

    def test_a_model_learned_before_brings_its_maintenance(self):
        """A run started from a maintained agent's saved model carries on its maintenance
        (where it pruned: nothing grows back there), but no chain from the last run's last
        action."""
        import tempfile

        from mobee_drake.planning.explorers import LoadAgentModel
        from mobee_drake.planning.supervisor import Agent, ExplorationSupervisor, SavedMaintenance

        dut = self._Dut()
        context = dut.CreateDefaultContext()
        dut.GetInputPort("robot_state").FixValue(context, [0.0, 0.0])
        dut.ExecuteInitializationEvents(context)
        self._Poll(dut, context, 4)  # (the robot stays: a round prunes and grows)
        self._Poll(dut, context, 3, follow=True)  # (then it arrives: chains are counted)
        (record,) = dut.Records(context)
        self.assertGreaterEqual(record.maintenance.ToData()[1]["previous"], 0)
        self.assertTrue(record.maintenance.chains.any())
        config = MaintenanceConfig(every=4, rules=["prune", "grow"], prune_after=2)
        with tempfile.TemporaryDirectory() as folder:
            dut.WriteCheckpoint(context, pathlib.Path(folder))
            model = LoadAgentModel(folder, "arm", record.explorer.config)
            before = SavedMaintenance(folder, "arm", config)
            saved = pathlib.Path(folder) / "arm.json"  # (as a fixed agent's: none)
            saved.write_text(json.dumps(json.loads(saved.read_text()) | dict(maintenance=None)))
            self.assertIsNone(SavedMaintenance(folder, "arm", config))
        self.assertEqual(before.changes, record.maintenance.changes)
        agent = Agent(
            name="arm", joints=["a"], space=model.space, explorer=record.explorer.config,
            model=model, maintenance=config, maintained_before=before,
        )  # fmt: skip
        again = ExplorationSupervisor(
            agents=[agent], joints=["a"], lower=np.array([-1.0]), upper=np.array([1.0]),
            home=np.array([0.0]),
        )  # fmt: skip
        context = again.CreateDefaultContext()
        again.GetInputPort("robot_state").FixValue(context, [0.0, 0.0])
        again.ExecuteInitializationEvents(context)
        (started,) = again.Records(context)
        self.assertEqual(started.maintenance.changes, record.maintenance.changes)
        np.testing.assert_array_equal(started.maintenance.chains, record.maintenance.chains)
        self.assertEqual(started.maintenance.ToData()[1]["previous"], -1)

    def test_a_checkpoint_keeps_the_space_and_its_maintenance(self):
        """Saved after 6 actions and read into a new supervisor, the run goes on exactly as
        the one not interrupted: a robot that never moves (its space pruned and grown), and
        one that arrives every time (chains counted into shortcuts: the checkpoint holds
        chains and the last action's start and end)."""
        a, _ = self._Resumed(None, 6, follow=False)
        self.assertEqual(len(a.maintenance.changes), 12)
        chains = MaintenanceConfig(every=4, rules=["shortcut"], shortcut_after=2)
        a, (saved_chains, saved) = self._Resumed(chains, 6, follow=True)
        self.assertTrue(saved_chains.any())
        self.assertGreaterEqual(min(saved["previous"], saved["arrival"]), 0)
        self.assertIn("shortcut", [c.rule for c in a.maintenance.changes])


class TestTheReachLearner(unittest.TestCase):
    """The reach learner moved onto a reshaped space: its histories and log follow."""

    def test_histories_and_log_follow_their_state_actions(self):
        """On the square, state 3 pruned: transition 0 -> 1 (0) keeps its number, 2 -> 0 (4)
        becomes 3; the reach of state 2 (8 + 2 = 10) becomes 4 + 2 = 6; the reach of state 3
        (11) and 1 -> 3 (3) go. A learner rebuilt from the renumbered log has the same
        histories."""
        from mobee_drake.reaching.learner import ReachLearner

        explorer = Explorer(SQUARE)
        learner = ReachLearner(SQUARE, explorer.transitions.counts, np.zeros((1, 3)))
        records = {0: (0, 0, 1), 4: (2, 2, 0), 10: (2, 2, 2), 11: (3, 3, 3), 3: (1, 1, 1)}
        for sa, (s, _, o) in records.items():
            target = np.array([0.1 * sa, 0.0, 0.0])
            learner.histories.Record(sa, target, 0.5, float(sa))
            learner.log.append((0, 0, sa, s, o, 0.5, float(sa), *target))
        edit = EditSpace(SQUARE, drop_states=[3])
        counts = CarryExplorer(explorer, edit).transitions.counts
        learner.Reshape(edit, counts)
        with self.assertRaisesRegex(ValueError, "tried already; Reshape"):
            learner.PutOnSpace(edit.space, counts)  # (for a fresh learner only)
        self.assertEqual((learner.num_transitions, learner.num_state_actions), (4, 7))
        moved = {0: 0, 4: 3, 10: 6}
        for old, new in moved.items():
            _, rewards = learner.histories.Records(new)
            np.testing.assert_array_equal(rewards, [float(old)])
        self.assertEqual(sum(len(learner.histories.Records(sa)[1]) for sa in range(7)), 3)
        self.assertEqual([entry[2] for entry in learner.log], [0, 3, 6, -1, -1])
        self.assertEqual([entry[3] for entry in learner.log], [0, 2, 2, -1, 1])
        rebuilt = ReachLearner(edit.space, counts, np.zeros((1, 3)))
        arrays, data = learner.ToArrays()
        rebuilt.LoadArrays(arrays, data)
        for sa in range(7):
            np.testing.assert_array_equal(
                rebuilt.histories.Records(sa)[1], learner.histories.Records(sa)[1]
            )
        # A second round (state 1 pruned: 0 -> 2 and 2 -> 0 stay as 0 and 1, the reach of
        # state 2 becomes 2 + 1 = 3): the entries dropped by the first round stay dropped, the
        # others follow again, and the histories rebuilt from the log are still the live ones.
        second = EditSpace(edit.space, drop_states=[1])
        learner.Reshape(second, CarryExplorer(Explorer(edit.space), second).transitions.counts)
        self.assertEqual([entry[2] for entry in learner.log], [-1, 1, 3, -1, -1])
        self.assertEqual([entry[3] for entry in learner.log], [0, 1, 1, -1, -1])
        self.assertEqual([entry[4] for entry in learner.log], [-1, 0, 1, -1, -1])
        rebuilt = ReachLearner(second.space, learner.model.counts, np.zeros((1, 3)))
        arrays, data = learner.ToArrays()
        rebuilt.LoadArrays(arrays, data)
        for sa in range(learner.num_state_actions):
            np.testing.assert_array_equal(
                rebuilt.histories.Records(sa)[1], learner.histories.Records(sa)[1]
            )
        self.assertEqual(
            [len(rebuilt.histories.Records(sa)[1]) for sa in range(learner.num_state_actions)],
            [0, 1, 0, 1],
        )

    def test_a_round_on_the_reach_learners_space(self):
        """The learner's MDP (every try into state 3 missed, 6 of them) seen as an explorer's
        model: state 3 is pruned and the learner moves; its favoured states are those whose
        reaches earned most over enough different targets; a transition chain is shown to the
        maintenance from the log."""
        from mobee_drake.reaching.learner import ReachLearner
        from mobee_drake.reaching.reshaping import (
            FavouredStates,
            MaintainReachSpace,
            ModelView,
            ObserveTransitions,
        )

        explorer = Explorer(SQUARE)
        _Tried(explorer, 3, 1, 3)  # 1 -> 3 stayed in 1
        _Tried(explorer, 5, 2, 3)  # 2 -> 3 stayed in 2
        _Tried(explorer, 0, 1, 2)  # 0 -> 1 arrived twice
        learner = ReachLearner(SQUARE, explorer.transitions.counts, np.zeros((1, 3)))
        np.testing.assert_array_equal(ModelView(learner).tries, explorer.tries)
        # (state 0: two targets; 1: one; 2: one target twice)
        for state, x, reward in ((0, 0, 0.2), (0, 1, 0.4), (1, 0, 0.9), (2, 0, 0.1), (2, 0, 0.1)):
            learner.histories.Record(learner.Reach(state), np.array([x, 0, 0.0]), 0.0, reward)
        self.assertEqual(FavouredStates(learner, 2, 2), [0])
        self.assertEqual(FavouredStates(learner, 5, 1), [1, 0, 2])
        self.assertEqual(FavouredStates(learner, 2, 1), [1, 0])
        maintenance = Maintenance(MaintenanceConfig(rules=["prune"]), 4)
        self.assertTrue(MaintainReachSpace(learner, maintenance, 0, 50))
        self.assertEqual(learner.space.num_states, 3)
        np.testing.assert_array_equal(learner.histories.Records(learner.Reach(1))[1], [0.9])
        self.assertFalse(MaintainReachSpace(learner, maintenance, 0, 100))  # (nothing left)
        # A state the MDP never shows the robot in, but the learner's log does (it reached
        # from there): not pruned, its reach's history kept.
        unseen = Explorer(SQUARE)
        _Tried(unseen, 3, 1, 6)  # 1 -> 3 stayed in 1, 6 times
        logged = ReachLearner(SQUARE, unseen.transitions.counts, np.zeros((1, 3)))
        logged.histories.Record(logged.Reach(3), np.zeros(3), 0.0, 0.7)
        logged.log.append((0, 0, logged.Reach(3), 3, 3, 0.0, 0.7, 0, 0, 0))
        prune = MaintenanceConfig(rules=["prune"])
        self.assertFalse(MaintainReachSpace(logged, Maintenance(prune, 4), 0, 50))
        logged.log.clear()  # (the same without the log's record: state 3 goes)
        self.assertTrue(MaintainReachSpace(logged, Maintenance(prune, 4), 0, 50))
        # 1 -> 0 -> 2, each arriving, a reach between them: one chain from 1 to 2.
        space = learner.space
        one_zero, zero_two = (
            int(space.Actions(a)[space.action_goal[space.Actions(a)] == b][0])
            for a, b in ((1, 0), (0, 2))
        )
        learner.log += [
            (0, 0, one_zero, 1, 0, 0.0, 0.0, 0, 0, 0),
            (0, 0, learner.Reach(0), 0, 0, 0.0, 0.5, 0, 0, 0),
            (0, 0, zero_two, 0, 2, 0.0, 0.0, 0, 0, 0),
        ]
        ObserveTransitions(learner, maintenance, 0)
        self.assertEqual(maintenance.chains.sum(), 1)
        self.assertEqual(maintenance.chains[1, 2], 1)


class TestGrowthNeverReturns(unittest.TestCase):
    def test_no_state_grows_back_where_one_was_pruned(self):
        """A line 0 - 0.5 - 1: 0.5 is pruned and states grow at 0.25 and 0.75 (joined to each
        other, 0.5 apart). When 0.75 is pruned too, growth goes halfway to 1 (0.875) but not
        halfway to 0.25, which is where 0.5 was pruned."""
        explorer = Explorer(FromGraph([[0.0], [0.5], [1.0]], [(0, 1), (1, 2)]))
        maintenance = Maintenance(MaintenanceConfig(rules=["prune", "grow"], prune_after=1), 3)
        for sa in (0, 3):  # 0 -> 0.5 and 1 -> 0.5, each missed once
            _Tried(explorer, sa, explorer.space.action_state[sa], 1)
        explorer, _ = maintenance.Apply(explorer, 0, 1)
        np.testing.assert_allclose(explorer.space.centres[:, 0], [0.0, 1.0, 0.25, 0.75])
        space = explorer.space
        for sa in np.flatnonzero(space.action_goal == 3):  # every try into 0.75 missed
            _Tried(explorer, sa, space.action_state[sa], 1)
        explorer, _ = maintenance.Apply(explorer, 0, 2)
        np.testing.assert_allclose(explorer.space.centres[:, 0], [0.0, 1.0, 0.25, 0.875])


class TestInAScenario(unittest.TestCase):
    def test_a_scenario_turns_it_on_and_logs_the_space(self):
        """The shipped hypercube scenario with `maintenance: {every: 3}` for its agent: the
        agent's record carries the maintenance and the data log its three columns."""
        from mobee_drake.scenario import BuildScenario, LoadScenario

        scenario = LoadScenario(
            "explore_hypercube",
            [
                "{attractor: !ExploreAttractor {agents: [{name: right_arm, joints: "
                "[r_shoulder_pitch, r_shoulder_roll, r_shoulder_yaw, r_elbow], levels: "
                "[0.25, 0.75], maintenance: {every: 3}}]}}"
            ],
        )
        self.assertEqual(scenario.attractor.agents[0].maintenance.every, 3)
        station = BuildScenario(scenario)
        supervisor = station.client
        names = [name for name, _ in supervisor.DataLogColumns()]
        self.assertEqual(names[-3:], [f"agent.right_arm.{c}" for c in _MAINTENANCE_COLUMNS])
        context = supervisor.CreateDefaultContext()
        supervisor.GetInputPort("robot_state").FixValue(
            context, np.zeros(2 * len(station.mobee.joints))
        )
        supervisor.ExecuteInitializationEvents(context)
        self.assertEqual(supervisor.Records(context)[0].maintenance.config.every, 3)


_MAINTENANCE_COLUMNS = ("states", "state_actions", "space_changes")
