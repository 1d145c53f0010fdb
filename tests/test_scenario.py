"""Scenarios from Drake's config types: the test file's Defaults and OneOfEverything, every shipped
scenario, tagged unions that make an illegal combination unwritable, one seed for every generator,
and a client of one's own through the station's seam."""

import dataclasses as dc
import pathlib
import unittest

import numpy as np
from pydrake.common.yaml import yaml_dump_typed
from pydrake.geometry import Meshcat
from pydrake.systems.primitives import ConstantVectorSource

from mobee_drake.resources import ScenarioNames
from mobee_drake.scenario import BuildScenario, LoadScenario, RunScenario, Scenario
from mobee_drake.station.builder import MakeMobeeStation
from mobee_drake.station.config import Dynamic
from mobee_drake.station.outcome import AttractorOutcome
from mobee_drake.station.parts import ClientPorts, StationParts
from mobee_drake.station.runner import RunStation
from mobee_drake.station.world_events import MakeSimulator
from mobee_drake.yaml_io import TaggedData, YamlFileError

TEST_SCENARIOS = pathlib.Path(__file__).with_name("test_scenarios.yaml")


def _AsData(scenario: Scenario) -> dict:
    """The scenario as plain data (Drake's config structs compare by identity, not value)."""
    return TaggedData(yaml_dump_typed(scenario))


class TestScenarioFile(unittest.TestCase):
    def test_defaults_are_the_schemas(self):
        loaded = LoadScenario(TEST_SCENARIOS, scenario_name="Defaults")
        self.assertEqual(_AsData(loaded), _AsData(Scenario()))

    def test_one_of_everything_sets_every_field(self):
        scenario = _AsData(LoadScenario(TEST_SCENARIOS, scenario_name="OneOfEverything"))
        defaults = _AsData(Scenario())
        self.assertEqual(sorted(scenario), sorted(f.name for f in dc.fields(Scenario)))
        unchanged = [name for name in scenario if scenario[name] == defaults[name]]
        self.assertEqual(unchanged, [])
        self.assertEqual(scenario["mover"]["!Reflex"]["speed_deg"], 30.0)

    def test_every_test_scenario_builds_and_runs(self):
        for name in ("Defaults", "OneOfEverything", "DynamicForce"):
            with self.subTest(name):
                scenario = LoadScenario(TEST_SCENARIOS, scenario_name=name)
                scenario.duration = min(scenario.duration, 0.3)
                summary = RunStation(BuildScenario(scenario), scenario.duration)
                self.assertAlmostEqual(summary.simulated_time, scenario.duration)

    def test_one_of_everything_applies_its_world_events(self):
        scenario = LoadScenario(TEST_SCENARIOS, scenario_name="OneOfEverything")
        station = BuildScenario(scenario)
        simulator = MakeSimulator(station)
        simulator.Initialize()
        context = simulator.get_context()
        self.assertEqual(station.world.Role(context, "ball"), "ghost")
        simulator.AdvanceTo(0.2)
        self.assertEqual(station.world.Role(context, "ball"), "obstacle")
        can = station.world.Objects(context)["can"][3]
        np.testing.assert_allclose(can.translation(), [-0.3, -0.25, 0.0])

    def test_dynamic_plant_config_reaches_the_plant(self):
        scenario = LoadScenario(TEST_SCENARIOS, scenario_name="DynamicForce")
        self.assertIsInstance(scenario.mover, Dynamic)
        station = BuildScenario(scenario)
        self.assertEqual(station.plant.time_step(), 0.002)
        self.assertEqual(station.plant.get_discrete_contact_approximation().name, "kSap")


