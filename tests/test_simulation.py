"""Scenarios, the kinematic and dynamic robots, the live world, the viewer and the runner."""

import dataclasses as dc
import pathlib
import tempfile
import unittest
import zipfile

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.analysis import InitializeParams
from pydrake.systems.framework import LeafSystem

from mobee_drake import cli
from mobee_drake.atomic_files import CurrentGeneration
from mobee_drake.mobee.fields import FieldPairs
from mobee_drake.mobee.params import Dissertation, MobeeParams
from mobee_drake.mobee.system import FORCE_TERMS
from mobee_drake.planning.state_space import Lattice
from mobee_drake.scenario import BuildScenario, LoadScenario, ResumableConfiguration, RunScenario
from mobee_drake.station.attractors import (
    FixedAttractor,
    MarkerGoal,
    MarkerGoalSprings,
    RandomAttractorSource,
)
from mobee_drake.station.builder import MakeMobeeStation
from mobee_drake.station.checkpoint import LoadCheckpoint, ReadCheckpointFiles, SaveCheckpoint
from mobee_drake.station.config import Dynamic
from mobee_drake.station.runner import Advance
from mobee_drake.station.safety import SafetyMonitor
from mobee_drake.station.virtual_dynamics import VirtualDynamics
from mobee_drake.station.world_events import MakeSimulator
from mobee_drake.world.objects import SceneObject, Sphere, WorldEvent
from mobee_drake.yaml_io import YamlFileError

DIAGRAMS = pathlib.Path(__file__).resolve().parents[1] / "diagrams"
REACH = DIAGRAMS / "reach_around_ball.yaml"


def _Palm(simulation, context):
    mobee = simulation.mobee
    i = mobee.marker_index("r_palm")
    return (
        mobee.GetOutputPort("marker_positions")
        .Eval(mobee.GetMyContextFromRoot(context))[3 * i : 3 * i + 3]
        .copy()
    )


def _RunAgents(scenario):
    """Runs an exploring scenario for its duration; returns it and its agents' records."""
    simulation = BuildScenario(scenario)
    simulator = MakeSimulator(simulation)
    simulator.Initialize()
    simulator.AdvanceTo(scenario.duration)
    supervisor = simulation.client
    records = supervisor.Records(supervisor.GetMyContextFromRoot(simulator.get_context()))
    return simulation, simulator, supervisor, records


def _Trajectory(scenario, times):
    simulation = BuildScenario(scenario)
    simulator = MakeSimulator(simulation)
    simulator.Initialize()
    palms, states = [], []
    for t in times:
        simulator.AdvanceTo(t)
        context = simulator.get_context()
        palms.append(_Palm(simulation, context))
        states.append(simulation.robot_state.Eval(context).copy())
    return simulation, simulator, np.array(palms), np.array(states)


class TestScenarioFiles(unittest.TestCase):
    def test_shipped_scenarios_load(self):
        for path in sorted(DIAGRAMS.glob("*.yaml")):
            scenario = LoadScenario(path)
            self.assertGreater(scenario.duration, 0, path)

    def _Write(self, text):
        path = pathlib.Path(tempfile.mkdtemp()) / "scenario.yaml"
        path.write_text(text)
        return path

    def test_unknown_key_names_file_and_line(self):
        path = self._Write("mover: !Kinematic {}\nduraton: 3\n")
        with self.assertRaisesRegex(YamlFileError, f"{path}:2: .*'duraton'"):
            LoadScenario(path)

    def test_wrong_type_and_bad_choice(self):
        path = self._Write("duration: long\n")
        with self.assertRaisesRegex(YamlFileError, f"{path}:1: .*'long'"):
            LoadScenario(path)
        path = self._Write("mover: !Dynamic {control: quantum}\n")
        with self.assertRaisesRegex(YamlFileError, "control must be one of .* 'quantum'"):
            LoadScenario(path)
        path = self._Write("mover: !Quantum {}\n")
        with self.assertRaisesRegex(YamlFileError, f"{path}:1: .*Quantum"):
            LoadScenario(path)

    def test_missing_file(self):
        with self.assertRaisesRegex(YamlFileError, "nowhere.yaml: no such file"):
            LoadScenario("nowhere.yaml")

    def test_unknown_model_joint_and_object(self):
        path = self._Write("robot: {model: iCubMars}\n")
        with self.assertRaisesRegex(ValueError, "unknown iCub model 'iCubMars'"):
            BuildScenario(LoadScenario(path))
        path = self._Write("attractor: !FixedAttractor {joints_deg: {r_knee: 10}}\n")
        with self.assertRaisesRegex(ValueError, "unknown joint 'r_knee'"):
            BuildScenario(LoadScenario(path))
        path = self._Write("objects: [{name: a}]\nworld_events: [{time: 1, object: b}]\n")
        with self.assertRaisesRegex(YamlFileError, "unknown object 'b'"):
            LoadScenario(path)

    def test_overrides(self):
        scenario = LoadScenario(REACH, "{mover: !Dynamic {control: force}}")
        self.assertIsInstance(scenario.mover, Dynamic)
        self.assertEqual(scenario.mover.control, "force")
        with self.assertRaisesRegex(YamlFileError, "overrides"):
            LoadScenario(REACH, "{mver: !Dynamic {}}")

    def test_an_override_switches_the_mobee_preset_both_ways(self):
        """``Dissertation`` subclasses ``MobeeParams``: Drake's loader alone would keep it."""
        scenario = LoadScenario("motor_babbling", "{mobee: !MobeeParams {}}")
        self.assertIs(type(scenario.mobee), MobeeParams)
        self.assertEqual(scenario.mobee.damping, MobeeParams().damping)
        scenario = LoadScenario(REACH, "{mobee: !Dissertation {damping: 30}}")
        self.assertIs(type(scenario.mobee), Dissertation)
        self.assertEqual(scenario.mobee.stiffness, Dissertation().stiffness)
        self.assertEqual(scenario.mobee.damping, 30)
        # The same tag merges, as Drake's loader does.
        scenario = LoadScenario("motor_babbling", "{mobee: !Dissertation {damping: 30}}")
        self.assertEqual((type(scenario.mobee), scenario.mobee.damping), (Dissertation, 30))


