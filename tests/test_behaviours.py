"""Parallel behaviours (ch. 9.4.2): the composition of several clients on one robot against
closed forms and its refusals, and the pointing behaviour (gaze, palm normal) in simulation."""

import contextlib
import io
import json
import pathlib
import shutil
import tempfile
import types
import unittest

import numpy as np
import pandas as pd
from pydrake.common.eigen_geometry import AngleAxis
from pydrake.math import RotationMatrix
from pydrake.systems.primitives import ConstantVectorSource
from test_figures import FigureTest

from mobee_drake import cli
from mobee_drake.behaviours.pointing import PointingError
from mobee_drake.behaviours.torso import PlaceTorso, PostureGrid, ReachMap
from mobee_drake.experiments import parallel_behaviours
from mobee_drake.reaching.predictors import RewardHistories
from mobee_drake.scenario import BuildScenario, LoadScenario, RunScenario
from mobee_drake.station.builder import MakeMobeeStation
from mobee_drake.station.composition import Behaviour, BehaviourComposer, ComposeBehaviours
from mobee_drake.station.parts import ClientContractError, ClientPorts
from mobee_drake.station.world_events import MakeSimulator

NECK = ["neck_pitch", "neck_roll", "neck_yaw"]
# A target the neck can turn the head to (this model has no eye joints).
IN_VIEW = [-0.6, 0.15, 0.45]


def _Gaze(target: str = "ball", gain: float = 1.0) -> str:
    return (
        f"{{name: gaze, joints: [{', '.join(NECK)}], "
        f"client: !PointAt {{marker: head, target: '{target}', gain: {gain}}}}}"
    )


def _Scenario(*behaviours: str, ball=IN_VIEW, duration: float = 4.0):
    return LoadScenario(
        "parallel_behaviours",
        [
            f"{{objects: [{{name: ball, shape: !Sphere {{radius: 0.04}}, position: {ball}}}]}}",
            f"{{attractor: !Behaviours {{behaviours: [{', '.join(behaviours)}]}}}}",
            f"{{duration: {duration}}}",
        ],
    )


