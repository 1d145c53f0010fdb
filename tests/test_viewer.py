"""The viewer's parts: drawers that send only what changed, a recording compacted without
changing what it plays, a camera framed on the task, light meshes and a light attractor robot."""

import base64
import math
import pathlib
import re
import subprocess
import sys
import tempfile
import unittest

import msgpack
import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import (
    FramePoseVector,
    GeometryFrame,
    GeometryId,
    GeometryInstance,
    IllustrationProperties,
    Meshcat,
    Role,
    SceneGraph,
    Sphere,
)
from pydrake.math import RigidTransform
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import TrajectorySource
from pydrake.trajectories import PiecewisePolynomial
import trimesh

from mobee_drake.mobee.fields import FieldContact
from mobee_drake.robots.icub import DEFAULT_ICUB_MODEL, RIGHT_ARM_JOINTS
from mobee_drake.robots.model_cache import LIGHT_MESH_FLOOR, LIGHT_MESH_SHARE, PreparedIcubModel
from mobee_drake.scenario import BuildScenario, LoadScenario, RunScenario
from mobee_drake.station.recording import KEYFRAME_TOLERANCE, ThinKeyframes
from mobee_drake.station.viewer import (
    ARROW_LENGTH_PER_PENETRATION,
    CAMERA_DIRECTION,
    CAMERA_FIELD_OF_VIEW,
    FRAMED_RADIUS,
    FRAMING_MARGIN,
    ForceDrawer,
    PoseStreamer,
    TrailDrawer,
)
from mobee_drake.station.world_events import MakeSimulator

DIAGRAMS = pathlib.Path(__file__).resolve().parents[1] / "diagrams"
REACH = DIAGRAMS / "reach_around_ball.yaml"


class CountingMeshcat:
    """Records what a drawer sends (method, path, time) and passes it on to a real Meshcat."""

    def __init__(self):
        self.meshcat, self.sent = Meshcat(), []

    def __getattr__(self, name):
        method = getattr(self.meshcat, name)

        def Send(path, *args):
            time = args[-1] if name in ("SetProperty", "SetTransform") else None
            value = args[1] if name == "SetProperty" else None
            self.sent.append((name, path, time, value))
            return method(path, *args)

        return Send

    def Property(self, path: str, name: str):
        return msgpack.unpackb(self.meshcat._GetPackedProperty(path, name))["value"]

    def Transform(self, path: str) -> np.ndarray:
        matrix = msgpack.unpackb(self.meshcat._GetPackedTransform(path))["matrix"]
        return np.array(matrix).reshape(4, 4).T

    def Points(self, path: str) -> np.ndarray:
        command = msgpack.unpackb(self.meshcat._GetPackedObject(path))
        data = command["object"]["geometries"][0]["data"]["attributes"]["position"]["array"]
        return np.frombuffer(data.data, dtype=np.float32).reshape(-1, 3)


def _Marker(times, positions) -> TrajectorySource:
    return TrajectorySource(PiecewisePolynomial.FirstOrderHold(times, np.array(positions).T))