class TestShippedScenarios(unittest.TestCase):
    """Every shipped scenario builds, runs, and does what it is for: each asserts an outcome of
    its own that a robot MoBeE does not move would miss (issue 32)."""

    def _Run(self, name: str, duration: float, meshcat=None):
        """(station, its final root context, the robot's (q, v) at the start) of ``name``."""
        station = BuildScenario(LoadScenario(name, f"{{duration: {duration}}}"), meshcat)
        simulator = MakeSimulator(station)
        simulator.Initialize()
        start = station.robot_state.Eval(simulator.get_context()).copy()
        simulator.AdvanceTo(duration)
        return station, simulator.get_context(), start

    def _Travel(self, station, context, start) -> float:
        """The largest joint displacement (deg) from the start to ``context``."""
        n = len(station.mobee.joints)
        return np.degrees(np.abs(station.robot_state.Eval(context)[:n] - start[:n]).max())

    def test_every_shipped_scenario_is_tested_here(self):
        tested = {n.removeprefix("test_") for n in dir(self) if n.startswith("test_")}
        self.assertLessEqual(set(ScenarioNames()), tested)

    def test_reach_around_ball(self):
        """The palm heads for its goal, beyond the ball, and stops at the ball without touching
        it (from 10.5 cm to 6.0 cm of the goal)."""
        station, context, _ = self._Run("reach_around_ball", 4.0)
        start = AttractorOutcome(station, station.diagram.CreateDefaultContext())
        end = AttractorOutcome(station, context)
        palm = "marker_distance_to_goal_m"
        self.assertGreater(start[palm]["r_palm"], 0.09)
        self.assertLess(end[palm]["r_palm"], 0.65 * start[palm]["r_palm"])
        report = station.monitor.Report(station.monitor.GetMyContextFromRoot(context))
        self.assertGreater(report.closest_approach["ball"], 0.0)

    def _AssertExplores(self, name: str, duration: float) -> None:
        """Every agent starts its actions from more than one state: the robot moves between
        states (the learned counts cannot show it: a prior fills every outcome)."""
        station = BuildScenario(LoadScenario(name, f"{{duration: {duration}}}"))
        simulator = MakeSimulator(station)
        simulator.Initialize()
        supervisor = station.client
        starts = {agent: set() for agent in supervisor.agent_names}
        for t in np.arange(1.0, duration + 0.5, 1.0):
            simulator.AdvanceTo(t)
            context = supervisor.GetMyContextFromRoot(simulator.get_context())
            for agent, record in zip(supervisor.agent_names, supervisor.Records(context)):
                starts[agent].add(record.state)
        for agent, states in starts.items():
            with self.subTest(agent):
                self.assertGreater(len(states), 2)

    def test_explore_hypercube(self):
        self._AssertExplores("explore_hypercube", 40.0)

    def test_three_agents_table(self):
        self._AssertExplores("three_agents_table", 40.0)

    def test_motor_babbling(self):
        """The robot babbles: some joint travels far from home."""
        self.assertGreater(self._Travel(*self._Run("motor_babbling", 8.0)), 20.0)

    def test_katana(self):
        self.assertGreater(self._Travel(*self._Run("katana", 6.0)), 20.0)

    def test_three_link_arm(self):
        """The arm of one's own babbles, and MoBeE holds it off the ball it swings into."""
        station, context, start = self._Run("three_link_arm", 6.0)
        self.assertGreater(self._Travel(station, context, start), 20.0)
        report = station.monitor.Report(station.monitor.GetMyContextFromRoot(context))
        self.assertGreater(report.closest_approach["ball"], 0.0)
        self.assertEqual(report.penetrating_steps, 0)

    def test_parallel_behaviours(self):
        """All three behaviours act at once, without a penetration: the agent explores, the
        head ends looking at the ball, and the palm faces it better than with its wrist held
        at home (the same run with the palm behaviour only measuring)."""
        on = RunScenario(LoadScenario("parallel_behaviours", "{duration: 20}"))
        scenario = LoadScenario("parallel_behaviours", "{duration: 20}")
        palm = scenario.attractor.behaviours[1]
        palm.client = dc.replace(palm.client, gain=0.0)
        off = RunScenario(scenario)
        figures = on.outcome["client"]
        self.assertEqual(on.safety.penetrating_steps, 0)
        self.assertLess(figures["gaze_pointing"]["final_error_deg"], 5.0)
        self.assertGreaterEqual(
            figures["reach_exploration_supervisor"]["agents"]["right_arm"]["actions"], 2
        )
        palm = "palm_pointing"
        self.assertLess(
            figures[palm]["mean_error_deg"], off.outcome["client"][palm]["mean_error_deg"] - 10.0
        )

    def test_icub_and_katana(self):
        """Both robots move: the iCub's arms and its companion Katana."""
        station, context, start = self._Run("icub_and_katana", 6.0)
        self.assertGreater(self._Travel(station, context, start), 20.0)
        katana = station.diagram.GetSubsystemByName("katana_mobee")
        q = katana.GetInputPort("state").Eval(katana.GetMyContextFromRoot(context))
        n = len(katana.joints)
        self.assertGreater(np.degrees(np.abs(q[:n] - katana.home).max()), 20.0)

    def test_interactive(self):
        """A slider moves the robot: its joint follows the slider to the value set."""
        meshcat = Meshcat()
        station = BuildScenario(LoadScenario("interactive", "{duration: 3}"), meshcat)
        simulator = MakeSimulator(station)
        simulator.Initialize()
        elbow = station.mobee.joint_index("r_elbow")
        home = np.degrees(station.mobee.home[elbow])
        meshcat.SetSliderValue("r_elbow", home + 30.0)
        simulator.AdvanceTo(3.0)
        q = station.robot_state.Eval(simulator.get_context())
        self.assertAlmostEqual(np.degrees(q[elbow]), home + 30.0, delta=2.0)


