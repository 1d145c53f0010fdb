"""The dense iCub overlay of issue 34: boxes fitted to slabs of each link's visual mesh."""

import importlib.util
import pathlib
import unittest

import numpy as np
from pydrake.math import RigidTransform, RollPitchYaw

from mobee_drake.ngik.kinematic_model import KinematicModel
from mobee_drake.resources import ResolveModelFile
from mobee_drake.robots.dense_overlay import LinkMeshVertices, SlabBoxes
from mobee_drake.robots.icub import DEFAULT_ICUB_MODEL, IcubConfig
from mobee_drake.robots.model_cache import PreparedIcubModel
from mobee_drake.robots.overlay import LoadOverlay, ZeroConfigurationPoses

ROOT = pathlib.Path(__file__).resolve().parents[1]


def _Inside(points: np.ndarray, boxes, tolerance: float) -> np.ndarray:
    """Which points lie in at least one of the boxes (grown by ``tolerance``)."""
    inside = np.zeros(len(points), dtype=bool)
    for box in boxes:
        X = RigidTransform(RollPitchYaw(np.radians(box.rpy_deg)), box.center)
        local = X.inverse().multiply(points.T).T
        inside |= np.all(np.abs(local) <= np.asarray(box.size) / 2 + tolerance, axis=1)
    return inside


class SlabBoxesTest(unittest.TestCase):
    def test_a_rotated_bar_is_cut_into_equal_slabs(self):
        # A 1 x 0.2 x 0.1 bar of points, turned 30 degrees about z and moved.
        rng = np.random.default_rng(0)
        local = rng.uniform([-0.5, -0.1, -0.05], [0.5, 0.1, 0.05], size=(4000, 3))
        X = RigidTransform(RollPitchYaw(0, 0, np.radians(30)), [1.0, 2.0, 3.0])
        points = X.multiply(local.T).T
        boxes = SlabBoxes(points, 4)
        self.assertEqual(len(boxes), 4)
        for box in boxes:
            np.testing.assert_allclose(sorted(box.size), [0.1, 0.2, 0.25], atol=0.01)
        # The centres lie on the bar's axis, a quarter apart.
        centres = np.array([box.center for box in boxes])
        along = (centres - X.translation()) @ X.rotation().col(0)
        np.testing.assert_allclose(sorted(along), [-0.375, -0.125, 0.125, 0.375], atol=0.01)
        self.assertTrue(np.all(_Inside(points, boxes, 1e-4)))


class DenseIcubOverlayTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dense = LoadOverlay(ResolveModelFile("icub_dense_overlay.yaml"))
        cls.base = LoadOverlay(ResolveModelFile("icub_overlay.yaml"))

    def test_the_shipped_file_is_the_generators(self):
        spec = importlib.util.spec_from_file_location(
            "make_dense_overlay", ROOT / "scripts" / "make_dense_overlay.py"
        )
        script = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(script)
        shipped = (ROOT / "models" / "icub_dense_overlay.yaml").read_text()
        self.assertEqual(script.DenseIcubOverlayText(), shipped)

    def test_boxes_hold_every_vertex_of_their_links_mesh(self):
        urdf = PreparedIcubModel(DEFAULT_ICUB_MODEL, "full")
        links = {p.link for p in self.base.primitives}
        self.assertEqual({p.link for p in self.dense.primitives}, links)
        self.assertGreaterEqual(len(self.dense.primitives), 120)
        meshes = LinkMeshVertices(urdf, links)
        from pydrake.multibody.parsing import Parser

        poses = ZeroConfigurationPoses(
            lambda plant: Parser(plant).AddModels(str(urdf))[0], "root_link"
        )
        for link in links:
            boxes = [p.shape for p in self.dense.primitives if p.link == link]
            points = poses[link].multiply(meshes[link].T).T
            # (The file rounds to 0.1 mm.)
            self.assertTrue(np.all(_Inside(points, boxes, 5e-4)), link)

    def test_a_links_boxes_never_meet_each_other_and_markers_stay(self):
        for link in {p.link for p in self.dense.primitives}:
            names = {p.name for p in self.dense.primitives if p.link == link}
            self.assertTrue(any(names <= set(group) for group in self.dense.exclude), link)
        self.assertEqual(self.dense.markers, self.base.markers)
        self.assertEqual(self.dense.clauses, self.base.clauses)

    def test_the_robot_at_home_touches_nothing(self):
        model = KinematicModel(IcubConfig(overlay="icub_dense_overlay.yaml"), [])
        self.assertEqual(model.Evaluate(model.home).collision_pairs, ())


if __name__ == "__main__":
    unittest.main()
