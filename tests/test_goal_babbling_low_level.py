"""Memory, nearest neighbours, local Jacobians and the local inverse model on the arm (Sec. III-B to
III-D).
"""

import math
import unittest

import numpy as np

from mobee_drake.goal_babbling.config import ArmConfig, Experiment1Config
from mobee_drake.goal_babbling.low_level import (
    DesiredDisplacements,
    PseudoInverseSolve,
    ReachingJointSteps,
    SensorimotorMemory,
)
from mobee_drake.goal_babbling.planar_arm import ForwardKinematics, LinkLengths
from mobee_drake.goal_babbling.sagg_riac import SaggRiac


def TrueJacobian(angles, lengths, step=1e-6):
    """Central finite differences of the forward kinematics."""
    columns = []
    for joint in range(len(angles)):
        offset = np.zeros(len(angles))
        offset[joint] = step
        columns.append(
            (
                ForwardKinematics(angles + offset, lengths)
                - ForwardKinematics(angles - offset, lengths)
            )
            / (2 * step)
        )
    return np.array(columns).T


class TestPseudoInverse(unittest.TestCase):
    def test_matches_moore_penrose(self):
        rng = np.random.default_rng(0)
        tall, rhs = rng.normal(size=(6, 30, 15)) * 0.01, rng.normal(size=(6, 30, 2))
        expected = np.linalg.pinv(tall) @ rhs
        np.testing.assert_allclose(
            PseudoInverseSolve(tall, rhs), expected, rtol=1e-5, atol=1e-8 * abs(expected).max()
        )
        wide, rhs = rng.normal(size=(6, 2, 15)), rng.normal(size=(6, 2, 1))
        np.testing.assert_allclose(
            PseudoInverseSolve(wide, rhs), np.linalg.pinv(wide) @ rhs, atol=1e-8
        )

    def test_rank_deficient_gives_the_minimum_norm_solution(self):
        rng = np.random.default_rng(1)
        low_rank = rng.normal(size=(3, 30, 2)) @ rng.normal(size=(3, 2, 15))
        rhs = rng.normal(size=(3, 30, 2))
        np.testing.assert_allclose(
            PseudoInverseSolve(low_rank, rhs), np.linalg.pinv(low_rank) @ rhs, atol=1e-6
        )


class TestMemory(unittest.TestCase):
    def test_neighbours_are_exact_across_tree_rebuilds(self):
        rng = np.random.default_rng(2)
        memory = SensorimotorMemory(15, 5000)
        for size in (1, 7, 300, 1100, 4000):
            while memory.size < size:
                memory.Add(rng.normal(size=15), np.zeros(2), np.zeros(15), np.zeros(2))
            queries = rng.normal(size=(5, 15))
            indices, distances = memory.Neighbours(queries, 20)
            brute = ((memory.joint_angles[:size][None] - queries[:, None]) ** 2).sum(axis=2)
            expected = np.sort(np.argsort(brute, axis=1)[:, : min(20, size)], axis=1)
            np.testing.assert_array_equal(indices, expected)
            np.testing.assert_allclose(distances, np.take_along_axis(brute, indices, axis=1))
            snapshot_indices, _ = memory.Snapshot().Neighbours(queries, 20)
            np.testing.assert_array_equal(snapshot_indices, indices)

    def test_jacobian_of_linear_data_is_exact(self):
        rng = np.random.default_rng(3)
        jacobian = rng.normal(size=(2, 15))
        memory = SensorimotorMemory(15, 100)
        for _ in range(100):
            step = rng.uniform(-0.01, 0.01, 15)
            memory.Add(rng.normal(size=15) * 0.1, np.zeros(2), step, jacobian @ step)
        estimated, _, _ = memory.EstimateJacobians(np.zeros((2, 15)), 30)
        np.testing.assert_allclose(estimated, np.broadcast_to(jacobian, (2, 2, 15)), atol=1e-6)

    def test_local_jacobian_and_forward_model_on_the_arm(self):
        config = ArmConfig()
        lengths = LinkLengths(config)
        rng = np.random.default_rng(4)
        pose = rng.uniform(-0.3, 0.3, 15)
        memory = SensorimotorMemory(15, 40)
        angles = pose.copy()
        for _ in range(40):  # a short exploration phase around the pose
            step = rng.uniform(-0.01, 0.01, 15)
            before = ForwardKinematics(angles, lengths)
            memory.Add(angles, before, step, ForwardKinematics(angles + step, lengths) - before)
            angles = angles + step
        estimated, _, _ = memory.EstimateJacobians(pose[None], 30)
        true = TrueJacobian(pose, lengths)
        self.assertLess(np.linalg.norm(estimated[0] - true) / np.linalg.norm(true), 0.2)
        query = pose + rng.uniform(-0.02, 0.02, 15)
        predicted = memory.PredictPositions(query[None], 30)[0]
        nearest_only = memory.positions[np.argmin(((memory.joint_angles - query) ** 2).sum(axis=1))]
        error = np.linalg.norm(predicted - ForwardKinematics(query, lengths))
        self.assertLess(
            error, 0.5 * np.linalg.norm(nearest_only - ForwardKinematics(query, lengths))
        )