class TestComposer(unittest.TestCase):
    def test_each_joint_from_its_owner_and_forces_on_owned_entries_only(self):
        home = np.array([0.1, 0.2, 0.3, 0.4])
        composer = BehaviourComposer(
            home=home,
            num_markers=2,
            owned_joints={"a": [0, 2], "b": [3]},
            owned_markers={"a": [], "b": [1]},
            config_forces=["a", "b"],
            marker_forces=["b"],
        )
        context = composer.CreateDefaultContext()
        composer.GetInputPort("a.attractor").FixValue(context, [1.0, 2.0, 3.0, 4.0])
        composer.GetInputPort("b.attractor").FixValue(context, [5.0, 6.0, 7.0, 8.0])
        composer.GetInputPort("a.config_force").FixValue(context, [1.0, 1.0, 1.0, 1.0])
        composer.GetInputPort("b.config_force").FixValue(context, [10.0, 10.0, 10.0, 10.0])
        composer.GetInputPort("b.marker_forces").FixValue(context, np.arange(6.0))
        np.testing.assert_array_equal(
            composer.GetOutputPort("attractor").Eval(context), [1.0, 0.2, 3.0, 8.0]
        )
        np.testing.assert_array_equal(
            composer.GetOutputPort("config_force").Eval(context), [1.0, 0.0, 1.0, 10.0]
        )
        np.testing.assert_array_equal(
            composer.GetOutputPort("marker_forces").Eval(context), [0, 0, 0, 3, 4, 5]
        )

    def _Build(self, *behaviours: Behaviour):
        return MakeMobeeStation(
            LoadScenario("parallel_behaviours"),
            prebuild_callback=lambda parts: ComposeBehaviours(parts, list(behaviours)),
        )

    @staticmethod
    def _Hold(name: str):
        def Add(parts):
            source = parts.builder.AddNamedSystem(
                f"{parts.prefix}hold", ConstantVectorSource(parts.mobee.home)
            )
            return ClientPorts(system=source, attractor=source.get_output_port())

        return Add

    def test_conflicts_and_unknown_names_are_refused_in_one_line(self):
        hold = self._Hold("x")
        for behaviours, message in [
            (
                [Behaviour("gaze", ("neck_yaw",), hold), Behaviour("look", ("neck_yaw",), hold)],
                "behaviours 'gaze' and 'look' both claim the joint 'neck_yaw'",
            ),
            (
                [Behaviour("gaze", ("neck_yawn",), hold)],
                "behaviour 'gaze': unknown joint 'neck_yawn'",
            ),
            (
                [Behaviour("a", ("neck_yaw",), hold, ("r_palm",)),
                 Behaviour("b", ("neck_roll",), hold, ("r_palm",))],
                "behaviours 'a' and 'b' both claim the marker 'r_palm'",
            ),
            (
                [Behaviour("a", ("neck_yaw",), hold), Behaviour("a", ("neck_roll",), hold)],
                "behaviours need names of their own",
            ),
        ]:  # fmt: skip
            with self.subTest(message), self.assertRaises(ValueError) as caught:
                self._Build(*behaviours)
            self.assertIn(message, str(caught.exception))
            self.assertNotIn("\n", str(caught.exception))

    def test_a_need_is_met_by_the_offer_of_its_name_only(self):
        """A pointing behaviour with no target of its own points at what another offers."""
        point = [-0.6, -0.2, 0.5]

        def Offer(parts):
            source = parts.builder.AddNamedSystem(
                f"{parts.prefix}spot", ConstantVectorSource(point)
            )
            hold = parts.builder.AddNamedSystem(
                f"{parts.prefix}hold", ConstantVectorSource(parts.mobee.home)
            )
            return ClientPorts(
                system=hold,
                attractor=hold.get_output_port(),
                offers={"target": source.get_output_port()},
            )

        scenario = _Scenario(_Gaze(target=""))
        gaze = scenario.attractor.behaviours[0]
        pointing = Behaviour("gaze", tuple(NECK), gaze.client.AddToBuilder)
        station = self._Build(Behaviour("spot", ("r_elbow",), Offer), pointing)
        simulator = MakeSimulator(station)
        simulator.AdvanceTo(4.0)
        error = station.diagram.GetSubsystemByName("gaze_pointing").GetOutputPort("error_deg")
        self.assertLess(
            error.Eval(error.get_system().GetMyContextFromRoot(simulator.get_context()))[0], 0.5
        )
        with self.assertRaisesRegex(ValueError, "behaviour 'gaze' needs 'target', which no "):
            self._Build(pointing)

    def test_a_lone_client_with_needs_is_refused(self):
        with self.assertRaisesRegex(ClientContractError, "needs ports \\(target\\)"):
            BuildScenario(
                LoadScenario(
                    "parallel_behaviours",
                    "{attractor: !PointAt {marker: head, target: ''}}",
                )
            )

    def test_the_command_line_refuses_a_conflict_in_one_line(self):
        folder = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, folder)
        twice = _Gaze().replace("name: gaze", "name: look")
        err = io.StringIO()
        with contextlib.redirect_stderr(err), self.assertRaises(SystemExit) as exited:
            cli.main(
                ["run", "parallel_behaviours", "--no-record", "--output", str(folder), "--set",
                 f"{{attractor: !Behaviours {{behaviours: [{_Gaze()}, {twice}]}}}}"]
            )  # fmt: skip
        self.assertEqual(exited.exception.code, 2)
        self.assertEqual(err.getvalue().count("\n"), 1, err.getvalue())
        self.assertIn(
            "behaviours 'gaze' and 'look' both claim the joint 'neck_pitch'", err.getvalue()
        )