def Forces(total, damping) -> np.ndarray:
    """MoBeE's ``forces`` vector with only its ``damping`` term and its ``total`` set."""
    n = len(total)
    forces = np.zeros((len(FORCE_TERMS) + 1, n))
    forces[FORCE_TERMS.index("damping")], forces[-1] = damping, total
    return forces.ravel()


class TestVirtualDynamics(unittest.TestCase):
    def test_one_step_is_semi_implicit_euler_with_implicit_damping(self):
        mass, damping, h = np.array([2.0, 1.0]), np.array([10.0, 0.0]), 0.02
        q0 = np.array([0.1, -0.2])
        dut = VirtualDynamics(
            mass=mass, damping=damping, period=h, initial_positions=q0, measured_damping=True
        )
        context = dut.CreateDefaultContext()
        np.testing.assert_array_equal(
            context.get_discrete_state_vector().value(), [0.1, -0.2, 0, 0]
        )
        v0 = np.array([0.5, 1.0])
        context.SetDiscreteState(np.concatenate([q0, v0]))
        total, damping_term = np.array([3.0, -4.0]), np.array([-1.0, 0.0])
        dut.GetInputPort("forces").FixValue(context, Forces(total, damping_term))
        state = dut.EvalUniquePeriodicDiscreteUpdate(context).get_vector().value()
        v1 = (v0 + h * (total - damping_term) / mass) / (1 + h * damping / mass)
        np.testing.assert_allclose(state, np.concatenate([q0 + h * v1, v1]))
        # Without the damping input it is the damping of this state, -C v0.
        kinematic = VirtualDynamics(mass=mass, damping=damping, period=h, initial_positions=q0)
        own = kinematic.CreateDefaultContext()
        own.SetDiscreteState(np.concatenate([q0, v0]))
        kinematic.GetInputPort("forces").FixValue(own, Forces(total, damping_term))
        state = kinematic.EvalUniquePeriodicDiscreteUpdate(own).get_vector().value()
        v1 = (v0 + h * (total + damping * v0) / mass) / (1 + h * damping / mass)
        np.testing.assert_allclose(state, np.concatenate([q0 + h * v1, v1]))

    def test_spring_and_damper_settle_at_the_attractor(self):
        # M q'' = -K (q - 1) - C q' with K = 50, C = 50: overdamped, its slow pole at -1.02/s,
        # so after 30 s it is at q = 1 to within e^-30.
        h, K, C = 0.02, 50.0, 50.0
        dut = VirtualDynamics(
            mass=np.ones(1), damping=np.array([C]), period=h, initial_positions=np.zeros(1)
        )
        context = dut.CreateDefaultContext()
        for _ in range(1500):
            q, v = context.get_discrete_state_vector().value()
            dut.GetInputPort("forces").FixValue(context, Forces([-K * (q - 1.0) - C * v], [-C * v]))
            context.SetDiscreteState(dut.EvalUniquePeriodicDiscreteUpdate(context).value())
        np.testing.assert_allclose(
            context.get_discrete_state_vector().value(), [1.0, 0.0], atol=1e-6
        )


