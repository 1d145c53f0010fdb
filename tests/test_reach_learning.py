"""The state-action executor (fixed input ports), and the reach-learning battery on the robot."""

import contextlib
import dataclasses as dc
import io
import json
import pathlib
import tempfile
import unittest
from unittest import mock

import numpy as np
from pydrake.common.eigen_geometry import AngleAxis
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.systems.analysis import Simulator

from mobee_drake.behaviours.torso import PostureGrid
from mobee_drake.experiments.ch8_reaching import LoadTrainedLearner
from mobee_drake.mobee.fields import FieldPairs
from mobee_drake.planning.supervisor import ActionTiming
from mobee_drake.reaching.appearance import AppearanceWatch
from mobee_drake.reaching.robot import SimulatedRobot
from mobee_drake.robots.icub import TORSO_JOINTS, IcubConfig
from mobee_drake.scenario import BuildScenario
from mobee_drake.station.executor import Phase, ReachForcing, StateActionExecutor


class TestStateActionExecutor(unittest.TestCase):
    def setUp(self):
        self.timing = ActionTiming(settle_speed=0.1, settle_time=0.5, min_duration=1.0, timeout=5.0)
        self.forcing = ReachForcing(marker="palm", force=300.0, softening=0.05)
        self.dut = StateActionExecutor(
            num_joints=2,
            marker_index=1,
            num_markers=2,
            initial_attractor=np.array([0.1, 0.2]),
            forcing=self.forcing,
            timing=self.timing,
            period=0.1,
        )
        self.simulator = Simulator(self.dut)
        self.context = self.simulator.get_mutable_context()
        self.markers = np.array([9.0, 9.0, 9.0, 0.1, 0.2, 0.3])
        self.dut.GetInputPort("marker_positions").FixValue(self.context, self.markers)
        self.Pairs([])
        self.Velocity([0.0, 0.0])

    def Pairs(self, b_is_robot):
        """Fixes MoBeE's field pairs: one per entry, against the robot (True) or not."""
        k = len(b_is_robot)
        pairs = FieldPairs(
            [None] * k,
            [None] * k,
            distance=np.zeros(k),
            margin=np.full(k, 0.05),
            p_WCa=np.zeros((k, 3)),
            nhat_BA_W=np.zeros((k, 3)),
            row_A=np.zeros(k, dtype=int),
            row_B=np.where(b_is_robot, 1, -1),
            X_WA=np.zeros((k, 3, 4)),
            X_WB=np.zeros((k, 3, 4)),
        )
        self.dut.GetInputPort("field_pairs").FixValue(self.context, AbstractValue.Make(pairs))

    def Velocity(self, v):
        self.dut.GetInputPort("robot_state").FixValue(self.context, np.concatenate([[0, 0], v]))

    def Attractor(self):
        return self.dut.GetOutputPort("attractor").Eval(self.context)

    def Forces(self):
        return self.dut.GetOutputPort("marker_forces").Eval(self.context).reshape(2, 3)

    def test_idle_keeps_the_initial_attractor_and_no_force(self):
        self.simulator.AdvanceTo(3.0)
        np.testing.assert_array_equal(self.Attractor(), [0.1, 0.2])
        np.testing.assert_array_equal(self.Forces(), 0.0)
        self.assertTrue(self.dut.Done(self.context))

    def test_transition_ends_when_settled(self):
        self.dut.StartTransition(self.context, np.array([0.5, -0.5]))
        np.testing.assert_array_equal(self.Attractor(), [0.5, -0.5])
        np.testing.assert_array_equal(self.Forces(), 0.0)
        self.Velocity([0.0, 0.2])  # moving: not settled
        self.simulator.AdvanceTo(2.05)
        self.assertEqual(self.dut.CurrentPhase(self.context), Phase.MOVING)
        self.Velocity([0.05, -0.05])  # slow from the poll at 2.1 s; settled 0.5 s later
        self.simulator.AdvanceTo(2.55)
        self.assertFalse(self.dut.Done(self.context))
        self.simulator.AdvanceTo(2.65)
        self.assertTrue(self.dut.Done(self.context))
        self.assertEqual(self.dut.CompletedActions(self.context), 1)
        np.testing.assert_array_equal(self.Attractor(), [0.5, -0.5])  # q* stays

    def test_transition_times_out(self):
        self.dut.StartTransition(self.context, np.array([0.5, -0.5]))
        self.Velocity([1.0, 0.0])
        self.simulator.AdvanceTo(4.95)
        self.assertFalse(self.dut.Done(self.context))
        self.simulator.AdvanceTo(5.05)
        self.assertTrue(self.dut.Done(self.context))

    def test_reach_forces_then_returns(self):
        target = np.array([0.4, 0.6, 0.3])
        self.dut.StartReach(self.context, np.array([0.3, 0.3]), target)
        error = target - self.markers[3:]  # |error| = 0.5
        np.testing.assert_allclose(self.Forces()[1], 300.0 * error / 0.55)
        np.testing.assert_array_equal(self.Forces()[0], 0.0)
        np.testing.assert_array_equal(self.Attractor(), [0.3, 0.3])
        self.simulator.AdvanceTo(1.55)  # slow since 0.1 s: settled at the 1.0 s minimum
        self.assertEqual(self.dut.CurrentPhase(self.context), Phase.RETURNING)
        np.testing.assert_array_equal(self.dut.ReachedPosition(self.context), self.markers[3:])
        np.testing.assert_array_equal(self.Forces(), 0.0)
        # Settles a second time (a new phase: min_duration again) and ends.
        self.simulator.AdvanceTo(1.95)
        self.assertFalse(self.dut.Done(self.context))
        self.simulator.AdvanceTo(2.05)
        self.assertTrue(self.dut.Done(self.context))

    def test_felt_object_latches_for_one_action(self):
        self.dut.StartTransition(self.context, np.array([0.5, -0.5]))
        self.Velocity([0.0, 0.2])
        self.Pairs([True, True])  # a self-collision: the robot's own body
        self.simulator.AdvanceTo(0.55)
        self.assertFalse(self.dut.FeltObject(self.context))
        self.Pairs([True, False])  # and an object, felt at the poll at 0.6 s ...
        self.simulator.AdvanceTo(0.65)
        self.assertTrue(self.dut.FeltObject(self.context))
        self.Pairs([])  # ... is remembered until the action ends
        self.Velocity([0.0, 0.0])
        self.simulator.AdvanceTo(2.0)
        self.assertTrue(self.dut.Done(self.context))
        self.assertTrue(self.dut.FeltObject(self.context))
        self.dut.StartTransition(self.context, np.array([0.1, 0.1]))  # a new action forgets it
        self.assertFalse(self.dut.FeltObject(self.context))

    def test_bad_commands(self):
        with self.assertRaisesRegex(ValueError, "q\\* must have 2 entries"):
            self.dut.StartTransition(self.context, np.zeros(3))
        with self.assertRaisesRegex(ValueError, "three finite numbers"):
            self.dut.StartReach(self.context, np.zeros(2), [0, np.nan, 0])
        self.dut.StartTransition(self.context, np.zeros(2))
        with self.assertRaisesRegex(ValueError, "in flight"):
            self.dut.StartTransition(self.context, np.zeros(2))


