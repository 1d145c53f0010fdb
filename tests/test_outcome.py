"""What a run achieved: the attractor's outcome against a free reach that converges, the
exploring agents' figures against their own models, and ``summary.json``."""

import contextlib
import io
import json
import pathlib
import shutil
import tempfile
import unittest

import numpy as np

from mobee_drake import cli
from mobee_drake.scenario import LoadScenario, RunScenario


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