class TestMarkerGoals(unittest.TestCase):
    def test_springs_pull_their_markers_only(self):
        dut = MarkerGoalSprings(
            num_markers=3, goals={1: MarkerGoal(marker="b", position=[1.0, 2.0, 3.0], gain=10.0)}
        )
        context = dut.CreateDefaultContext()
        p = np.arange(9.0)
        dut.get_input_port().FixValue(context, p)
        forces = dut.get_output_port().Eval(context).reshape(3, 3)
        np.testing.assert_array_equal(forces[[0, 2]], 0.0)
        np.testing.assert_allclose(forces[1], 10.0 * (np.array([1.0, 2.0, 3.0]) - p[3:6]))

    def test_the_palm_reaches_a_workspace_goal(self):
        # The palm pulled to where a posture puts it, from home, the attractor left at home:
        # MoBeE's workspace forcing (eq. 5.10) alone moves it there, against the home spring.
        goal = np.array([-0.30, 0.16, 0.06])
        scenario = dc.replace(
            LoadScenario("reach_around_ball", "{duration: 6.0, data_log: {enabled: false}}"),
            objects=[],
            attractor=FixedAttractor(
                marker_goals=[MarkerGoal(marker="r_palm", position=list(goal), gain=400.0)]
            ),
        )
        station = BuildScenario(scenario)
        simulator = MakeSimulator(station)
        simulator.AdvanceTo(scenario.duration)
        mobee = station.mobee
        palm = mobee.GetOutputPort("marker_positions").Eval(
            mobee.GetMyContextFromRoot(simulator.get_context())
        )[3 * mobee.marker_index("r_palm") :][:3]
        start = np.array([-0.31, 0.14, 0.01])  # home (the scenario's comment)
        self.assertLess(np.linalg.norm(palm - goal), 0.5 * np.linalg.norm(start - goal))
        # It settles where the workspace spring balances the home spring (eq. 5.7 at rest).
        context = mobee.GetMyContextFromRoot(simulator.get_context())
        spring, f_work = (mobee.GetOutputPort(t).Eval(context) for t in ("spring", "f_work"))
        self.assertGreater(np.linalg.norm(f_work), 1.0)
        np.testing.assert_allclose(spring, -f_work, atol=1e-3 * np.linalg.norm(f_work))
        with self.assertRaisesRegex(ValueError, "gain"):
            LoadScenario(
                "reach_around_ball",
                "{attractor: !FixedAttractor {marker_goals: [{gain: -1}]}}",
            )


class TestRandomAttractors(unittest.TestCase):
    def test_reproducible_in_range_and_home_elsewhere(self):
        lower, upper, home = np.array([-1.0, 0.0, 2.0]), np.array([1.0, 2.0, 4.0]), np.zeros(3)
        kwargs = dict(
            lower=lower,
            upper=upper,
            home=home,
            babbling=[True, True, False],
            range_fraction=0.5,
            period=2.0,
            seed=7,
        )
        draws = []
        for _ in range(2):
            dut = RandomAttractorSource(**kwargs)
            context = dut.CreateDefaultContext()
            sequence = [dut.get_output_port().Eval(context).copy()]
            for k in range(1, 50):
                context.SetTime(2.0 * k)
                context.SetDiscreteState(dut.EvalUniquePeriodicDiscreteUpdate(context).value())
                sequence.append(dut.get_output_port().Eval(context).copy())
            draws.append(np.array(sequence))
        np.testing.assert_array_equal(draws[0], draws[1])
        self.assertTrue(np.all(draws[0][:, 0] >= -0.5) and np.all(draws[0][:, 0] <= 0.5))
        self.assertTrue(np.all(draws[0][:, 1] >= 0.5) and np.all(draws[0][:, 1] <= 1.5))
        np.testing.assert_array_equal(draws[0][:, 2], 0.0)
        self.assertGreater(len(np.unique(draws[0][:, 0])), 45)


class TestSafetyMonitor(unittest.TestCase):
    def test_keeps_closest_approach_and_penetrations(self):
        from pydrake.geometry import GeometryInstance, SceneGraph
        from pydrake.geometry import Sphere as DrakeSphere
        from pydrake.math import RigidTransform

        scene_graph = SceneGraph()
        source = scene_graph.RegisterSource("test")
        ball, table, thing, arm, chest = (
            scene_graph.RegisterAnchoredGeometry(
                source, GeometryInstance(RigidTransform(), DrakeSphere(0.1), name)
            )
            for name in ("ball", "table", "thing", "arm", "chest")
        )
        query = scene_graph.get_query_output_port().Eval(scene_graph.CreateDefaultContext())
        dut = SafetyMonitor(names=["ball", "table"], period=0.01, num_joints=2)
        context = dut.CreateDefaultContext()
        dut.GetInputPort("geometry_query").FixValue(context, query)

        def Step(ids, distances, barrier=(0.0, 0.0)):
            dut.GetInputPort("f_barrier").FixValue(context, np.array(barrier))
            k = len(ids)
            pairs = FieldPairs(
                [arm] * k,
                list(ids),
                distance=np.array(distances),
                margin=np.full(k, 0.03),
                p_WCa=np.zeros((k, 3)),
                nhat_BA_W=np.zeros((k, 3)),
                row_A=np.zeros(k, dtype=int),
                row_B=np.array([1 if i == chest else -1 for i in ids]),
                X_WA=np.zeros((k, 3, 4)),
                X_WB=np.zeros((k, 3, 4)),
            )
            dut.GetInputPort("field_pairs").FixValue(context, pairs)
            context.SetDiscreteState(dut.EvalUniquePeriodicDiscreteUpdate(context).value())

        Step([ball], [0.02])
        Step([ball, chest, thing], [0.01, -0.002, 0.025], barrier=(0.0, 3.0))
        Step([ball], [0.015])
        Step([], [], barrier=(-1.0, 0.0))  # (the barrier may act on pairs beyond the fields)
        report = dut.Report(context)
        self.assertEqual(
            report.closest_approach,
            {"ball": 0.01, "table": None, "(self)": -0.002, "(other objects)": 0.025},
        )
        self.assertEqual(report.penetrating_steps, 1)
        self.assertAlmostEqual(report.deepest_penetration, 0.002)
        self.assertEqual(report.barrier_periods, 2)


