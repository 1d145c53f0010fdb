"""The data log of a run (station/data_log.py) and the recording's world (station/viewer.py)."""

import pathlib
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
from pydrake.geometry import SceneGraph
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import DiagramBuilder

from mobee_drake.mobee.system import FORCE_TERMS
from mobee_drake.scenario import BuildScenario, LoadScenario, RunScenario
from mobee_drake.station.viewer import WorldDrawer
from mobee_drake.station.world_events import MakeSimulator
from mobee_drake.world.live_world import LiveWorld
from mobee_drake.world.objects import SceneObject, Sphere

# The ball becomes a ghost at 0.5 s; the log keeps a row every 20 ms.
GHOST_AT_HALF_A_SECOND = """{duration: 1.0, data_log: {period: 0.02},
world_events: [{time: 0.5, object: ball, role: ghost}]}"""


def _Folder() -> pathlib.Path:
    return pathlib.Path(tempfile.mkdtemp())


class TestDataLog(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.scenario = LoadScenario("reach_around_ball", GHOST_AT_HALF_A_SECOND)
        cls.station = BuildScenario(cls.scenario)
        simulator = MakeSimulator(cls.station)
        simulator.Initialize()
        simulator.AdvanceTo(1.0)
        cls.context = simulator.get_context()
        cls.path = _Folder() / "run.log.parquet"
        cls.station.data_log.Write(cls.path, cls.context)
        cls.log = pd.read_parquet(cls.path)

    def test_rows_every_period_from_zero_to_the_end(self):
        np.testing.assert_allclose(self.log["time"], np.arange(51) * 0.02, atol=1e-12)

    def test_columns_and_units(self):
        joints, markers = self.station.mobee.joints, self.station.mobee.marker_names
        expected = (
            ["time"]
            + [f"{prefix}.{j}" for prefix in ("q", "v", "q_star") for j in joints]
            + [f"force.{term}" for term in (*FORCE_TERMS, "total")]
            + [f"marker.{m}.{a}" for m in markers for a in "xyz"]
            + ["field_pairs", "closest_distance", "world_events"]
        )
        self.assertEqual(list(self.log.columns), expected)
        schema = pq.read_schema(self.path)
        units = {name: schema.field(name).metadata[b"unit"].decode() for name in expected}
        self.assertEqual(units["time"], "s")
        self.assertEqual(units[f"q.{joints[0]}"], "rad")
        self.assertEqual(units[f"v.{joints[0]}"], "rad/s")
        self.assertEqual(units["closest_distance"], "m")
        self.assertEqual(schema.metadata[b"period"], b"0.02")

    def test_the_last_row_is_the_final_state(self):
        """The last row holds what the diagram's ports say at the end."""
        station, context, last = self.station, self.context, self.log.iloc[-1]
        n = len(station.mobee.joints)
        state = station.robot_state.Eval(context)
        q = [last[f"q.{j}"] for j in station.mobee.joints]
        v = [last[f"v.{j}"] for j in station.mobee.joints]
        np.testing.assert_array_equal(q, state[:n])
        np.testing.assert_array_equal(v, state[n:])
        mobee_context = station.mobee.GetMyContextFromRoot(context)
        total = station.mobee.GetOutputPort("total").Eval(mobee_context)
        self.assertAlmostEqual(last["force.total"], np.linalg.norm(total), places=12)
        palm = station.mobee.GetOutputPort("marker_positions").Eval(mobee_context)
        i = 3 * station.mobee.marker_index("r_palm")
        np.testing.assert_array_equal(
            [last["marker.r_palm.x"], last["marker.r_palm.y"], last["marker.r_palm.z"]],
            palm[i : i + 3],
        )

    def test_field_pairs_and_the_closest_distance(self):
        """Before the ghost the palm nears the ball inside its field; no pair means NaN."""
        inside = self.log[self.log["field_pairs"] > 0]
        self.assertGreater(len(inside), 0)
        self.assertTrue(np.all(np.isfinite(inside["closest_distance"])))
        self.assertTrue(np.all(inside["closest_distance"] > 0))  # never into the ball
        self.assertTrue(
            np.all(np.isnan(self.log[self.log["field_pairs"] == 0]["closest_distance"]))
        )

    def test_the_world_event_shows_in_the_row_after_its_time(self):
        events = self.log[self.log["world_events"] != ""]
        self.assertEqual(list(events["world_events"]), ["ball: role ghost"])
        self.assertAlmostEqual(events["time"].iloc[0], 0.52)
        # A ghost is outside every field: from then on nothing is inside one.
        self.assertEqual(self.log[self.log["time"] > 0.52]["field_pairs"].max(), 0)

    def test_full_forces_sum_to_the_total(self):
        scenario = LoadScenario(
            "reach_around_ball", "{duration: 0.3, data_log: {full_forces: true}}"
        )
        path = _Folder() / "full.parquet"
        RunScenario(scenario, data_log=str(path))
        log = pd.read_parquet(path)
        for joint in ("r_elbow", "torso_yaw"):
            terms = sum(log[f"force.{term}.{joint}"] for term in FORCE_TERMS)
            np.testing.assert_allclose(terms, log[f"force.total.{joint}"], atol=1e-12)
        self.assertNotIn("force.total", log.columns)

    def test_the_agents_actions_are_logged(self):
        path = _Folder() / "explore.parquet"
        summary = RunScenario(
            LoadScenario("explore_hypercube", "{duration: 30}"), data_log=str(path)
        )
        log = pd.read_parquet(path)
        ((name, outcome),) = summary.outcome["client"]["agents"].items()
        done = log[f"agent.{name}.actions_done"]
        self.assertTrue(np.all(np.diff(done) >= 0))
        self.assertGreater(outcome["actions"], 0)
        self.assertEqual(done.iloc[-1], outcome["actions"])
        self.assertGreater(log[f"agent.{name}.state_action"].nunique(), 1)

    def AssertIsTheWholeRun(self, path: pathlib.Path) -> None:
        """The log at ``path`` is that of reach_around_ball run for 1 s without a stop."""
        resumed = pd.read_parquet(path)
        whole = _Folder() / "whole.parquet"
        RunScenario(LoadScenario("reach_around_ball", "{duration: 1.0}"), data_log=str(whole))
        whole = pd.read_parquet(whole)
        self.assertEqual(list(resumed["time"]), list(whole["time"]))
        np.testing.assert_allclose(
            resumed["q.r_elbow"].to_numpy(), whole["q.r_elbow"].to_numpy(), atol=1e-12
        )

    def test_a_resumed_run_continues_the_log(self):
        folder = _Folder()
        path, checkpoint = folder / "run.parquet", str(folder / "checkpoint")
        for duration in (0.5, 1.0):
            scenario = LoadScenario("reach_around_ball", f"{{duration: {duration}}}")
            RunScenario(scenario, data_log=str(path), checkpoint=checkpoint)
        self.AssertIsTheWholeRun(path)

    def test_a_resumed_log_is_the_checkpoints_never_a_file_left_at_its_path(self):
        """Issue 31, item 2: the log was written at the end only, and a resumed run kept the
        rows of whatever file sat at its path. Here the first run's log never reaches the path
        (as after a kill), another run's log sits there instead, and the stale segment of a
        killed run lies beside the checkpoint's: the resumed log is still the whole run's."""
        folder = _Folder()
        path, checkpoint = folder / "run.parquet", folder / "checkpoint"
        RunScenario(
            LoadScenario("reach_around_ball", "{duration: 0.5}"),
            data_log=str(folder / "first.parquet"),
            checkpoint=str(checkpoint),
        )
        RunScenario(
            LoadScenario("reach_around_ball", "{duration: 1.0, time_step: 0.02}"),
            data_log=str(path),
        )
        (checkpoint / "log" / "000001.parquet").write_bytes(b"a killed run's segment")
        RunScenario(
            LoadScenario("reach_around_ball", "{duration: 1.0}"),
            data_log=str(path),
            checkpoint=str(checkpoint),
        )
        self.AssertIsTheWholeRun(path)

    def test_a_run_killed_at_random_points_logs_the_uninterrupted_run_row_for_row(self):
        """Issue 31, item 2: ``run --checkpoint --log`` SIGKILLed three times, each a random
        0-50 ms after a random 1-4 more checkpoints (a seeded draw; some kills land inside a
        checkpoint's write), then run to its end: its log equals an uninterrupted run's in every
        row and column."""
        folder = _Folder()
        command = [sys.executable, "-m", "mobee_drake.cli", "run", "explore_hypercube",
                   "--duration", "120", "--no-meshcat", "--no-record"]  # fmt: skip
        subprocess.run([*command, "--log", "whole.parquet"], cwd=folder, check=True,
                       capture_output=True)  # fmt: skip
        resumed = [*command, "--log", "resumed.parquet", "--checkpoint", "checkpoint"]
        rng, done = np.random.default_rng(31), 0
        for _ in range(3):
            run = subprocess.Popen(resumed, cwd=folder, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)  # fmt: skip
            target, deadline = done + rng.integers(1, 5), time.monotonic() + 60
            while done < target and run.poll() is None and time.monotonic() < deadline:
                time.sleep(0.002)
                done = max([int(p.name[1:]) for p in folder.glob("checkpoint/g*")] or [0])
            time.sleep(rng.uniform(0.0, 0.05))
            run.kill()
            self.assertEqual(run.wait(), -signal.SIGKILL, "the run ended before its kill")
        subprocess.run(resumed, cwd=folder, check=True, capture_output=True)
        whole = pd.read_parquet(folder / "whole.parquet")
        pd.testing.assert_frame_equal(pd.read_parquet(folder / "resumed.parquet"), whole)
        self.assertAlmostEqual(whole["time"].iloc[-1], 120.0)

    def test_a_long_run_keeps_at_most_its_rows(self):
        """2 s at 10 ms periods with at most 50 rows: a row every 40 ms (memory bounded)."""
        scenario = LoadScenario("reach_around_ball", "{duration: 2.0, data_log: {max_rows: 50}}")
        path = _Folder() / "bounded.parquet"
        RunScenario(scenario, data_log=str(path))
        log = pd.read_parquet(path)
        self.assertEqual(len(log), 51)
        np.testing.assert_allclose(np.diff(log["time"]), 0.04, atol=1e-12)

    def test_a_run_without_a_log(self):
        station = BuildScenario(LoadScenario("reach_around_ball", "{data_log: {enabled: false}}"))
        self.assertIsNone(station.data_log)
        self.assertFalse(station.diagram.HasSubsystemNamed("data_log"))


class MeshcatSpy:
    """Records the drawing calls a WorldDrawer makes."""

    def __init__(self):
        self.objects, self.visible = {}, {}

    def SetObject(self, path, shape, rgba):
        self.objects[path] = rgba.a()

    def SetTransform(self, path, X):
        pass

    def SetProperty(self, path, name, value, time_in_recording):
        self.visible.setdefault(path, {})[time_in_recording] = value


class TestWorldDrawer(unittest.TestCase):
    def test_each_world_shows_at_its_time(self):
        """A ball made a ghost at 0.6 s: its solid state is shown until then, its ghost after."""
        builder = DiagramBuilder()
        scene_graph = builder.AddSystem(SceneGraph())
        plant = MultibodyPlant(0.0)
        plant.RegisterAsSourceForSceneGraph(scene_graph)
        world = LiveWorld(plant, scene_graph)
        world.Register(SceneObject(name="ball", shape=Sphere(radius=0.05)))
        plant.Finalize()
        spy = MeshcatSpy()
        drawer = builder.AddSystem(WorldDrawer(meshcat=spy, world=world, period=0.1))
        builder.Connect(scene_graph.get_query_output_port(), drawer.get_input_port())
        diagram = builder.Build()
        context = diagram.CreateDefaultContext()
        diagram.ForcedPublish(context)
        context.SetTime(0.6)
        world.SetRole(context, "ball", "ghost")
        diagram.ForcedPublish(context)
        context.SetTime(0.9)
        diagram.ForcedPublish(context)  # nothing changed: nothing recorded
        self.assertEqual(list(spy.objects), ["world/ball/0", "world/ball/1"])
        self.assertEqual(spy.objects["world/ball/0"], 1.0)  # solid
        self.assertLess(spy.objects["world/ball/1"], 1.0)  # translucent
        self.assertEqual(spy.visible["world/ball/0"], {0.0: True, 0.6: False})
        self.assertEqual(spy.visible["world/ball/1"], {0.0: False, 0.6: True})


if __name__ == "__main__":
    unittest.main()
