"""The scalar force laws of MoBeE 2.0 against the dissertation's figures (Fig. 5.2, Fig. 5.3)."""

import unittest

import numpy as np

from mobee_drake.mobee.joint_limits import JointLimitForce
from mobee_drake.mobee.squash import Squash


class TestSquash(unittest.TestCase):
    """Fig. 5.2: L(v) = m v / (m/k + |v|) with m = 2, k = 3."""

    m, k = 2.0, 3.0

    def test_zero_and_slope_at_zero(self):
        self.assertEqual(Squash(np.array([0.0]), self.m, self.k)[0], 0.0)
        h = 1e-7
        slope = (Squash(np.array([h]), self.m, self.k) - Squash(np.array([-h]), self.m, self.k)) / (
            2 * h
        )
        np.testing.assert_allclose(slope, self.k, rtol=1e-6)

    def test_limit_is_m_and_odd_and_increasing(self):
        v = np.linspace(-1e6, 1e6, 20001)
        L = Squash(v, self.m, self.k)
        np.testing.assert_allclose(
            Squash(np.array([1e9, -1e9]), self.m, self.k), [2.0, -2.0], rtol=1e-8
        )
        self.assertTrue(np.all(np.abs(L) < self.m))
        np.testing.assert_allclose(L, -Squash(-v, self.m, self.k))
        self.assertTrue(np.all(np.diff(L) > 0))

    def test_closed_form_values(self):
        # At |v| = m/k the function reaches half its maximum.
        np.testing.assert_allclose(Squash(np.array([2 / 3, -2 / 3]), self.m, self.k), [1.0, -1.0])

    def test_per_dimension_parameters(self):
        v = np.array([1.0, 1.0])
        np.testing.assert_allclose(
            Squash(v, np.array([1.0, 10.0]), np.array([1.0, 1.0])), [1 / 2, 10 / 11]
        )


class TestJointLimitForce(unittest.TestCase):
    """Fig. 5.3: limits -3..3, delta = 1, f_max = 1."""

    def f(self, q):
        return JointLimitForce(np.asarray(q, dtype=float), -3.0, 3.0, 1.0, 1.0)

    def test_values_of_the_figure(self):
        np.testing.assert_allclose(self.f([-3.0, 3.0]), [1.0, -1.0])
        np.testing.assert_allclose(self.f(np.linspace(-2, 2, 41)), 0.0)
        np.testing.assert_allclose(self.f([-2.5, 2.5]), [0.5, -0.5])

    def test_continuous_and_linear_ramps(self):
        q = np.linspace(-4, 4, 8001)
        f = self.f(q)
        self.assertLess(np.max(np.abs(np.diff(f))), 2e-3)  # No jumps on a 1e-3 grid.
        ramp = q <= -2
        np.testing.assert_allclose(f[ramp], -(q[ramp] + 2.0))  # slope -f_max/delta
        ramp = q >= 2
        np.testing.assert_allclose(f[ramp], -(q[ramp] - 2.0))

    def test_pushes_back_inside_beyond_the_limits(self):
        np.testing.assert_allclose(self.f([-3.5, 3.5]), [1.5, -1.5])


if __name__ == "__main__":
    unittest.main()