class TestKinematicRobot(unittest.TestCase):
    def test_reach_bends_around_the_ball(self):
        scenario = LoadScenario(REACH)
        times = np.arange(0.5, scenario.duration + 1e-9, 0.5)
        simulation, simulator, palms, _ = _Trajectory(scenario, times)
        ball = next(o for o in scenario.objects if o.name == "ball")
        center, radius = np.array(ball.position), ball.shape.radius
        report = simulation.monitor.Report(
            simulation.monitor.GetMyContextFromRoot(simulator.get_context())
        )
        self.assertEqual(report.penetrating_steps, 0)
        self.assertGreater(report.closest_approach["ball"], 0.0)
        # The palm went past the ball (from y = 0.14 to the other side of its centre) ...
        self.assertLess(palms[-1, 1], center[1])
        # ... over it, never closer to its centre than its radius.
        self.assertGreater(palms[:, 2].max(), center[2] + radius)
        self.assertGreater(np.linalg.norm(palms - center, axis=1).min(), radius)

        # Without the ball, the same attractor would have driven the hand into it: replay the
        # free motion in the world with the ball and look at the hand's distance to it.
        scenario.objects = [o for o in scenario.objects if o.name != "ball"]
        _, _, _, free = _Trajectory(scenario, np.arange(0.1, scenario.duration, 0.1))
        virtual = simulation.mover
        context = simulator.get_mutable_context()
        mobee_context = simulation.mobee.GetMyContextFromRoot(context)
        distances = []
        for x in free:
            virtual.GetMyMutableContextFromRoot(context).SetDiscreteState(x)
            contacts = simulation.mobee.GetOutputPort("field_contacts").Eval(mobee_context)
            distances += [c.distance for c in contacts if c.name_B == "ball"]
        self.assertLess(min(distances), -0.01)

    def test_settles_at_the_attractor_in_free_space(self):
        scenario = LoadScenario(REACH, "{objects: [], duration: 12}")
        simulation, simulator, _, states = _Trajectory(scenario, [12.0])
        q_star = simulation.attractor.Eval(simulator.get_context())
        n = len(q_star)
        np.testing.assert_allclose(states[-1][:n], q_star, atol=2e-3)
        np.testing.assert_allclose(states[-1][n:], 0.0, atol=1e-2)


class TestClientForces(unittest.TestCase):
    def test_marker_force_lifts_the_palm_and_is_drawn(self):
        from pydrake.geometry import Meshcat

        scenario = LoadScenario(REACH, "{objects: [], duration: 2}")
        meshcat = Meshcat()
        simulation = BuildScenario(scenario, meshcat)
        simulator = MakeSimulator(simulation)
        context = simulator.get_mutable_context()
        forces = np.zeros(3 * len(simulation.mobee.marker_names))
        i = simulation.mobee.marker_index("r_palm")
        forces[3 * i + 2] = 50.0  # upwards, in world
        simulation.diagram.GetInputPort("marker_forces").FixValue(context, forces)
        simulator.Initialize()
        start = _Palm(simulation, context)
        simulation.diagram.ForcedPublish(context)
        self.assertTrue(meshcat.HasPath("/marker_forces"))
        simulator.AdvanceTo(2.0)
        lifted = _Palm(simulation, context)
        # Without the force, the attractor alone moves the palm down a little.
        _, _, free, _ = _Trajectory(scenario, [2.0])
        self.assertGreater(lifted[2] - free[0][2], 0.05)
        self.assertGreater(lifted[2], start[2])


class TestDynamicRobot(unittest.TestCase):
    """Each modality follows MoBeE: after 3 s of the reach, within a few degrees of the
    kinematic robot, and without penetrating the ball."""

    @classmethod
    def setUpClass(cls):
        cls.times = [1.0, 3.0]
        _, _, cls.kinematic_palms, cls.kinematic = _Trajectory(LoadScenario(REACH), cls.times)

    def _Check(self, control, tolerance_deg):
        scenario = LoadScenario(REACH, f"{{mover: !Dynamic {{control: {control}}}}}")
        simulation, simulator, palms, states = _Trajectory(scenario, self.times)
        n = states.shape[1] // 2
        error = np.degrees(np.abs(states[:, :n] - self.kinematic[:, :n])).max()
        self.assertLess(error, tolerance_deg, control)
        report = simulation.monitor.Report(
            simulation.monitor.GetMyContextFromRoot(simulator.get_context())
        )
        self.assertEqual(report.penetrating_steps, 0, control)
        # A few degrees over the torso and the arm (the palm 0.4-0.6 m away): 2 cm at the palm.
        np.testing.assert_allclose(palms, self.kinematic_palms, atol=0.02)

    def test_position(self):
        self._Check("position", 2.0)

    def test_velocity(self):
        self._Check("velocity", 3.0)

    def test_force(self):
        self._Check("force", 2.0)