class TestPointing(unittest.TestCase):
    def test_the_error_rotation(self):
        theta, axis = PointingError(np.array([1.0, 0, 0]), np.array([0, 1.0, 0]))
        self.assertAlmostEqual(theta, np.pi / 2)
        np.testing.assert_allclose(axis, [0, 0, 1])
        theta, axis = PointingError(np.array([1.0, 0, 0]), np.array([-1.0, 0, 0]))
        self.assertAlmostEqual(theta, np.pi)
        self.assertAlmostEqual(float(np.dot(axis, [1.0, 0, 0])), 0.0)
        self.assertAlmostEqual(float(np.linalg.norm(axis)), 1.0)

    def test_the_gaze_turns_the_head_to_the_target(self):
        """The head's marker direction ends pointing at the ball (closed form: the angle
        between it and the line to the ball), from more than 10 degrees off; with gain 0 the
        neck stays home and the error stays."""
        scenario = _Scenario(_Gaze())
        station = BuildScenario(scenario)
        simulator = MakeSimulator(station)
        simulator.Initialize()
        context = simulator.get_context()
        start = self._Angle(station, context)
        simulator.AdvanceTo(4.0)
        self.assertGreater(start, 10.0)
        self.assertLess(self._Angle(station, context), 0.5)
        held = RunScenario(_Scenario(_Gaze(gain=0.0)))
        self.assertAlmostEqual(held.outcome["client"]["final_error_deg"], start, delta=1e-6)
        self.assertLess(held.outcome["attractor"]["largest_joint_error_deg"], 1e-6)

    @staticmethod
    def _Angle(station, context) -> float:
        mobee = station.mobee
        i = mobee.marker_index("head")
        mobee_context = mobee.GetMyContextFromRoot(context)
        p = mobee.GetOutputPort("marker_positions").Eval(mobee_context)[3 * i : 3 * i + 3]
        d = mobee.GetOutputPort("marker_directions").Eval(mobee_context)[3 * i : 3 * i + 3]
        u = (np.array(IN_VIEW) - p) / np.linalg.norm(np.array(IN_VIEW) - p)
        return float(np.degrees(np.arccos(np.clip(np.dot(d, u), -1, 1))))

    def test_the_error_is_logged_and_summarised(self):
        log = pathlib.Path(tempfile.mkdtemp()) / "gaze.parquet"
        summary = RunScenario(_Scenario(_Gaze(), duration=2.0), data_log=str(log))
        figures = summary.outcome["client"]
        self.assertEqual(set(figures), {"final_error_deg", "mean_error_deg"})
        self.assertLess(figures["final_error_deg"], figures["mean_error_deg"])
        logged = pd.read_parquet(log)["gaze_pointing.error_deg"].to_numpy()
        self.assertAlmostEqual(logged[-1], figures["final_error_deg"], places=6)
        self.assertGreater(logged[0], 10.0)


class TestTorsoPlacement(unittest.TestCase):
    def test_the_torso_turns_the_target_onto_the_maps_peak(self):
        """A map peaked where the target would be seen with the torso turned by 24 deg about
        its yaw axis (closed form: the target turned back by 24 deg about that axis): the
        behaviour chooses that yaw, and MoBeE turns the torso there."""
        scenario = _Scenario(_Gaze())
        station = BuildScenario(scenario)  # (for the plant's kinematics)
        plant, context = station.plant, station.plant.CreateDefaultContext()
        joint = plant.GetJointByName("torso_yaw")
        X_WJ = joint.frame_on_parent().CalcPoseInWorld(context)
        axis, centre = X_WJ.rotation() @ joint.revolute_axis(), X_WJ.translation()
        turn = np.radians(24.0)
        back = RotationMatrix(AngleAxis(-turn, axis))
        peak = centre + back @ (np.array(IN_VIEW) - centre)
        placement = PlaceTorso(
            reach_map=lambda x: -np.linalg.norm(x - peak, axis=1),
            target="ball",
            levels=41,
            range_fraction=1.0,
            period=0.1,
        )
        composed = MakeMobeeStation(
            scenario,
            prebuild_callback=lambda parts: ComposeBehaviours(
                parts, [Behaviour("torso", ("torso_yaw",), placement.AddToBuilder)]
            ),
        )
        system = composed.diagram.GetSubsystemByName("torso_torso_placement")
        scores = system.Scores(np.array(IN_VIEW))
        grid = PostureGrid(composed.mobee, ["torso_yaw"], 41, 1.0)[:, 0]
        self.assertAlmostEqual(grid[np.argmax(scores)], turn, delta=np.radians(1.3))
        simulator = MakeSimulator(composed)
        simulator.AdvanceTo(8.0)
        yaw = composed.robot_state.Eval(simulator.get_context())[
            composed.mobee.joint_index("torso_yaw")
        ]
        self.assertAlmostEqual(np.degrees(yaw), 24.0, delta=2.0)
        outcome = system.Outcome(system.GetMyContextFromRoot(simulator.get_context()))
        self.assertAlmostEqual(
            outcome["posture_deg"]["torso_yaw"], np.degrees(grid[np.argmax(scores)])
        )

    def test_a_flat_map_keeps_the_torso_home(self):
        scenario = _Scenario(_Gaze())
        placement = PlaceTorso(reach_map=lambda x: np.zeros(len(x)), target="ball", period=0.1)
        composed = MakeMobeeStation(
            scenario,
            prebuild_callback=lambda parts: ComposeBehaviours(
                parts, [Behaviour("torso", ("torso_yaw", "torso_pitch"), placement.AddToBuilder)]
            ),
        )
        simulator = MakeSimulator(composed)
        simulator.AdvanceTo(1.0)
        q = composed.robot_state.Eval(simulator.get_context())
        for joint in ("torso_yaw", "torso_pitch"):
            i = composed.mobee.joint_index(joint)
            self.assertAlmostEqual(q[i], composed.mobee.home[i], delta=1e-9)