class TestTrailDrawer(unittest.TestCase):
    def Run(self, times, positions, until):
        builder = DiagramBuilder()
        meshcat = CountingMeshcat()
        trail = builder.AddSystem(
            TrailDrawer(meshcat=meshcat, marker_index=0, num_markers=1, period=0.02)
        )
        source = builder.AddSystem(_Marker(times, positions))
        builder.Connect(source.get_output_port(), trail.get_input_port())
        simulator = Simulator(builder.Build())
        simulator.AdvanceTo(until)
        return meshcat

    def test_the_whole_path_is_kept_in_pieces_sent_once(self):
        # 10 cm/s along x for 3 s (30 cm), then still for 7 s.
        start, end = np.array([0.1, 0.2, 0.3]), np.array([0.4, 0.2, 0.3])
        meshcat = self.Run([0.0, 3.0, 10.0], [start, end, end], until=10.0)
        pieces = sorted(
            {p for name, p, *_ in meshcat.sent if name == "SetObject"},
            key=lambda p: int(p.split("/")[-1]),
        )
        # A piece is closed after 0.5 s: six pieces for 3 s of motion, none while still.
        self.assertEqual(len(pieces), 6)
        points = np.vstack([meshcat.Points(p) for p in pieces])
        np.testing.assert_allclose(points[0], start, atol=1e-6)
        np.testing.assert_allclose(points[-1], end, atol=0.002 + 1e-6)
        # Consecutive pieces share their end points: the line is unbroken.
        for a, b in zip(pieces, pieces[1:]):
            np.testing.assert_allclose(meshcat.Points(a)[-1], meshcat.Points(b)[0])
        # A closed piece is never sent again: the pieces sent never go back.
        sends = [int(p.split("/")[-1]) for name, p, *_ in meshcat.sent if name == "SetObject"]
        self.assertEqual(sends, sorted(sends))
        # Nothing is sent while the marker stands still (after 3 s).
        self.assertLessEqual(len(sends), 3.0 / 0.02 + 1)
        # In a recording each piece is hidden from 0 and shown from its start, in order.
        shown = [t for name, _, t, value in meshcat.sent if name == "SetProperty" and value]
        hidden = [t for name, _, t, value in meshcat.sent if name == "SetProperty" and not value]
        self.assertEqual((len(shown), hidden), (6, [0.0] * 6))
        np.testing.assert_allclose(np.diff(shown), 0.5, atol=0.021)

    def test_a_still_marker_draws_nothing(self):
        p = np.array([0.0, 0.0, 1.0])
        meshcat = self.Run([0.0, 1.0], [p, p], until=1.0)
        self.assertEqual(meshcat.sent, [])


def _Contact(point, normal, penetration, margin=0.03) -> FieldContact:
    g = GeometryId.get_new_id()
    return FieldContact(
        g,
        g,
        "palm",
        "ball",
        margin - penetration,
        margin,
        np.array(point),
        np.array(point),
        np.array(normal) / np.linalg.norm(normal),
    )


class TestPoseStreamer(unittest.TestCase):
    """Two bodies' frames in a SceneGraph, their poses fixed at the diagram's input."""

    def setUp(self):
        builder = DiagramBuilder()
        scene_graph = builder.AddSystem(SceneGraph())
        self.source = scene_graph.RegisterSource("bodies")
        self.frames = {}
        for name in ("a", "b"):
            frame = scene_graph.RegisterFrame(self.source, GeometryFrame(name))
            geometry = scene_graph.RegisterGeometry(
                self.source, frame, GeometryInstance(RigidTransform(), Sphere(0.1), name)
            )
            scene_graph.AssignRole(self.source, geometry, IllustrationProperties())
            self.frames[name] = frame
        self.meshcat = CountingMeshcat()
        streamer = builder.AddSystem(
            PoseStreamer(meshcat=self.meshcat, role=Role.kIllustration, prefix="test", period=0.1)
        )
        builder.Connect(scene_graph.get_query_output_port(), streamer.get_input_port())
        builder.ExportInput(scene_graph.get_source_pose_port(self.source), "poses")
        self.diagram = builder.Build()
        self.context = self.diagram.CreateDefaultContext()

    def Publish(self, time: float, a: list, b: list) -> list:
        poses = FramePoseVector()
        poses.set_value(self.frames["a"], RigidTransform(a))
        poses.set_value(self.frames["b"], RigidTransform(b))
        self.diagram.get_input_port().FixValue(self.context, AbstractValue.Make(poses))
        self.context.SetTime(time)
        before = len(self.meshcat.sent)
        self.diagram.ForcedPublish(self.context)
        return [(path, t) for _, path, t, _ in self.meshcat.sent[before:]]

    def test_only_what_moved_is_sent_and_a_restart_keeps_its_still_pose(self):
        origin, moved = [0.0, 0.0, 0.0], [0.0, 0.0, 0.5]
        sent = self.Publish(0.0, origin, origin)
        self.assertEqual(sent, [("/drake/test/a", 0.0), ("/drake/test/b", 0.0)])
        self.assertEqual(self.Publish(0.1, origin, [0.0, 0.0, 5e-5]), [])  # within tolerance
        # a stood still from 0 to 0.1: its still pose at 0.1, then the new one at 0.2.
        sent = self.Publish(0.2, moved, origin)
        self.assertEqual(sent, [("/drake/test/a", 0.1), ("/drake/test/a", 0.2)])
        # And again from 0.2 to 0.5.
        sent = self.Publish(0.6, origin, origin)
        self.assertEqual(sent, [("/drake/test/a", 0.5), ("/drake/test/a", 0.6)])
        np.testing.assert_allclose(self.meshcat.Transform("/drake/test/a")[:3, 3], origin)