class TestLiveWorld(unittest.TestCase):
    def test_roles_moves_additions_and_removals(self):
        scenario = LoadScenario(REACH, "{duration: 2}")
        simulation = BuildScenario(scenario)
        simulator = MakeSimulator(simulation)
        simulator.Initialize()
        context = simulator.get_mutable_context()
        mobee_context = simulation.mobee.GetMyContextFromRoot(context)
        world = simulation.world

        def Touching():
            contacts = simulation.mobee.GetOutputPort("field_contacts").Eval(mobee_context)
            return {c.name_B for c in contacts}

        simulator.AdvanceTo(1.0)
        self.assertIn("ball", Touching())
        world.SetRole(context, "ball", "ghost")
        self.assertEqual(world.Role(context, "ball"), "ghost")
        self.assertNotIn("ball", Touching())
        world.SetRole(context, "ball", "target")
        self.assertNotIn("ball", Touching())
        world.SetRole(context, "ball", "obstacle")
        self.assertIn("ball", Touching())
        palm = _Palm(simulation, context)
        world.Move(context, "ball", [-0.6, 0.0, 0.3])
        self.assertNotIn("ball", Touching())
        world.Move(context, "ball", palm)  # Right on the palm: deep inside the hand's field.
        self.assertIn("ball", Touching())
        self.assertEqual(world.Role(context, "ball"), "obstacle")
        world.Move(context, "ball", [-0.6, 0.0, 0.3])
        palm = _Palm(simulation, context)
        world.Add(
            context,
            SceneObject(
                name="cube",
                shape=Sphere(radius=0.02),
                position=list(palm + [-0.05, 0, 0]),
                role="obstacle",
            ),
        )
        self.assertIn("cube", Touching())
        simulator.AdvanceTo(1.5)  # The simulation goes on with the new object ...
        self.assertGreater(np.linalg.norm(_Palm(simulation, context) - palm), 0.0)
        world.Remove(context, "cube")
        self.assertNotIn("cube", Touching())
        simulator.AdvanceTo(2.0)
        report = simulation.monitor.Report(simulation.monitor.GetMyContextFromRoot(context))
        self.assertIsNotNone(report.closest_approach["(other objects)"])  # the cube
        with self.assertRaisesRegex(ValueError, "unknown world object 'cube'"):
            world.Remove(context, "cube")
        with self.assertRaisesRegex(ValueError, "unknown role 'wall'"):
            world.SetRole(context, "ball", "wall")

    def test_scenario_events(self):
        scenario = LoadScenario(
            REACH, "{duration: 3, world_events: [{time: 0.04, object: ball, role: ghost}]}"
        )
        simulation = BuildScenario(scenario)
        simulator = MakeSimulator(simulation)
        simulator.Initialize()
        context = simulator.get_context()
        Advance(simulation, simulator, 0.02)
        self.assertEqual(simulation.world.Role(context, "ball"), "obstacle")
        Advance(simulation, simulator, 3.0)
        self.assertEqual(simulation.world.Role(context, "ball"), "ghost")
        # The hand was still outside the ball's field at 0.04 s (it enters it at 0.07 s); from
        # then on MoBeE ignores the ball, so the motion is exactly the one without it.
        report = simulation.monitor.Report(
            simulation.monitor.GetMyContextFromRoot(simulator.get_context())
        )
        self.assertIsNone(report.closest_approach["ball"])
        scenario.objects = [o for o in scenario.objects if o.name != "ball"]
        scenario.world_events = []
        _, _, free, _ = _Trajectory(scenario, [3.0])
        np.testing.assert_allclose(_Palm(simulation, simulator.get_context()), free[0], atol=1e-12)


class TestExploration(unittest.TestCase):
    def test_curious_agent_on_the_kinematic_robot(self):
        scenario = LoadScenario(DIAGRAMS / "explore_hypercube.yaml", "{duration: 40}")
        simulation, simulator, _, (record,) = _RunAgents(scenario)
        context = simulator.get_context()
        explorer = record.explorer
        self.assertGreaterEqual(record.actions_done, 4)
        self.assertEqual(explorer.tries.sum(), record.actions_done)
        # Without obstacles and inside the hypercube every action reaches its goal: each tried
        # state-action's count of its goal grew by its tries (the initialisation put 1 there).
        tried = np.flatnonzero(explorer.tries)
        goals = explorer.space.action_goal[tried]
        np.testing.assert_array_equal(
            explorer.transitions.counts[tried, goals], 2 + explorer.tries[tried]
        )
        # The attractor is the goal centre of the action in flight, inside the joint limits.
        q_star = simulation.attractor.Eval(context)
        lower, upper = simulation.mobee.position_limits
        self.assertTrue(np.all((q_star >= lower) & (q_star <= upper)))


