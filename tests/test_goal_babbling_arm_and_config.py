"""The planar arm's forward kinematics against closed forms, and the configuration's round trip."""

import json
import math
import unittest

import numpy as np

from mobee_drake.goal_babbling.config import (
    ArmConfig,
    ConfigFromDict,
    ConfigToDict,
    Experiment1Config,
    Experiment2Config,
    GoalBabblingConfig,
)
from mobee_drake.goal_babbling.planar_arm import ForwardKinematics, LinkLengths, PlanarArm


class TestForwardKinematics(unittest.TestCase):
    """15 equal links of total length 50, relative joint angles."""

    def setUp(self):
        self.lengths = LinkLengths(ArmConfig())

    def tip(self, angles):
        return ForwardKinematics(np.asarray(angles, dtype=float), self.lengths)

    def test_straight_rest_reaches_total_length(self):
        np.testing.assert_allclose(self.tip(np.zeros(15)), [50.0, 0.0], atol=1e-12)

    def test_rotating_the_base_turns_the_straight_arm(self):
        for angle in (math.pi / 2, -math.pi / 3, 2.0):
            angles = np.zeros(15)
            angles[0] = angle
            np.testing.assert_allclose(
                self.tip(angles), [50 * math.cos(angle), 50 * math.sin(angle)], atol=1e-12
            )

    def test_folding_a_joint_back(self):
        # Joint j turned by pi: links 0..j-1 forward, links j..14 backward, each of length 50/15.
        for joint in (7, 14):
            angles = np.zeros(15)
            angles[joint] = math.pi
            np.testing.assert_allclose(
                self.tip(angles), [(joint - (15 - joint)) * 50 / 15, 0.0], atol=1e-12
            )

    def test_closed_polygon_returns_to_the_base(self):
        # Equal turns of 2 pi / 15 make a regular 15-gon: the tip is back at the origin.
        np.testing.assert_allclose(self.tip(np.full(15, 2 * math.pi / 15)), [0.0, 0.0], atol=1e-12)

    def test_batches_and_reach_bound(self):
        rng = np.random.default_rng(0)
        angles = rng.uniform(-math.pi, math.pi, (4, 3, 15))
        tips = self.tip(angles)
        self.assertEqual(tips.shape, (4, 3, 2))
        np.testing.assert_allclose(tips[2, 1], self.tip(angles[2, 1]))
        self.assertTrue(np.all(np.linalg.norm(tips, axis=-1) <= 50 + 1e-9))


class TestPlanarArm(unittest.TestCase):
    def test_move_clips_to_limits_and_reset(self):
        arm = PlanarArm(ArmConfig(joint_limit=0.5), np.random.default_rng(0))
        np.testing.assert_allclose(arm.position, [50, 0], atol=1e-12)
        step = np.full(15, 0.2)
        step[3] = 0.9
        performed = arm.Move(step)
        self.assertAlmostEqual(performed[3], 0.5)
        np.testing.assert_allclose(np.delete(performed, 3), 0.2)
        np.testing.assert_allclose(
            arm.position, ForwardKinematics(arm.joint_angles, arm.link_lengths)
        )
        arm.Reset()
        np.testing.assert_allclose(arm.joint_angles, 0.0)
        np.testing.assert_allclose(arm.position, [50, 0], atol=1e-12)

    def test_sensor_noise_has_the_configured_spread(self):
        arm = PlanarArm(ArmConfig(sensor_noise_std=0.3), np.random.default_rng(1))
        samples = []
        for _ in range(2000):
            arm.Reset()
            samples.append(arm.position)
        errors = np.array(samples) - [50.0, 0.0]
        np.testing.assert_allclose(errors.std(axis=0), [0.3, 0.3], rtol=0.1)
        np.testing.assert_allclose(errors.mean(axis=0), [0.0, 0.0], atol=0.05)


class TestConfig(unittest.TestCase):
    def test_defaults_are_the_papers_values(self):
        config = GoalBabblingConfig()
        self.assertEqual((config.arm.num_joints, config.arm.total_length), (15, 50.0))
        self.assertEqual((config.num_subgoals, config.reset_every_attempts), (5, 2))
        self.assertEqual(config.interest.max_region_goals, 50)
        self.assertEqual(config.interest.mode_probabilities, [0.7, 0.2, 0.1])
        self.assertEqual(config.low_level.velocity, 0.5)
        first, second = Experiment1Config(), Experiment2Config()
        self.assertEqual(
            (first.goal_space_high, first.low_level.exploration_actions, first.budget),
            ([50.0, 50.0], 20, 50_000),
        )
        self.assertEqual(
            (second.goal_space_low, second.low_level.exploration_actions, second.budget),
            ([0.0, -150.0], 100, 200_000),
        )

    def test_round_trip(self):
        config = Experiment2Config(seed=7, budget=1234)
        config.interest.mode_probabilities = [0.5, 0.3, 0.2]
        config.arm.sensor_noise_std = 0.1
        restored = ConfigFromDict(json.loads(json.dumps(ConfigToDict(config))))
        self.assertEqual(restored, config)
        self.assertIsInstance(restored.low_level.exploration_actions, int)

    def test_partial_and_unknown_fields(self):
        self.assertEqual(ConfigFromDict({"arm": {"num_joints": 3}}).arm, ArmConfig(num_joints=3))
        with self.assertRaisesRegex(RuntimeError, "joints"):
            ConfigFromDict({"arm": {"joints": 3}})

    def test_actuator_reset_period(self):
        # From rest (50, 0) to (0, 50): 50 sqrt 2; then to (0, -50): 100; at 0.5 per step.
        self.assertEqual(
            GoalBabblingConfig().ActuatorResetPeriod(), math.ceil((50 * math.sqrt(2) + 100) / 0.5)
        )


if __name__ == "__main__":
    unittest.main()