class TestReachMaps(unittest.TestCase):
    def test_the_two_readings(self):
        """One transition and two reaches: "evidence" is the best mean reward recorded within
        5 cm (0 where none was); "prediction" is eq. 8.5, which tends to its prior (1) far away."""
        histories = RewardHistories(np.array([False, True, True]))
        records = [
            (1, [0, 0, 0], 0.6), (1, [0.02, 0, 0], 0.4), (2, [0.3, 0, 0], 0.9),
            (0, [0.01, 0, 0], 5.0),  # a transition's: not a reach
        ]  # fmt: skip
        for sa, target, reward in records:
            histories.Record(sa, target, 0.0, reward)
        learner = types.SimpleNamespace(num_transitions=1, num_state_actions=3, histories=histories)
        points = np.array([[0.01, 0, 0], [0.3, 0.04, 0], [2.0, 0, 0]])
        np.testing.assert_allclose(ReachMap(learner, "evidence")(points), [0.5, 0.9, 0.0])
        far = ReachMap(learner, "prediction")(points)[2]
        self.assertGreater(far, 0.9)  # (the optimistic prior)
        with self.assertRaisesRegex(ValueError, "unknown reach map 'nearest'"):
            ReachMap(learner, "nearest")


class TestParallelBehavioursExperiment(FigureTest):
    def test_the_smoke_battery(self):
        """Two seeds of 6 s: both conditions report, the palm faces the ball better with its
        behaviour on, nothing penetrates, and the figure reads alone."""
        folder = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, folder)
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            parallel_behaviours.main(
                ["--seeds", "2", "--duration", "6", "--output", str(folder), "--workers", "2"]
            )
        runs = [
            parallel_behaviours.ParallelRun(**json.loads(path.read_text()))
            for path in sorted(folder.glob("runs/*/result.json"))
        ]
        self.assertEqual(sorted((r.seed, r.condition) for r in runs),
                         [(0, "off"), (0, "on"), (1, "off"), (1, "on")])  # fmt: skip
        self.assertTrue(all(r.end_angles and r.penetrating_steps == 0 for r in runs))
        mean = {c: np.mean([r.palm_mean for r in runs if r.condition == c]) for c in ("on", "off")}
        self.assertLess(mean["on"], mean["off"])
        report = (folder / "report.md").read_text()
        self.assertIn("| on | 2 |", report)
        self.assertIn("On minus off, paired by seed (Holm over the 2):", report)
        self.assertReadable(parallel_behaviours.Figure(runs), "parallel behaviours")


if __name__ == "__main__":
    unittest.main()