class TestPlanningOnTheRobot(unittest.TestCase):
    def test_planner_reuses_a_learned_model_to_reach_a_goal(self):
        folder = pathlib.Path(tempfile.mkdtemp()) / "learned"
        RunScenario(
            LoadScenario(DIAGRAMS / "explore_hypercube.yaml", "{duration: 30}"),
            checkpoint=str(folder),
        )
        # The goal: the corner of the hypercube opposite the start (4 steps away).
        scenario = LoadScenario(DIAGRAMS / "explore_hypercube.yaml", "{duration: 60}")
        simulation = BuildScenario(scenario)
        space = Lattice([0.25, 0.75], 4)
        lower, upper = simulation.mobee.position_limits
        columns = [simulation.mobee.joint_index(j) for j in scenario.attractor.agents[0].joints]
        home = (simulation.mobee.home[columns] - lower[columns]) / (upper - lower)[columns]
        first = space.StateOf(home)
        goal = space.StateOf(1.0 - space.centres[first])
        agent = scenario.attractor.agents[0]
        agent.model = str(folder)
        agent.explorer.strategy, agent.explorer.goal_state = "planner", goal
        _, _, _, (record,) = _RunAgents(scenario)
        self.assertTrue(record.arrived)
        self.assertEqual(record.state, goal)
        self.assertEqual(record.actions_done, 4)  # the shortest way through the hypercube
        with self.assertRaisesRegex(ValueError, "no saved model of agent 'right_arm'"):
            agent.model = str(folder.parent / "nothing")
            BuildScenario(scenario)


class TestSeveralAgents(unittest.TestCase):
    def test_three_agents_explore_in_parallel(self):
        scenario = LoadScenario(DIAGRAMS / "three_agents_table.yaml", "{duration: 20}")
        simulation, simulator, supervisor, records = _RunAgents(scenario)
        context = simulator.get_context()
        self.assertEqual(supervisor.agent_names, ["right_arm", "left_arm", "torso"])
        self.assertEqual([r.explorer.space.num_state_actions for r in records], [1296, 1296, 216])
        self.assertTrue(all(r.actions_done >= 2 for r in records))
        # Each agent sets the attractor of its own joints only: the neck stays at home.
        q_star = simulation.attractor.Eval(context)
        neck = [simulation.mobee.joint_index(j) for j in ("neck_pitch", "neck_roll", "neck_yaw")]
        np.testing.assert_array_equal(q_star[neck], simulation.mobee.home[neck])


class TestCheckpoints(unittest.TestCase):
    def test_resumed_run_equals_uninterrupted_run(self):
        folder = pathlib.Path(tempfile.mkdtemp())
        scenario = LoadScenario(DIAGRAMS / "explore_hypercube.yaml", "{duration: 30}")

        def Final(simulation, simulator):
            context = simulator.get_context()
            supervisor = simulation.client
            (record,) = supervisor.Records(supervisor.GetMyContextFromRoot(context))
            return (
                simulation.robot_state.Eval(context).copy(),
                record.explorer.tries.copy(),
                record.explorer.transitions.counts.copy(),
                record.state_action,
            )

        # Uninterrupted: 0 to 30 s.
        simulation = BuildScenario(scenario)
        simulator = MakeSimulator(simulation)
        simulator.Initialize()
        simulator.AdvanceTo(30.0)
        expected = Final(simulation, simulator)

        # Interrupted at 12.34 s (in the middle of an action), saved, resumed in a new diagram.
        first = BuildScenario(scenario)
        simulator = MakeSimulator(first)
        simulator.Initialize()
        simulator.AdvanceTo(12.34)
        SaveCheckpoint(first, simulator.get_context(), folder / "run")
        second = BuildScenario(scenario)
        simulator = MakeSimulator(second)
        LoadCheckpoint(second, simulator.get_mutable_context(), folder / "run")
        simulator.Initialize(InitializeParams(suppress_initialization_events=True))
        simulator.AdvanceTo(30.0)
        for a, b in zip(expected, Final(second, simulator)):
            np.testing.assert_array_equal(a, b)
        # The arrays stored compressed (a learned model's counts are mostly zeros).
        for name in ("right_arm.npz", "simulation.npz"):
            with zipfile.ZipFile(CurrentGeneration(folder / "run") / name) as saved:
                members = saved.infolist()
            self.assertTrue(members)
            self.assertTrue(all(m.compress_type == zipfile.ZIP_DEFLATED for m in members))

    def test_runner_saves_after_actions_and_resumes(self):
        folder = pathlib.Path(tempfile.mkdtemp()) / "run"
        scenario = LoadScenario(DIAGRAMS / "explore_hypercube.yaml", "{duration: 20}")
        first = RunScenario(scenario, checkpoint=str(folder))
        self.assertAlmostEqual(first.simulated_time, 20.0)
        scenario.duration = 30.0
        second = RunScenario(scenario, checkpoint=str(folder))  # resumes at 20 s
        self.assertAlmostEqual(second.simulated_time, 10.0)
        reach = LoadScenario(REACH, "{mover: !Dynamic {}}")
        other = BuildScenario(reach)
        with self.assertRaisesRegex(ValueError, "another configuration .*attractor"):
            LoadCheckpoint(
                other, other.diagram.CreateDefaultContext(), folder, ResumableConfiguration(reach)
            )
        with self.assertRaisesRegex(ValueError, "no saved state for 'plant'"):
            ReadCheckpointFiles(
                other, other.diagram.CreateDefaultContext(), CurrentGeneration(folder)
            )


