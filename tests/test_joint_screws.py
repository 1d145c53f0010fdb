"""The joints' screws give every point Jacobian MoBeE uses: checked against Drake's own."""

import unittest

import numpy as np
from pydrake.multibody.tree import BodyIndex, JacobianWrtVariable

from mobee_drake.experiments.bench_forces import BuildPosedScene
from mobee_drake.mobee.joint_screws import JointScrews
from mobee_drake.robots.icub import IcubConfig
from mobee_drake.robots.zero_position import ZeroPositionConfig


class JointScrewsTest(unittest.TestCase):
    def Check(self, robot_config, expected_leaves: int):
        scene = BuildPosedScene(robot_config, [])
        plant, mobee = scene.plant, scene.mobee
        _, plant_context, _ = scene.Contexts()
        velocity_map = mobee._to_joints
        dut = JointScrews(plant, velocity_map)
        self.assertEqual(len(dut._leaf_frames), expected_leaves)
        # Every body but the world (the scene has nothing but the robot).
        bodies = [plant.get_body(BodyIndex(i)) for i in range(1, plant.num_bodies())]
        indices = np.array([int(b.index()) for b in bodies])
        world = plant.world_frame()
        rng = np.random.default_rng(7)
        for _ in range(5):
            q_min, q_max = mobee.position_limits
            x = plant.GetPositions(plant_context)
            x[scene.PositionOrder()] = rng.uniform(q_min, q_max)
            plant.SetPositions(plant_context, x)
            screws = dut.Calc(plant_context)
            points = rng.normal(size=(len(bodies), 3))
            jacobians = dut.Jacobians(screws, dut.Moves(indices), points)
            for body, p_WP, J in zip(bodies, points, jacobians):
                p_BP = body.EvalPoseInWorld(plant_context).inverse().multiply(p_WP)
                expected = (
                    plant.CalcJacobianTranslationalVelocity(
                        plant_context, JacobianWrtVariable.kV, body.body_frame(), p_BP, world, world
                    )
                    @ velocity_map
                )
                np.testing.assert_allclose(J, expected, atol=1e-12, err_msg=body.name())
            # A direction's projection is n . J; with the difference of two bodies' motions it
            # is the relative motion of two points on one line along n.
            directions = rng.normal(size=(len(bodies), 3))
            moves = dut.Moves(indices)
            np.testing.assert_allclose(
                dut.Project(screws, moves, points, directions),
                np.einsum("ki,kij->kj", directions, jacobians),
                atol=1e-12,
            )
            other = rng.permutation(len(bodies))
            offsets = rng.normal(size=(len(bodies), 1)) * directions
            relative = dut.Project(screws, moves - moves[other], points, directions)
            expected = np.einsum("ki,kij->kj", directions, jacobians) - np.einsum(
                "ki,kij->kj",
                directions,
                dut.Jacobians(screws, dut.Moves(indices[other]), points - offsets),
            )
            np.testing.assert_allclose(relative, expected, atol=1e-12)

    def test_icub(self):
        # Torso and arms: the right hand, the left hand and the head end the three chains.
        self.Check(IcubConfig(), expected_leaves=3)

    def test_katana_with_its_gripper_follower(self):
        # The gripper motor drives two finger joints (one follows): two chains.
        self.Check(ZeroPositionConfig(), expected_leaves=2)


if __name__ == "__main__":
    unittest.main()