class TestTargets(unittest.TestCase):
    def test_grid_of_27_clear_of_the_robot_at_home(self):
        from mobee_drake.reaching.targets import LoadTargetGrid

        grid = LoadTargetGrid()
        centres = grid.Centres()
        self.assertEqual(centres.shape, (27, 3))
        self.assertEqual(len(np.unique(centres, axis=0)), 27)
        self.assertTrue(np.all(centres[:, 0] < -0.1))  # in front of the robot (it faces -x)

    def test_bad_grid_file(self):
        from mobee_drake.reaching.targets import LoadTargetGrid
        from mobee_drake.yaml_io import YamlFileError

        with tempfile.TemporaryDirectory() as folder:
            path = pathlib.Path(folder) / "grid.yaml"
            path.write_text("radius: 0.05\nx: [0.1]\ny: []\nz: [0.2]\n")
            with self.assertRaisesRegex(YamlFileError, "grid.yaml: 'y' needs at least one"):
                LoadTargetGrid(path)


class TestMdpLearning(unittest.TestCase):
    def test_it_stops_at_the_tries_or_at_the_cap(self):
        """Every state-action tried enough, or MDP_ACTIONS_PER_TRY actions per state-action and
        try asked for, whichever comes first (a state the arm cannot enter never stops it)."""
        from mobee_drake.experiments.ch8_reaching import MDP_ACTIONS_PER_TRY, _Learned

        explorer = mock.Mock(tries=np.array([5, 7]))
        self.assertTrue(_Learned(explorer, 5))
        explorer.tries = np.array([0, 2 * 5 * MDP_ACTIONS_PER_TRY - 1])
        self.assertFalse(_Learned(explorer, 5))
        explorer.tries[1] += 1
        self.assertTrue(_Learned(explorer, 5))