class TestInteractive(unittest.TestCase):
    def test_sliders_move_the_attractor(self):
        from pydrake.geometry import Meshcat

        scenario = LoadScenario(DIAGRAMS / "interactive.yaml")
        with self.assertRaisesRegex(ValueError, "slider attractor needs Meshcat"):
            BuildScenario(scenario)
        meshcat = Meshcat()
        simulation = BuildScenario(scenario, meshcat)
        simulator = MakeSimulator(simulation)
        simulator.Initialize()
        context = simulator.get_context()
        np.testing.assert_allclose(simulation.attractor.Eval(context), simulation.mobee.home)
        meshcat.SetSliderValue("r_elbow", 70.0)  # degrees
        simulator.AdvanceTo(0.1)  # The sliders are sampled every 50 ms.
        q_star = simulation.attractor.Eval(context)
        self.assertAlmostEqual(q_star[simulation.mobee.joint_index("r_elbow")], np.radians(70))
        # MoBeE's field forces are drawn while the hand is near the ball: put it 1 cm off the palm.
        mobee, mobee_context = simulation.mobee, simulation.mobee.GetMyContextFromRoot(context)
        i = mobee.marker_index("r_palm")
        normal = mobee.GetOutputPort("marker_directions").Eval(mobee_context)[3 * i : 3 * i + 3]
        ball = _Palm(simulation, context) + 0.05 * normal
        simulation.world.Move(simulator.get_mutable_context(), "ball", ball)
        simulation.diagram.ForcedPublish(context)
        self.assertTrue(_Visible(meshcat, "/field_forces/0"))
        # Without the ball nothing is inside a field, and no force is drawn.
        simulation.world.Remove(simulator.get_mutable_context(), "ball")
        simulation.world.Remove(simulator.get_mutable_context(), "table")
        simulation.diagram.ForcedPublish(context)
        self.assertFalse(_Visible(meshcat, "/field_forces/0"))


def _Visible(meshcat, path: str) -> bool:
    """Whether Meshcat shows the object at ``path`` (its last "visible" property)."""
    import msgpack

    return msgpack.unpackb(meshcat._GetPackedProperty(path, "visible"))["value"]


class BallSwitcher(LeafSystem):
    """A toy supervisor: once the palm is within 10 cm of the ball, it asks for the ball to become
    a ghost (a world event in its abstract state, listed on ``world_events``)."""

    def __init__(self, mobee, ball_position):
        super().__init__()
        self._ball = np.asarray(ball_position)
        self._palm = 3 * mobee.marker_index("r_palm")
        self._positions = self.DeclareVectorInputPort(
            "marker_positions", 3 * len(mobee.marker_names)
        )
        self._issued = self.DeclareAbstractState(AbstractValue.Make([]))
        self.DeclarePeriodicUnrestrictedUpdateEvent(0.1, 0.0, self._Update)
        self.DeclareAbstractOutputPort(
            "world_events",
            lambda: AbstractValue.Make([]),
            lambda context, output: output.set_value(
                context.get_abstract_state(int(self._issued)).get_value()
            ),
            prerequisites_of_calc={self.abstract_state_ticket(self._issued)},
        )

    def _Update(self, context, state):
        issued = context.get_abstract_state(int(self._issued)).get_value()
        palm = self._positions.Eval(context)[self._palm : self._palm + 3]
        if not issued and np.linalg.norm(palm - self._ball) < 0.10:
            event = WorldEvent(time=context.get_time(), object="ball", role="ghost")
            state.get_mutable_abstract_state(int(self._issued)).set_value([event])


