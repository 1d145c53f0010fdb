"""MoBeE's safety guarantee (mobee/barrier.py): closed forms of the barrier force, the parameters
that would break the guarantee refused, and saturated client pushes into a table, a ball and the
robot itself that penetrate without the barrier and never with it, on both robots."""

import re
import unittest

import numpy as np

from mobee_drake.experiments.bench_safety import SCENES, PushedRun, SceneRun
from mobee_drake.mobee.barrier import BarrierForce, BarrierParams, StepModel
from mobee_drake.mobee.params import MobeeParams
from mobee_drake.scenario import LoadScenario

PARAMS = BarrierParams(rate=0.2, clearance=0.005)


class TestBarrierForce(unittest.TestCase):
    def test_a_gap_closing_too_fast_is_held_at_the_rate_with_the_least_force(self):
        """One pair: the closing speed is cut to the allowed one, by the change of least
        M^-1-norm (along M S n)."""
        n = np.array([[1.0, 0.5]])
        mass, gain, h, d = np.array([1.0, 4.0]), np.array([0.01, 0.01]), 0.01, 0.015
        total = np.array([-30.0, -20.0])
        dT = BarrierForce(n, np.array([d]), np.zeros(2), total, mass, gain, h, PARAMS)
        allowed = -PARAMS.rate * (d - PARAMS.clearance) / h
        self.assertAlmostEqual((n @ (gain * (total + dT)))[0], allowed)
        direction = mass * gain * n[0]
        self.assertAlmostEqual(dT[0] * direction[1] - dT[1] * direction[0], 0.0)  # parallel
        self.assertGreater(dT @ direction, 0)

    def test_no_force_while_the_gap_closes_slowly_enough(self):
        """Allowed: -0.2 (0.02 - 0.005) / 0.01 = -0.3 m/s; the pair closes at 0.2 m/s (and at
        0.4 m/s it would not be allowed)."""
        n = np.array([[1.0, 0.0]])
        for speed, free in ((-0.2, True), (-0.4, False)):
            dT = BarrierForce(
                n, np.array([0.02]), np.array([speed, 0.0]), np.zeros(2), np.ones(2),
                np.full(2, 0.01), 0.01, PARAMS,
            )  # fmt: skip
            self.assertEqual(bool(np.all(dT == 0.0)), free)

    def test_a_pair_the_joints_cannot_move_is_left_out(self):
        n = np.zeros((1, 2))
        dT = BarrierForce(
            n, np.array([-0.01]), np.zeros(2), np.ones(2), np.ones(2), np.ones(2), 0.01, PARAMS
        )
        np.testing.assert_array_equal(dT, 0.0)

    def test_two_barriers_are_met_together(self):
        n = np.array([[1.0, 0.0], [0.0, 1.0]])
        gain, h = np.full(2, 0.01), 0.01
        total = np.array([-50.0, -50.0])
        d = np.array([0.006, 0.010])
        dT = BarrierForce(n, d, np.zeros(2), total, np.ones(2), gain, h, PARAMS)
        closing = n @ (gain * (total + dT))
        np.testing.assert_allclose(closing, -PARAMS.rate * (d - PARAMS.clearance) / h)

    def test_pinched_solids_get_the_least_squares_change(self):
        """Two barriers that ask for opposite motions of one joint cannot both hold."""
        n = np.array([[1.0], [-1.0]])
        dT = BarrierForce(
            n, np.array([-0.01, -0.01]), np.zeros(1), np.zeros(1), np.ones(1), np.ones(1), 0.01,
            PARAMS,
        )  # fmt: skip
        np.testing.assert_allclose(dT, 0.0, atol=1e-9)

    def test_the_step_models(self):
        """S of ``v+ = v + S T``: the implicit damping of the virtual dynamics, or explicit."""
        mass, damping, h = np.array([1.0, 2.0]), np.array([50.0, 10.0]), 0.02
        np.testing.assert_allclose(
            StepModel(h).Gain(mass, damping), h / mass / (1 + h * damping / mass)
        )
        np.testing.assert_allclose(
            StepModel(h, implicit_damping=False).Gain(mass, damping), h / mass
        )


class TestBarrierParameters(unittest.TestCase):
    def test_values_that_would_break_the_guarantee_are_refused(self):
        joints = ["a"]
        for params, words in (
            (MobeeParams(barrier=BarrierParams(rate=1.0)), "barrier rate must be in (0, 1)"),
            (MobeeParams(barrier=BarrierParams(rate=0.0)), "barrier rate must be in (0, 1)"),
            (MobeeParams(barrier=BarrierParams(clearance=0.0)), "barrier clearance"),
            (MobeeParams(damping=0.0), "damping must be > 0 while the safety barrier is on"),
        ):
            with self.subTest(words), self.assertRaisesRegex(ValueError, re.escape(words)):
                params.Validate(joints)
        MobeeParams(damping=0.0, barrier=BarrierParams(enabled=False)).Validate(joints)


class TestSaturatedPushes(unittest.TestCase):
    """c = f = 1000 on the palm, with the attractor: into a table, a ball, the robot's body."""

    def _Check(self, scene, mover, preset="defaults"):
        summary = SceneRun(scene, mover, seconds=2.0, preset=preset)
        safety = summary.safety
        self.assertEqual(safety.penetrating_steps, 0, (scene.name, mover))
        closest = safety.closest_approach[scene.obstacle]
        self.assertIsNotNone(closest)  # the push reached the obstacle's field
        self.assertGreater(closest, 0.0)

    def test_without_the_barrier_the_pushes_penetrate(self):
        # With the dissertation's maxima the client forces (60) beat the fields' (40); with the
        # defaults' (80) the table is still entered by a few mm (docs/mobee.md).
        for scene in SCENES[:2]:
            with self.subTest(scene.name):
                safety = SceneRun(
                    scene, "kinematic", barrier=False, seconds=2.0, preset="dissertation"
                ).safety
                self.assertGreater(safety.deepest_penetration, 0.01)
        safety = SceneRun(SCENES[0], "kinematic", barrier=False, seconds=2.0).safety
        self.assertGreater(safety.deepest_penetration, 0.0)

    def test_the_kinematic_robot_never_penetrates(self):
        for scene in SCENES:
            with self.subTest(scene.name):
                self._Check(scene, "kinematic")

    def test_babbling_with_random_saturated_pushes(self):
        """The benchmark's second part, short: random attractors above a table, the push's
        direction redrawn every second."""
        scenario = LoadScenario("motor_babbling", "{duration: 6.0, data_log: {enabled: false}}")
        summary = PushedRun(scenario, marker="r_palm", direction=(0, 0, -1), every=1.0)
        self.assertEqual(summary.safety.penetrating_steps, 0)

    def test_the_dynamic_robot_never_penetrates_in_any_modality(self):
        # At the dissertation's speeds (0.4-1.2 rad/s); at the defaults' (up to 3 rad/s under
        # saturated pushes) the plant's tracking lag let the hand overshoot by up to 0.4 mm in
        # the position and velocity modes (docs/mobee.md, "The safety guarantee", condition 3).
        table, ball, own_body = SCENES
        for scene, mover in ((table, "position"), (ball, "velocity"), (own_body, "force")):
            with self.subTest(f"{scene.name}, {mover}"):
                self._Check(scene, mover, preset="dissertation")
        self._Check(own_body, "force")  # the force mode has no virtual trajectory to lag


if __name__ == "__main__":
    unittest.main()