class TestForceDrawer(unittest.TestCase):
    def setUp(self):
        self.meshcat = CountingMeshcat()
        self.drawer = ForceDrawer(meshcat=self.meshcat, num_markers=1, period=0.1)
        self.context = self.drawer.CreateDefaultContext()
        self.drawer.GetInputPort("marker_positions").FixValue(self.context, [0.0, 0.0, 0.0])

    def Draw(self, contacts, time=0.0):
        self.context.SetTime(time)
        self.drawer.GetInputPort("field_contacts").FixValue(self.context, contacts)
        self.drawer.ForcedPublish(self.context)

    def test_an_arrow_per_contact_along_its_normal_scaled_by_its_penetration(self):
        contacts = [
            _Contact([0.1, 0.2, 0.3], [0.0, 0.0, 1.0], 0.01),
            _Contact([0.0, -0.1, 0.5], [1.0, 1.0, 0.0], 0.02),
        ]
        self.Draw(contacts)
        for i, c in enumerate(contacts):
            path = f"/field_forces/{i}"
            X = self.meshcat.Transform(path)
            np.testing.assert_allclose(X[:3, 3], c.p_WCa)
            np.testing.assert_allclose(X[:3, 2], c.nhat_BA_W, atol=1e-12)  # The arrow's axis.
            length = self.meshcat.Property(path, "scale")[2]
            self.assertAlmostEqual(length, ARROW_LENGTH_PER_PENETRATION * c.penetration)
            self.assertTrue(self.meshcat.Property(path, "visible"))
        # An unchanged frame sends nothing; one contact fewer hides (not deletes) an arrow.
        sent = len(self.meshcat.sent)
        self.Draw(contacts, 0.1)
        self.assertEqual(len(self.meshcat.sent), sent)
        self.Draw(contacts[:1], 0.2)
        self.assertEqual(self.meshcat.sent[sent:], [("SetProperty", "/field_forces/1", 0.2, False)])
        self.assertFalse(self.meshcat.Property("/field_forces/1", "visible"))
        # Geometry is sent once per arrow, ever.
        lines = [s for s in self.meshcat.sent if s[0] == "SetLineSegments"]
        self.assertEqual(len(lines), 2)

    def test_marker_forces_are_drawn_when_given(self):
        self.drawer.GetInputPort("marker_forces").FixValue(self.context, [0.0, 0.0, 10.0])
        self.Draw([])
        self.assertAlmostEqual(self.meshcat.Property("/marker_forces/0", "scale")[2], 0.1)


