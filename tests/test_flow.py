"""The obstacle-aware flow (mobee/flow.py) against its closed forms."""

import unittest

import numpy as np

from mobee_drake.mobee.flow import ModulatedFlow

CLEARANCE = 0.005
MARGIN = 0.03


def Proximity(distance: float) -> float:
    return (MARGIN - distance) / (MARGIN - CLEARANCE)


class TestModulatedFlow(unittest.TestCase):
    def setUp(self):
        self.rng = np.random.default_rng(3)

    def Flow(self, force, normals, distances):
        normals = np.atleast_2d(normals)
        distances = np.atleast_1d(np.asarray(distances, dtype=float))
        return ModulatedFlow(
            np.asarray(force, dtype=float),
            normals,
            distances,
            np.full(len(distances), MARGIN),
            CLEARANCE,
        )

    def test_free_space_is_the_flow_itself(self):
        force = self.rng.normal(size=7)
        np.testing.assert_array_equal(self.Flow(force, np.zeros((0, 7)), []), force)
        # A pair at its field's edge (proximity 0) changes nothing either.
        np.testing.assert_array_equal(self.Flow(force, -force, MARGIN), force)

    def test_closed_form_for_one_pair(self):
        n = np.array([0.0, 2.0, 0.0])  # generalized normals need not be unit
        force = np.array([1.0, -3.0, 0.5])  # into the pair: f . n < 0
        d = 0.0175  # proximity 0.5
        w = Proximity(d)
        self.assertAlmostEqual(w, 0.5)
        normal, tangent = np.array([0.0, -3.0, 0.0]), np.array([1.0, 0.0, 0.5])
        turned = (1 - w) * normal + (1 + w) * tangent
        expected = turned * np.linalg.norm(force) / np.linalg.norm(turned)
        np.testing.assert_allclose(self.Flow(force, n, d), expected)

    def test_tangent_at_the_clearance_and_never_more_into_the_pair(self):
        for _ in range(200):
            n = self.rng.normal(size=6)
            force = self.rng.normal(size=6)
            d = self.rng.uniform(-0.01, MARGIN)
            flow = self.Flow(force, n, d)
            into_before, into_after = force @ n, flow @ n
            if into_before >= 0:  # away from the pair: untouched
                np.testing.assert_array_equal(flow, force)
                continue
            self.assertLessEqual(abs(into_after), abs(into_before) + 1e-12)
            self.assertLessEqual(into_after, 1e-12)  # never turned into a push away either
            if d <= CLEARANCE:  # on (or within) the clearance: tangent to the obstacle
                self.assertAlmostEqual(into_after, 0.0, places=12)
            # Turned, not strengthened: its length is kept, its part along the surface keeps
            # its direction and never shrinks.
            self.assertAlmostEqual(np.linalg.norm(flow), np.linalg.norm(force), places=12)
            tangent_before = force - into_before / (n @ n) * n
            tangent_after = flow - into_after / (n @ n) * n
            scale = (tangent_after @ tangent_before) / (tangent_before @ tangent_before)
            np.testing.assert_allclose(tangent_after, scale * tangent_before, atol=1e-12)
            self.assertGreaterEqual(scale, 1.0 - 1e-12)

    def test_a_pull_straight_into_a_pair_at_its_clearance_is_stopped(self):
        n = np.array([0.0, 1.0])
        np.testing.assert_array_equal(self.Flow([0.0, -2.0], n, CLEARANCE), [0.0, 0.0])

    def test_the_nearest_pair_is_followed_last(self):
        # Two pairs with orthogonal normals, the farther at proximity 0.4, the nearer at the
        # clearance: the farther's modulation first, then the nearer's, which ends tangent.
        force = np.array([-1.0, -1.0, 0.2])
        normals = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
        flow = self.Flow(force, normals, [0.02, CLEARANCE])
        after_farther = np.array([0.6 * -1.0, 1.4 * -1.0, 1.4 * 0.2])
        turned = 2.0 * after_farther * [1.0, 0.0, 1.0]
        np.testing.assert_allclose(flow, turned * np.linalg.norm(force) / np.linalg.norm(turned))
        self.assertAlmostEqual(flow @ normals[1], 0.0, places=12)


if __name__ == "__main__":
    unittest.main()