class TestSupervisorWorldEvents(unittest.TestCase):
    """World events live in the Context: applied by the simulator's monitor after every step,
    counted in the ledger's state, read from SceneGraph's Context."""

    @classmethod
    def setUpClass(cls):
        cls.scenario = LoadScenario(REACH, "{duration: 4}")
        ball = next(o for o in cls.scenario.objects if o.name == "ball").position

        def ClientAndSwitcher(parts):
            client = cls.scenario.attractor.AddToBuilder(parts)
            switcher = parts.builder.AddNamedSystem("switcher", BallSwitcher(parts.mobee, ball))
            parts.builder.Connect(
                parts.mobee.GetOutputPort("marker_positions"), switcher.get_input_port()
            )
            # The switcher's requests are declared with the client's offer.
            client.world_events.append(switcher.GetOutputPort("world_events"))
            return client

        cls.station = MakeMobeeStation(cls.scenario, prebuild_callback=ClientAndSwitcher)

    def _Run(self, chunked: bool):
        simulator = MakeSimulator(self.station)
        simulator.Initialize()
        if chunked:
            Advance(self.station, simulator, 4.0)
        else:
            simulator.AdvanceTo(4.0)
        return simulator.get_context()

    def test_a_supervisor_switches_the_ball_to_a_ghost(self):
        context = self._Run(chunked=True)
        self.assertEqual(self.station.world.Role(context, "ball"), "ghost")
        ledger = self.station.event_ledger
        np.testing.assert_array_equal(ledger.Counts(ledger.GetMyContextFromRoot(context)), [0, 1])

    def test_plain_advance_contexts_and_checkpoints_agree(self):
        chunked, plain = self._Run(chunked=True), self._Run(chunked=False)
        world = self.station.world
        self.assertEqual(world.Snapshot(plain), world.Snapshot(chunked))
        np.testing.assert_array_equal(
            self.station.robot_state.Eval(plain), self.station.robot_state.Eval(chunked)
        )
        # A fresh context of the same diagram has the world it was built with.
        fresh = self.station.diagram.CreateDefaultContext()
        self.assertEqual(world.Role(fresh, "ball"), "obstacle")
        # A checkpoint restores the world and the ledger into a fresh context.
        folder = pathlib.Path(tempfile.mkdtemp()) / "checkpoint"
        SaveCheckpoint(self.station, plain, folder)
        LoadCheckpoint(self.station, fresh, folder)
        self.assertEqual(world.Snapshot(fresh), world.Snapshot(plain))
        ledger = self.station.event_ledger
        np.testing.assert_array_equal(
            ledger.Counts(ledger.GetMyContextFromRoot(fresh)),
            ledger.Counts(ledger.GetMyContextFromRoot(plain)),
        )


class TestRunner(unittest.TestCase):
    def test_recording_and_summary(self):
        from pydrake.geometry import Meshcat

        path = pathlib.Path(tempfile.mkdtemp()) / "run.html"
        meshcat = Meshcat()
        summary = RunScenario(
            LoadScenario(REACH, "{duration: 1}"), meshcat=meshcat, record=str(path)
        )
        self.assertEqual(summary.recording, str(path.resolve()))
        text = path.read_text()
        self.assertTrue(text.startswith("<!DOCTYPE html>"))
        self.assertGreater(len(text), 1_000_000)  # the meshes and the animation are embedded
        # The robot, the translucent attractor robot, the ball, the trail.
        for scene_path in (
            "/drake/illustration/icub_iCubGazeboV2_5",
            "/drake/illustration/attractor",
            "/drake/world/ball/0",
            "/trail/0",
        ):
            self.assertTrue(meshcat.HasPath(scene_path), scene_path)
        self.assertAlmostEqual(summary.simulated_time, 1.0)
        self.assertIn("penetrations of solid geometry: 0", summary.Format())

    def test_a_recording_keeps_at_most_its_frames(self):
        """The frame rate is the viewer's, or lower for a run longer than the most frames."""
        from pydrake.geometry import Meshcat

        folder = pathlib.Path(tempfile.mkdtemp())
        for duration, max_frames, rate in ((1.0, 3600, 24.0), (2.0, 10, 5.0)):
            meshcat = Meshcat()
            scenario = LoadScenario(
                REACH,
                f"{{duration: {duration}, visualization: {{max_recorded_frames: {max_frames}}}}}",
            )
            RunScenario(scenario, meshcat=meshcat, record=str(folder / "run.html"))
            self.assertEqual(meshcat.get_mutable_recording().frames_per_second(), rate)

    def test_cli_run(self):
        import contextlib
        import io

        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            cli.main(["run", str(REACH), "--duration", "0.5", "--no-meshcat"])
        self.assertIn("simulated 0.50 s", out.getvalue())
        self.assertIn("ball", out.getvalue())
        err = io.StringIO()
        with self.assertRaises(SystemExit) as raised, contextlib.redirect_stderr(err):
            cli.main(["run", str(DIAGRAMS / "missing.yaml"), "--no-meshcat"])
        self.assertEqual(raised.exception.code, 2)
        self.assertRegex(err.getvalue(), r"^error: .*missing.yaml: no such file\n$")
        # A shipped scenario by its name.
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            cli.main(["run", "reach_around_ball", "--duration", "0.1", "--no-meshcat"])
        self.assertIn("simulated 0.10 s", out.getvalue())


if __name__ == "__main__":
    unittest.main()