class TestIllegalCombinations(unittest.TestCase):
    def _Load(self, text: str):
        return LoadScenario(TEST_SCENARIOS, text, scenario_name="Defaults")

    def test_mover_fields_belong_to_their_tag(self):
        with self.assertRaisesRegex(YamlFileError, "control"):
            self._Load("{mover: !Kinematic {control: force}}")
        with self.assertRaisesRegex(YamlFileError, "speed_deg"):
            self._Load("{mover: !Dynamic {speed_deg: 20}}")
        with self.assertRaisesRegex(YamlFileError, "mover control must be one of"):
            self._Load("{mover: !Dynamic {control: torque}}")

    def test_companions_need_the_kinematic_robot(self):
        with self.assertRaisesRegex(YamlFileError, "kinematic robot only"):
            LoadScenario("icub_and_katana", "{mover: !Dynamic {}}")


class TestOneSeed(unittest.TestCase):
    def _Attractors(self, overrides: str) -> np.ndarray:
        station = BuildScenario(LoadScenario("explore_hypercube", overrides))
        simulator = MakeSimulator(station)
        simulator.Initialize()
        attractors = []
        for t in (0.1, 5.0, 10.0):
            simulator.AdvanceTo(t)
            attractors.append(station.attractor.Eval(simulator.get_context()).copy())
        return np.array(attractors)

    def test_random_seed_reaches_the_exploring_agents(self):
        same = self._Attractors("{random_seed: 3, duration: 10}")
        np.testing.assert_array_equal(same, self._Attractors("{random_seed: 3, duration: 10}"))
        other = self._Attractors("{random_seed: 4, duration: 10}")
        self.assertFalse(np.array_equal(same, other))


class HoldPose:
    """A client of one's own: holds the attractor at the home pose with the elbow bent."""

    def Validate(self) -> None:
        pass

    def AddToBuilder(self, parts: StationParts) -> ClientPorts:
        q_star = parts.mobee.home
        q_star[parts.mobee.joint_index("r_elbow")] = np.radians(80.0)
        source = parts.builder.AddNamedSystem("hold_pose", ConstantVectorSource(q_star))
        return ClientPorts(system=source, attractor=source.get_output_port())


class TestOwnClient(unittest.TestCase):
    def test_a_client_of_ones_own_through_the_seam(self):
        scenario = LoadScenario("reach_around_ball")
        station = MakeMobeeStation(scenario, prebuild_callback=HoldPose().AddToBuilder)
        self.assertIsInstance(station.client, ConstantVectorSource)
        simulator = MakeSimulator(station)
        context = simulator.get_context()
        elbow = station.mobee.joint_index("r_elbow")
        self.assertEqual(np.degrees(station.attractor.Eval(context)[elbow]), 80.0)
        n = len(station.mobee.joints)
        start = np.degrees(station.robot_state.Eval(context)[elbow])
        simulator.AdvanceTo(3.0)
        q = station.robot_state.Eval(context)[:n]
        # The spring pulls the elbow from its home angle toward the client's 80 degrees.
        self.assertGreater(np.degrees(q[elbow]), start + 20.0)

    def test_without_a_client_the_attractor_is_an_input(self):
        station = MakeMobeeStation(LoadScenario("reach_around_ball"))
        self.assertIsNone(station.client)
        simulator = MakeSimulator(station)
        context = simulator.get_mutable_context()
        q_star = station.mobee.home
        station.diagram.GetInputPort("attractor").FixValue(context, q_star)
        simulator.AdvanceTo(0.5)
        np.testing.assert_array_equal(station.attractor.Eval(context), q_star)


if __name__ == "__main__":
    unittest.main()