class TestRecording(unittest.TestCase):
    def test_thinning_keeps_every_frame_within_the_tolerance(self):
        rng = np.random.default_rng(0)
        still = [1.0, 2.0, 3.0]
        values = [still] * 10 + [[1.0 + 0.01 * k, 2.0, 3.0] for k in range(10)] + [still] * 10
        values = [list(np.add(v, rng.uniform(-1e-6, 1e-6, 3))) for v in values]
        keys = [{"time": k, "value": v} for k, v in enumerate(values)]
        kept = ThinKeyframes(keys)
        self.assertLess(len(kept), 16)
        frames = [k["time"] for k in kept]
        for axis in range(3):
            played = np.interp(range(len(keys)), frames, [k["value"][axis] for k in kept])
            np.testing.assert_allclose(played, [v[axis] for v in values], atol=KEYFRAME_TOLERANCE)

    def test_a_compacted_recording_plays_as_drake_recorded_it(self):
        path = pathlib.Path(tempfile.mkdtemp()) / "run.html"
        meshcat = Meshcat()
        RunScenario(LoadScenario(REACH, "{duration: 3}"), meshcat=meshcat, record=str(path))
        original, compact = _Animation(meshcat.StaticHtml()), _Animation(path.read_text())
        self.assertLess(sum(map(len, (k for _, k in compact))), len(original) * 60)
        for (name, keys), (other, kept) in zip(original, compact):
            self.assertEqual(name, other)
            if not isinstance(keys[0]["value"], list):
                continue
            frames = [k["time"] for k in kept]
            for axis in range(len(keys[0]["value"])):
                played = np.interp(
                    [k["time"] for k in keys], frames, [k["value"][axis] for k in kept]
                )
                np.testing.assert_allclose(
                    played, [k["value"][axis] for k in keys], atol=KEYFRAME_TOLERANCE
                )


def _Animation(html: str) -> list[tuple[str, list[dict]]]:
    """The tracks of a recording's animation: (path and property, keyframes)."""
    for blob in re.findall(r'octet-binary;base64,([A-Za-z0-9+/=]*)"', html):
        command = msgpack.unpackb(base64.b64decode(blob), strict_map_key=False)
        if command["type"] == "set_animation":
            return [
                (a["path"] + t["name"], t["keys"])
                for a in command["animations"]
                for t in a["clip"]["tracks"]
            ]
    raise AssertionError("no animation in the recording")


class TestCameraAndScene(unittest.TestCase):
    def test_the_camera_is_framed_on_the_palm_and_the_ball(self):
        meshcat = Meshcat()
        station = BuildScenario(LoadScenario(REACH), meshcat)
        context = station.diagram.CreateDefaultContext()
        station.diagram.ExecuteInitializationEvents(context)
        camera = msgpack.unpackb(
            meshcat._GetPackedProperty("/Cameras/default/rotated/<object>", "position")
        )["value"]
        x, z, minus_y = camera  # Meshcat's camera is y-up.
        position = np.array([x, -minus_y, z])
        mobee = station.mobee
        palm = mobee.GetOutputPort("marker_positions").Eval(mobee.GetMyContextFromRoot(context))
        palm = palm[3 * mobee.marker_index("r_palm") :][:3]
        ball = np.array(LoadScenario(REACH).objects[1].position)
        target = (palm + ball) / 2
        radius = max(FRAMED_RADIUS, np.linalg.norm(palm - ball) / 2) * FRAMING_MARGIN
        distance = radius / math.sin(CAMERA_FIELD_OF_VIEW / 2)
        np.testing.assert_allclose(position, target + distance * CAMERA_DIRECTION)

    def test_the_drawn_robot_follows_the_plant(self):
        """The streamer's paths are the visualizer's: the drawn hand is where the plant's is."""
        meshcat = Meshcat()
        station = BuildScenario(LoadScenario(REACH), meshcat)
        simulator = MakeSimulator(station)
        context = simulator.get_context()
        scene_graph = station.scene_graph
        hand = station.plant.GetBodyFrameIdOrThrow(station.plant.GetBodyByName("r_hand").index())

        def Hand():
            query = scene_graph.get_query_output_port().Eval(
                scene_graph.GetMyContextFromRoot(context)
            )
            return RigidTransform(query.GetPoseInWorld(hand))

        start = Hand()
        simulator.AdvanceTo(2.0)
        X_WH = Hand()
        path = "/drake/illustration/icub_iCubGazeboV2_5/iCub/r_hand"
        matrix = msgpack.unpackb(meshcat._GetPackedTransform(path))["matrix"]
        drawn = np.array(matrix).reshape(4, 4).T
        self.assertGreater(np.linalg.norm(X_WH.translation() - start.translation()), 0.01)
        np.testing.assert_allclose(drawn, X_WH.GetAsMatrix4(), atol=2e-4)

    def test_the_attractor_robot_draws_only_what_moves(self):
        meshcat = Meshcat()
        scenario = LoadScenario(
            REACH, f"{{robot: {{controlled_joints: {list(RIGHT_ARM_JOINTS)}}}}}"
        )
        station = BuildScenario(scenario, meshcat)
        station.diagram.ForcedPublish(station.diagram.CreateDefaultContext())
        ghost = "/drake/illustration/attractor"
        self.assertTrue(meshcat.HasPath(f"{ghost}/r_forearm"))
        for body in ("chest", "l_forearm", "head", "root_link"):
            self.assertFalse(meshcat.HasPath(f"{ghost}/{body}"), body)
            self.assertTrue(meshcat.HasPath(f"/drake/illustration/icub_iCubGazeboV2_5/iCub/{body}"))