class TestReachingSteps(unittest.TestCase):
    def test_desired_displacement(self):
        desired = DesiredDisplacements(
            np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]),
            np.array([[3.0, 4.0], [1.2, 1.0], [2.0, 2.0]]),
            0.5,
        )
        np.testing.assert_allclose(desired, [[0.3, 0.4], [0.2, 0.0], [0.0, 0.0]], atol=1e-12)

    def test_joint_steps_realise_the_displacement_with_minimum_norm(self):
        rng = np.random.default_rng(5)
        jacobians, desired = rng.normal(size=(4, 2, 15)), rng.normal(size=(4, 2)) * 0.01
        steps = ReachingJointSteps(jacobians, desired, max_joint_step=10.0)
        np.testing.assert_allclose(np.einsum("mdn,mn->md", jacobians, steps), desired, atol=1e-10)
        # Minimum norm: the step lies in the row space of J.
        for jacobian, step in zip(jacobians, steps, strict=True):
            residual = step - jacobian.T @ np.linalg.lstsq(jacobian.T, step, rcond=None)[0]
            self.assertLess(np.linalg.norm(residual), 1e-10)
        clipped = ReachingJointSteps(jacobians, desired * 1e3, max_joint_step=0.05)
        np.testing.assert_allclose(np.abs(clipped).max(axis=1), 0.05)
        unclipped = ReachingJointSteps(jacobians, desired * 1e3, max_joint_step=1e9)
        np.testing.assert_allclose(
            clipped / np.linalg.norm(clipped, axis=1, keepdims=True),
            unclipped / np.linalg.norm(unclipped, axis=1, keepdims=True),
        )


class TestLocalInverseModel(unittest.TestCase):
    def test_reaching_a_nearby_goal_reduces_the_error(self):
        config = Experiment1Config(seed=6, budget=2000)
        learner = SaggRiac(config)
        rng = np.random.default_rng(6)
        learner.arm.joint_angles = rng.uniform(-0.2, 0.2, 15)
        learner.arm.position = ForwardKinematics(learner.arm.joint_angles, learner.arm.link_lengths)
        learner.Explore()
        learner.Explore()
        for _ in range(5):
            # Goals 3 units away, inwards or sideways (a near-straight arm cannot go outwards).
            start = learner.arm.position.copy()
            angle = math.atan2(-start[1], -start[0]) + rng.uniform(-math.pi / 2, math.pi / 2)
            goal = start + 3.0 * np.array([math.cos(angle), math.sin(angle)])
            competence = learner.ReachGoal(goal)
            final_error = np.linalg.norm(learner.arm.position - goal)
            self.assertLess(final_error, 0.3, f"from 3.0 to {final_error:.3f}")
            self.assertAlmostEqual(
                competence, 0.0 if final_error <= 0.05 * 3.0 else -final_error / 3.0
            )


if __name__ == "__main__":
    unittest.main()