class TestBattery(unittest.TestCase):
    """A reduced battery on the kinematic iCub: every strategy, real reaches and evaluations."""

    @classmethod
    def setUpClass(cls):
        from mobee_drake.experiments.ch8_reaching import RunSettings, TrainMdp

        cls.folder = tempfile.TemporaryDirectory()
        cls.output = pathlib.Path(cls.folder.name)
        cls.mdp = cls.output / "mdp"
        cls.model = TrainMdp(cls.mdp, min_tries=1)
        cls.Settings = RunSettings

    @classmethod
    def tearDownClass(cls):
        cls.folder.cleanup()

    def Run(self, name, settings):
        from mobee_drake.experiments.ch8_reaching import RunOne

        return RunOne(self.output / name, self.mdp, settings)

    def test_watch_in_meshcat(self):
        from pydrake.geometry import Meshcat

        from mobee_drake.experiments.ch8_reaching import ReachRobot

        meshcat = Meshcat()
        robot = ReachRobot(self.model.space, 0.05, meshcat=meshcat)
        robot.simulator.set_target_realtime_rate(0.0)  # the test need not wait
        robot.SetProblem(np.array([-0.23, 0.22, 0.19]))
        state = robot.State()
        robot.Transition(int(self.model.space.action_goal[self.model.space.Actions(state)[0]]))
        self.assertTrue(meshcat.HasPath("/drake/illustration"))

    def PalmAtNeighbour(self, robot, action: int):
        """(the robot's state, the goal of its ``action``-th action, where the palm is there):
        the robot goes there with a target far away and comes back."""
        space = self.model.space
        start = robot.State()
        goal = int(space.action_goal[space.Actions(start)[action]])
        robot.SetProblem(np.array([1.0, 1.0, 1.0]))  # far away
        self.assertEqual(robot.Transition(goal), goal)
        self.assertFalse(robot.FeltObject())
        palm = robot.MarkerPosition()
        self.assertEqual(robot.Transition(start), start)
        return start, goal, palm

    def test_fields_feel_the_target_in_the_way(self):
        from mobee_drake.experiments.ch8_reaching import ReachRobot

        robot = ReachRobot(self.model.space, 0.05)
        start, goal, palm = self.PalmAtNeighbour(robot, 0)
        robot.SetProblem(palm)  # where the palm was at the goal: in the way
        robot.Transition(goal)
        self.assertTrue(robot.FeltObject())

    def test_a_reach_ends_its_problem_and_takes_the_target_away(self):
        """A target where the palm is at a neighbour state, clear of the resting arm: the robot
        settles there beside it, and the reach lets the palm into it and brings it back to the
        state's centre, inside it. The problem-try is then over and the target gone, so the
        move after it has nothing to push the palm out of (it took 6 penetrating periods when
        the target stayed); the next problem's target appears anew."""
        from mobee_drake.experiments.ch8_reaching import ReachRobot
        from mobee_drake.reaching.targets import TARGET_NAME
        from mobee_drake.station.safety import Penetrations

        robot = ReachRobot(self.model.space, 0.05)
        start, neighbour, palm = self.PalmAtNeighbour(robot, 3)
        robot.SetProblem(palm)
        self.assertFalse(Penetrations(robot.station.diagram, robot.context))
        self.assertEqual(robot.Transition(neighbour), neighbour)
        robot.Reach(palm)
        world = robot.station.world
        self.assertNotIn(TARGET_NAME, world.Names(robot.context))
        self.assertIsNone(robot.target)
        before = robot.Safety().penetrating_steps
        self.assertEqual(robot.Transition(start), start)
        self.assertEqual(robot.Safety().penetrating_steps, before)
        robot.SetProblem(palm)
        self.assertIn(TARGET_NAME, world.Names(robot.context))

    def test_the_learning_frame_follows_the_shoulder(self):
        """With the torso at home a target is where it is; with the torso turned by theta about
        its yaw axis, the learner sees it turned back by theta about that axis (closed form),
        which puts it where it is relative to the shoulder."""
        from mobee_drake.experiments.ch8_reaching import RIGHT_ARM, ReachScenario

        scenario = ReachScenario()
        scenario.robot = IcubConfig(controlled_joints=list(TORSO_JOINTS) + RIGHT_ARM)
        robot = SimulatedRobot(BuildScenario(scenario), RIGHT_ARM, self.model.space, 0.05)
        target = np.array([-0.3, 0.2, 0.1])
        np.testing.assert_allclose(robot.LearningFrame(target), target, atol=1e-12)
        mobee, plant = robot.station.mobee, robot.station.plant
        q = mobee.home
        q[mobee.joint_index("torso_yaw")] = np.radians(20.0)
        robot.MoveTo(q)
        turned = robot.station.robot_state.Eval(robot.context)[mobee.joint_index("torso_yaw")]
        self.assertGreater(np.degrees(turned), 10.0)  # (settled near 20 deg)
        joint = plant.GetJointByName("torso_yaw")
        context = plant.CreateDefaultContext()
        X_WJ = joint.frame_on_parent().CalcPoseInWorld(context)  # the axis doesn't move
        axis = X_WJ.rotation() @ joint.revolute_axis()
        back = RigidTransform(RotationMatrix(AngleAxis(-turned, axis)))
        expected = X_WJ.translation() + back @ (target - X_WJ.translation())
        np.testing.assert_allclose(robot.LearningFrame(target), expected, atol=1e-9)

    def test_the_torso_reach_smoke_battery(self):
        """A learner of 4 problem-tries, evaluated on 3 targets inside and outside the reach,
        the torso module on and off, 2 seeds: every run reports, the report pairs them, and
        the outside targets are the inside ones moved away from the shoulder."""
        from mobee_drake.experiments import torso_reach

        settings = self.Settings("greedy", 0, 4, [4], 1, 4, mdp="simultaneous")
        learner_dir = self.output / "torso_learner"
        self.Run("torso_learner", settings)
        (learner_dir / "job.json").write_text(
            json.dumps({"settings": dc.asdict(settings), "mdp": "(learned with the reaches)"})
        )
        output = self.output / "torso_reach"
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            torso_reach.main(
                ["--learner", str(learner_dir), "--seeds", "2", "--problems", "3",
                 "--output", str(output), "--workers", "2"]
            )  # fmt: skip
        runs = [
            torso_reach.TorsoReachRun(**json.loads(path.read_text()))
            for path in output.glob("runs/*/result.json")
        ]
        self.assertEqual(len(runs), 8)
        self.assertTrue(all(len(r.distances) == 3 and r.robot_seconds > 0 for r in runs))
        self.assertEqual(sum(r.penetrating_steps for r in runs), 0)
        report = (output / "report.md").read_text()
        self.assertIn("| outside | on | 2 |", report)
        self.assertIn("outside targets, share reached", report)  # (tested, or equal in every pair)
        # The outside targets are the inside ones moved 10 cm from the shoulder.
        learner, grid = LoadTrainedLearner(learner_dir)
        robot = torso_reach.TorsoReachRobot(learner, grid.radius, torso=False)
        inside = grid.Centres()[:3]
        moved = torso_reach.Beyond(robot, inside, 0.1) - inside
        np.testing.assert_allclose(np.linalg.norm(moved, axis=1), 0.1)
        # A target that appears where the palm is is counted as appearing inside the robot, and
        # its problem's penetrating periods are not counted among the others'.
        # (The pushing out is the first problem's; a watch resumed from its counts goes on
        # counting: the far target's problem is the resumed watch's.)
        watched = AppearanceWatch(robot)
        watched.SetProblem(robot.MarkerPosition())
        robot.Transition(robot.State())  # MoBeE pushes the arm out of the target
        pushed_out = robot.Safety().penetrating_steps
        self.assertGreater(pushed_out, 0)
        watched = AppearanceWatch(robot, dc.replace(watched.counts))
        watched.SetProblem(np.array([1.0, 1.0, 1.0]))
        watched.SetProblem(robot.MarkerPosition() + [0.0, 0.0, 0.5])
        watched.Close()
        self.assertEqual(watched.counts.appeared_inside, 1)
        self.assertEqual(watched.counts.other_penetrating_steps, 0)
        # With --settle the torso comes to rest where the module puts it before the arm acts.
        # The evidence map is made to peak (a record above any reach's reward) where one of the
        # grid's postures would show the target: the torso settles in that posture.
        module = torso_reach.TorsoModule("evidence", levels=3, range_fraction=0.8, settle=True)
        self.assertEqual(module.Label(), "evidence-levels3-range0.8-settled")
        self.assertEqual(torso_reach.TorsoModule().Label(), "")
        mobee, target = robot.station.mobee, moved[0] + inside[0]
        posture = PostureGrid(mobee, TORSO_JOINTS, 3, 0.8)[12]  # (yaw -40 deg)
        torso = np.array([mobee.joint_index(j) for j in TORSO_JOINTS])
        q = mobee.home.copy()
        q[torso] = posture
        robot.MoveTo(q)
        learner.histories.Record(learner.num_transitions, robot.LearningFrame(target), 0.0, 5.0)
        robot = torso_reach.TorsoReachRobot(learner, grid.radius, torso=True, module=module)
        began = robot.context.get_time()
        torso_reach.SettledTorso(robot).SetProblem(target)
        x = robot.station.robot_state.Eval(robot.context)
        np.testing.assert_allclose(x[torso], posture, atol=np.radians(2.0))
        self.assertLess(np.abs(x[len(mobee.joints) + torso]).max(), np.radians(2.0))
        self.assertGreater(robot.context.get_time(), began + 1.0)
        executor = robot.executor
        self.assertEqual(executor.CompletedActions(executor.GetMyContextFromRoot(robot.context)), 0)

    def test_a_noisy_robot_sometimes_settles_in_another_state(self):
        """Issue 33: with actuation noise (sd 0.2 of each joint's range: a joint leaves its state
        with probability 2 Phi(-0.625) = 53 %) transitions end elsewhere; without, never."""
        from mobee_drake.experiments.ch8_reaching import ReachRobot

        space = self.model.space
        arrived = {}
        for noise in (0.0, 0.2):
            robot = ReachRobot(space, 0.05, transition_noise=noise, noise_seed=3)
            robot.SetProblem(np.array([1.0, 1.0, 1.0]))  # far away
            arrived[noise] = []
            for _ in range(6):
                goal = int(space.action_goal[space.Actions(robot.State())[0]])
                arrived[noise].append(robot.Transition(goal) == goal)
        self.assertTrue(all(arrived[0.0]))
        self.assertFalse(all(arrived[0.2]))

    def test_the_evaluations_robot_time(self):
        """A run that only evaluates (no problem-try) spends all its robot time in the
        evaluations; one that explores too spends the rest exploring."""
        only = self.Run("evaluations_only", self.Settings("greedy", 0, 0, [0], 1, 4))
        self.assertGreater(only["evaluation_seconds"], 1.0)
        self.assertEqual(only["evaluation_seconds"], only["simulated_seconds"])
        both = self.Run("evaluations_and_tries", self.Settings("greedy", 0, 4, [4], 1, 4))
        self.assertGreater(both["evaluation_seconds"], 1.0)
        self.assertGreater(both["simulated_seconds"], both["evaluation_seconds"] + 1.0)

    def test_weaker_reach_stops_farther(self):
        from mobee_drake.experiments.ch8_reaching import ReachRobot

        target = np.array([-0.23, 0.22, 0.19])
        misses = {}
        for force in (300.0, 30.0):
            robot = ReachRobot(self.model.space, 0.05, force)
            robot.SetProblem(target)
            misses[force] = np.linalg.norm(robot.Reach(target) - target)
        # MoBeE's attractor spring holds a weaker push back farther from the target.
        self.assertGreater(misses[30.0], misses[300.0] + 0.02)
        with self.assertRaisesRegex(ValueError, "force and softening must be > 0"):
            ReachRobot(self.model.space, 0.05, -1.0)

    def test_mdp_learned_with_the_reaches(self):
        from mobee_drake.experiments.ch8_reaching import LEVELS, RIGHT_ARM
        from mobee_drake.planning.explorers import Explorer
        from mobee_drake.planning.state_space import Lattice

        np.testing.assert_array_equal(
            Lattice(LEVELS, len(RIGHT_ARM)).action_goal, self.model.space.action_goal
        )
        result = self.Run(
            "simultaneous", self.Settings("random", 0, 8, [8], 1, 4, mdp="simultaneous")
        )
        log = np.array(result["log"])
        counts = np.load(self.output / "simultaneous" / "mdp.npz")["counts"]
        initial = Explorer(self.model.space).transitions.counts
        # The model learned from transitions only, each recording 0 (model updates) or -10 (the
        # fields felt the target in the way); at most one outcome count per logged transition.
        transitions = log[log[:, 2] < 432]
        self.assertTrue(np.all(np.isin(transitions[:, 6], [0.0, -10.0])))
        updated = np.flatnonzero(np.any(counts != initial, axis=1))
        self.assertTrue(set(updated) <= set(transitions[transitions[:, 6] == 0, 2].astype(int)))
        self.assertGreater(len(updated), 0)
        # An observation adds 1, or 2 when it opens a new outcome's bin (Alg. 6).
        self.assertLessEqual(counts.sum() - initial.sum(), 2 * len(transitions))

    def test_mdp_tried_everything(self):
        self.assertEqual(self.model.space.num_state_actions, 432)
        self.assertGreaterEqual(self.model.tries.min(), 1)

    def test_reduced_battery(self):
        from mobee_drake.reaching.strategies import REACH_STRATEGIES as STRATEGIES
        from mobee_drake.reaching.targets import LoadTargetGrid

        results = [self.Run(s, self.Settings(s, 0, 12, [0, 12], 1, 5)) for s in STRATEGIES]
        for result in results:
            log = np.array(result["log"])
            # Every problem-try ended with a reach or after at most 10 actions.
            self.assertEqual(sorted(result["evaluations"]), ["0", "12"])
            self.assertEqual(int(log[:, 0].max()), 11)
            reaches = log[log[:, 2] >= 432]
            self.assertTrue(np.all((reaches[:, 6] > 0) & (reaches[:, 6] <= 1)))
            transitions = log[log[:, 2] < 432]
            self.assertTrue(np.all(np.isin(transitions[:, 6], [0.0, -10.0])))
            # A reach's state is where the robot was, and it stays there.
            np.testing.assert_array_equal(reaches[:, 2] - 432, reaches[:, 3])
            if result["settings"]["strategy"] == "goal_babbling":
                # Goals of its own, in the targets' box grown by their radius.
                grid = LoadTargetGrid().Centres()
                self.assertTrue(
                    np.all(
                        (log[:, 7:] >= grid.min(axis=0) - 0.05)
                        & (log[:, 7:] <= grid.max(axis=0) + 0.05)
                    )
                )
                self.assertFalse(np.any(np.all(np.isin(log[:, 7:], grid), axis=1)))
            else:  # Least-tried problems first: 12 tries on 12 different problems.
                self.assertEqual(len(np.unique(log[log[:, 2] >= 432][:, 1])), len(reaches))
            for evaluation in result["evaluations"].values():
                self.assertEqual(sorted(t["problem"] for t in evaluation[0]), list(range(27)))
        # Fresh learners evaluate alike (same start, same greedy ties from the same seed).
        self.assertEqual(len({json.dumps(r["evaluations"]["0"]) for r in results}), 1)
        from mobee_drake.experiments.ch8_reaching import ReachRun
        from mobee_drake.experiments.ch8_report import Report

        report = Report(self.output, [ReachRun.FromJson(r) for r in results])
        self.assertIn("| intrinsic |", report)
        self.assertIn(
            "| the source's claim | value compared | unit1_force300 | holds under |", report
        )
        self.assertIn("| goal_babbling |", report)
        for figure in (
            "8.2_cumulative_reward.png",
            "8.7_problem_tries.png",
            "8.8_failed_transitions.png",
            "8.4-8.6_reaches_greedy.png",
        ):
            self.assertTrue((self.output / figure).is_file(), figure)

    def test_resume_after_a_kill_is_exact(self):
        from mobee_drake.reaching.learner import ReachLearner

        settings = self.Settings("intrinsic", 1, 10, [0, 6, 10], 1, 3)
        whole = self.Run("whole", settings)
        explore, calls = ReachLearner.Explore, []

        def Dying(learner, robot):
            calls.append(1)
            if len(calls) == 8:
                raise KeyboardInterrupt
            return explore(learner, robot)

        from mobee_drake.experiments.ch8_reaching import RunOne

        checkpoints = []
        with mock.patch.object(ReachLearner, "Explore", Dying):
            with self.assertRaises(KeyboardInterrupt):
                RunOne(self.output / "killed", self.mdp, settings, progress=checkpoints.append)
        self.assertEqual(checkpoints[-1], 6)
        resumed = self.Run("killed", settings)
        self.assertEqual(resumed["log"], whole["log"])
        self.assertEqual(resumed["evaluations"], whole["evaluations"])
        self.assertAlmostEqual(resumed["simulated_seconds"], whole["simulated_seconds"])
