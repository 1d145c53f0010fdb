"""What a run achieved: the attractor's outcome against a free reach that converges, the markers
a task involves, targets reached or not against closed forms, the world events applied, the
exploring agents' figures against their own models, and ``summary.json``."""

import contextlib
import io
import json
import pathlib
import shutil
import tempfile
import unittest

import numpy as np
from pydrake.geometry import Box, Convex, Cylinder, Sphere
from pydrake.math import RigidTransform, RollPitchYaw

from mobee_drake import cli
from mobee_drake.resources import ModelsDirectory
from mobee_drake.scenario import LoadScenario, RunScenario
from mobee_drake.world.point_distance import SignedDistance

# The example arm (models/three_link_arm.urdf) swings to joint1 = 90 deg: its tip ends at
# (0, 0.9, 0), the centre of the cup; its elbow marker at (0, 0.3, 0).
ARM_TASK = """
robot: !ModelFileConfig {}
objects:
  - {name: cup, shape: !Sphere {radius: 0.05}, position: [0.0, 0.9, 0.0], role: target}
  - {name: far, shape: !Box {size: [0.1, 0.1, 0.1]}, position: [-0.9, -0.5, 0.0], role: target}
  - {name: wall, shape: !Box {size: [0.05, 0.05, 0.05]}, position: [-0.5, 0.5, 0.0], role: ghost}
world_events:
  - {time: 1.0, object: wall, role: obstacle}
  - {time: 2.0, object: wall, position: [-0.6, 0.6, 0.0]}
  - {time: 9.0, object: wall, role: ghost}
attractor: !FixedAttractor {joints_deg: {joint1: 90}}
duration: 6.0
visualization: {trail_marker: tip}
"""


class TestOutcome(unittest.TestCase):
    def test_a_free_reach_ends_at_its_attractor(self):
        # Without the ball and the table, the spring pulls the arm onto the attractor: after 12 s
        # (time constants near one second) every joint and marker is there.
        summary = RunScenario(LoadScenario("reach_around_ball", "{objects: [], duration: 12}"))
        attractor = summary.outcome["attractor"]
        self.assertLess(attractor["largest_joint_error_deg"], 0.05)
        for marker, distance in attractor["marker_distance_to_goal_m"].items():
            self.assertLess(distance, 1e-4, marker)
        # With the ball in the way the palm ends short of its goal.
        blocked = RunScenario(LoadScenario("reach_around_ball", "{duration: 12}")).outcome
        self.assertGreater(blocked["attractor"]["marker_distance_to_goal_m"]["r_palm"], 0.01)

    def _Arm(self, *overrides: str):
        path = pathlib.Path(tempfile.mkdtemp()) / "arm.yaml"
        path.write_text(ARM_TASK)
        return RunScenario(LoadScenario(path, list(overrides))).outcome

    def test_only_the_markers_the_attractor_moves_are_reported(self):
        # joint1 moves both markers; joint3 only the tip (the elbow marker sits at joint2).
        swing = self._Arm()["attractor"]["marker_distance_to_goal_m"]
        self.assertEqual(set(swing), {"tip", "elbow"})
        wrist = self._Arm("{attractor: !FixedAttractor {joints_deg: {joint1: 0, joint3: 45}}}")
        self.assertEqual(set(wrist["attractor"]["marker_distance_to_goal_m"]), {"tip"})

    def test_targets_reached_or_not_and_the_events_applied(self):
        outcome = self._Arm()
        cup, far = outcome["targets"]["cup"], outcome["targets"]["far"]
        self.assertEqual((cup["reached"], cup["marker"]), (True, "tip"))
        self.assertAlmostEqual(cup["distance_m"], -0.05, delta=1e-6)  # the tip at its centre
        self.assertEqual((far["reached"], far["marker"]), (False, "elbow"))
        # The elbow at (0, 0.3, 0); the box's nearest corner at (-0.85, -0.45, 0).
        self.assertAlmostEqual(far["distance_m"], np.hypot(0.85, 0.75), delta=1e-6)
        # The event at 9 s is after the run's end: not applied.
        self.assertEqual(
            outcome["world_events"],
            ["1 s: wall becomes an obstacle", "2 s: wall moves to [-0.6, 0.6, 0.0]"],
        )

    def test_the_agents_figures(self):
        summary = RunScenario(LoadScenario("explore_hypercube", "{duration: 30}"))
        (agent,) = summary.outcome["client"]["agents"].values()
        self.assertEqual(agent["state_actions"], 64)
        self.assertGreaterEqual(agent["actions"], 4)
        # Without obstacles each action tries a state-action; some may be tried twice.
        self.assertLessEqual(agent["state_actions_tried"], agent["actions"])
        self.assertGreater(agent["state_actions_tried"], 0)
        # Value iteration stopped once no value changed by delta (1e-3) in a sweep.
        self.assertLess(agent["value_iteration_residual"], 1e-3)


class TestSignedDistance(unittest.TestCase):
    """Closed forms: a point's signed distance to each shape, posed off the origin."""

    def test_each_shape(self):
        X = RigidTransform(RollPitchYaw(0.0, 0.0, np.pi / 2), [1.0, 2.0, 3.0])
        pillar = ModelsDirectory() / "pillar.obj"  # a hexagonal prism, 0.05 m to its corners
        for shape, p_O, expected in [
            (Sphere(0.5), [0.0, 0.0, 2.0], 1.5),
            (Sphere(0.5), [0.1, 0.0, 0.0], -0.4),
            (Box(0.2, 0.4, 0.6), [0.4, 0.0, 0.0], 0.3),  # off a face
            (Box(0.2, 0.4, 0.6), [0.4, 0.5, 0.0], np.hypot(0.3, 0.3)),  # off an edge
            (Box(0.2, 0.4, 0.6), [0.05, 0.0, 0.0], -0.05),  # inside, to the nearest face
            (Cylinder(0.1, 1.0), [0.0, 0.3, 0.0], 0.2),  # off the side
            (Cylinder(0.1, 1.0), [0.0, 0.0, 0.7], 0.2),  # off an end
            (Cylinder(0.1, 1.0), [0.4, 0.0, 0.9], np.hypot(0.3, 0.4)),  # off the rim
            (Convex(str(pillar)), [0.0, 0.0, 0.5], 0.3),  # above its top face
            (Convex(str(pillar)), [0.02, 0.0, 0.0], -0.03 * np.cos(np.pi / 6)),  # to a side
        ]:
            with self.subTest(shape=type(shape).__name__, p_O=p_O):
                self.assertAlmostEqual(SignedDistance(shape, X, X @ np.array(p_O)), expected)


class TestSummaryFile(unittest.TestCase):
    def test_the_cli_writes_the_summary_beside_the_recording(self):
        folder = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, folder)
        recording = folder / "run.html"
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            cli.main(["run", "reach_around_ball", "--duration", "1", "--record", str(recording)])
        text = (folder / "run.summary.json").read_text()
        data = json.loads(text, parse_constant=lambda name: self.fail(f"{name} in JSON"))
        self.assertAlmostEqual(data["simulated_time"], 1.0)
        self.assertEqual(data["recording"], str(recording.resolve()))
        self.assertIsNone(data["safety"]["closest_approach"]["table"])
        self.assertEqual(
            set(data["outcome"]["attractor"]),
            {"largest_joint_error_deg", "largest_error_joint", "marker_distance_to_goal_m"},
        )
        self.assertTrue(np.isfinite(data["outcome"]["attractor"]["largest_joint_error_deg"]))


if __name__ == "__main__":
    unittest.main()
