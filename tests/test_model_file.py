"""A robot of one's own from a URDF file and its overlay, and obstacles from mesh files, in a
scenario (robots/model_file.py, world/objects.py's Mesh)."""

import contextlib
import pathlib
import shutil
import tempfile
import unittest

import numpy as np
from pydrake.geometry import Rgba, SceneGraph
from pydrake.multibody.plant import MultibodyPlant

from mobee_drake.resources import ModelsDirectory
from mobee_drake.robots.model_file import ModelFileConfig
from mobee_drake.robots.scenario_robot import AddGhostRobot
from mobee_drake.scenario import BuildScenario, LoadScenario, ScenarioDoubts
from mobee_drake.station.runner import RunStation
from mobee_drake.yaml_io import YamlFileError

# A cube 0.2 m on a side, centred on its origin.
CUBE_OBJ = "\n".join(
    [f"v {x} {y} {z}" for x in (-0.1, 0.1) for y in (-0.1, 0.1) for z in (-0.1, 0.1)]
    + [f"f {a} {b} {c}" for a, b, c in [(1, 2, 4), (1, 4, 3), (5, 7, 8), (5, 8, 6), (1, 5, 6),
                                        (1, 6, 2), (3, 4, 8), (3, 8, 7), (1, 3, 7), (1, 7, 5),
                                        (2, 6, 8), (2, 8, 4)]]
)  # fmt: skip

ARM = """
robot: !ModelFileConfig {{file: {file}, overlay: {overlay}}}
objects:
  - {{name: block, shape: {shape}, position: [0.45, 0.35, 0.0]}}
attractor: !FixedAttractor {{joints_deg: {{joint1: 60}}}}
time_step: 0.01
duration: 3.0
visualization: {{trail_marker: tip}}
"""


class TestOwnRobot(unittest.TestCase):
    def setUp(self):
        self.folder = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, self.folder)
        for name in ("three_link_arm.urdf", "three_link_arm_overlay.yaml"):
            shutil.copy(ModelsDirectory() / name, self.folder / name)
        (self.folder / "cube.obj").write_text(CUBE_OBJ)

    def _Scenario(self, shape: str, **files) -> pathlib.Path:
        files = {"file": "three_link_arm.urdf", "overlay": "three_link_arm_overlay.yaml", **files}
        path = self.folder / "arm.yaml"
        path.write_text(ARM.format(shape=shape, **files))
        return path

    def _Closest(self, shape: str) -> float:
        """The arm's closest approach to the block while joint1 swings it towards the block."""
        with contextlib.chdir(tempfile.gettempdir()):  # the files are found beside the scenario
            station = BuildScenario(LoadScenario(self._Scenario(shape)))
        summary = RunStation(station, 3.0)
        self.assertEqual(summary.safety.penetrating_steps, 0)
        return summary.safety.closest_approach["block"]

    def test_relative_files_are_found_beside_the_scenario(self):
        scenario = LoadScenario(self._Scenario("!Sphere {radius: 0.05}"))
        self.assertEqual(scenario.robot.file, str(self.folder / "three_link_arm.urdf"))
        station = BuildScenario(scenario)
        self.assertEqual(list(station.mobee.joints), ["joint1", "joint2", "joint3"])

    def test_a_mesh_obstacle_is_seen_as_its_convex_hull(self):
        """The arm swings into a cube read from an OBJ file exactly as into the same box:
        MoBeE holds it off by the same closest approach, within the field."""
        mesh = self._Closest("!Mesh {file: cube.obj}")
        box = self._Closest("!Box {size: [0.2, 0.2, 0.2]}")
        self.assertGreater(mesh, 0.0)
        self.assertLess(mesh, 0.05)  # inside the arm's field: MoBeE had to act
        self.assertAlmostEqual(mesh, box, delta=1e-6)

    def test_a_moved_mesh_survives_a_snapshot(self):
        """The live world's snapshot (what a checkpoint saves) keeps a mesh's file and scale
        across a move, and restores them into a fresh context."""
        station = BuildScenario(LoadScenario(self._Scenario("!Mesh {file: cube.obj, scale: 0.5}")))
        world, context = station.world, station.diagram.CreateDefaultContext()
        world.Move(context, "block", [0.5, -0.3, 0.0])
        snapshot = world.Snapshot(context)
        (block,) = [o for o in snapshot if o["name"] == "block"]
        self.assertEqual(block["shape"], {"convex": [str(self.folder / "cube.obj"), 0.5]})
        fresh = station.diagram.CreateDefaultContext()
        world.Restore(fresh, snapshot)
        self.assertEqual(world.Snapshot(fresh), snapshot)

    def test_a_mesh_in_millimetres_is_doubted(self):
        scenario = LoadScenario(self._Scenario("!Mesh {file: cube.obj, scale: 1000}"))
        (doubt,) = ScenarioDoubts(scenario)
        self.assertIn("objects 'block': extent 200 m", doubt)
        self.assertIn("scale", doubt)

    def test_missing_files_are_named(self):
        for files, message in [
            ({"file": "package://nowhere/arm.urdf"}, "robot file: package://nowhere/arm.urdf: "
             "unknown package 'nowhere'"),
            ({"overlay": "missing.yaml"}, "robot overlay: .*missing.yaml: no such file"),
        ]:  # fmt: skip
            with self.subTest(files), self.assertRaisesRegex(YamlFileError, message):
                LoadScenario(self._Scenario("!Sphere {radius: 0.05}", **files))
        with self.assertRaisesRegex(YamlFileError, "object 'block': mesh file .*nothing.obj"):
            LoadScenario(self._Scenario("!Mesh {file: nothing.obj}"))


class TestGhost(unittest.TestCase):
    def test_the_ghost_keeps_the_models_colours_translucent(self):
        scene_graph = SceneGraph()
        plant = MultibodyPlant(0.0)
        plant.RegisterAsSourceForSceneGraph(scene_graph)
        instance, home = AddGhostRobot(plant, scene_graph, ModelFileConfig(), alpha=0.3)
        plant.Finalize()
        inspector = scene_graph.model_inspector()
        colours = {}
        for index in plant.GetBodyIndices(instance):
            body = plant.get_body(index)
            for geometry in plant.GetVisualGeometriesForBody(body):
                properties = inspector.GetIllustrationProperties(geometry)
                colours[body.name()] = properties.GetProperty("phong", "diffuse")
        self.assertEqual(set(colours), {"base", "link1", "link2", "link3"})
        link3 = colours["link3"]  # the URDF's orange, at the ghost's opacity
        np.testing.assert_allclose(
            [link3.r(), link3.g(), link3.b(), link3.a()], [0.9, 0.6, 0.2, 0.3]
        )
        self.assertTrue(all(isinstance(c, Rgba) and c.a() == 0.3 for c in colours.values()))
        self.assertEqual(plant.num_positions(), 3)  # the base welded, the joints free
        self.assertEqual(home, {})


if __name__ == "__main__":
    unittest.main()