# A process that records a run in a Meshcat of its own (nothing holds it after) and writes a
# space's figures (a model built with a Meshcat holds it in a cycle), then sets the cycle
# collector off on another thread, as a battery's worker pool may: Drake ends a process whose
# Meshcat is destroyed on another thread than its own.
_MESHCAT_THREADS = """
import gc, pathlib, sys, threading
import numpy as np
from mobee_drake.experiments.adaptive_space_figures import History, WriteSpaceFigures
from mobee_drake.experiments.arms import Arms
from mobee_drake.scenario import LoadScenario, RunScenario
folder = pathlib.Path(sys.argv[1])
RunScenario(LoadScenario(sys.argv[2], "{duration: 0.1}"), record=str(folder / "run.html"))
history = History("icub, rank3", Arms()["icub"], np.full((2, 4), 0.5) + [[0], [0.1]], [])
WriteSpaceFigures({"icub": [history]}, folder, "space")
collector = threading.Thread(target=gc.collect)
collector.start()
collector.join()
print("survived")
"""


class TestMeshcatThreads(unittest.TestCase):
    def test_a_meshcat_made_for_a_while_is_gone_before_another_thread_collects(self):
        """RunScenario's own recording Meshcat and the figures' scenes are destroyed on the
        thread that made them, before their functions return (the figures' by
        ``ReleaseMeshcats``)."""
        with tempfile.TemporaryDirectory() as folder:
            done = subprocess.run(
                [sys.executable, "-c", _MESHCAT_THREADS, folder, str(REACH)],
                capture_output=True,
                text=True,
                timeout=300,
            )
            self.assertEqual(done.returncode, 0, done.stderr[-600:])
            self.assertEqual(done.stdout.split()[-1], "survived")
            self.assertTrue((pathlib.Path(folder) / "space_icub.html").is_file())


class TestLightMeshes(unittest.TestCase):
    def test_each_light_mesh_keeps_a_tenth_of_its_triangles_or_is_small(self):
        light, full = (PreparedIcubModel(DEFAULT_ICUB_MODEL, m) for m in ("light", "full"))
        light_meshes = re.findall(r'filename="([^"]+)"', light.read_text())
        full_meshes = re.findall(r'filename="([^"]+)"', full.read_text())
        self.assertEqual(len(light_meshes), len(full_meshes))
        for a, b in zip(light_meshes, full_meshes):
            n_light = len(trimesh.load(a, force="mesh").faces)
            n_full = len(trimesh.load(b, force="mesh").faces)
            if n_full <= LIGHT_MESH_FLOOR:
                self.assertEqual(n_light, n_full, a)
            else:
                self.assertLessEqual(n_light, max(LIGHT_MESH_SHARE * n_full, LIGHT_MESH_FLOOR))
                self.assertGreater(n_light, 0.5 * LIGHT_MESH_SHARE * n_full)

    def test_an_unknown_resolution_is_refused_by_name(self):
        with self.assertRaisesRegex(ValueError, "meshes: 'medium' is not one of"):
            PreparedIcubModel(DEFAULT_ICUB_MODEL, "medium")


if __name__ == "__main__":
    unittest.main()
