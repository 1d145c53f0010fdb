"""Joints that one motor drives (robots/couplings.py): MoBeE sees one degree of freedom, the
followers move with it, and MoBeE's forces act on the motor through the chain rule."""

import unittest

from arm_diagram import ArmDiagram
import numpy as np

from mobee_drake.robots.couplings import JointCoupling
from mobee_drake.scenario import BuildScenario, LoadScenario
from mobee_drake.station.world_events import MakeSimulator

# joint3 follows joint2: q3 = -0.5 q2 + 0.2.
COUPLING = JointCoupling(follower="joint3", leader="joint2", ratio=-0.5, offset=0.2)


class TestCoupledArm(unittest.TestCase):
    def setUp(self):
        self.arm = ArmDiagram(joints=["joint1", "joint2"], couplings=(COUPLING,))

    def _Tip(self, q):
        arm = self.arm
        arm.Set([q[0], q[1], -0.5 * q[1] + 0.2])
        return arm.Out("marker_positions")[:3].copy()

    def test_mobee_has_one_degree_of_freedom_per_motor(self):
        self.assertEqual(self.arm.dut.joints, ["joint1", "joint2"])
        self.assertEqual(self.arm.dut.GetInputPort("state").size(), 4)

    def test_the_follower_moves_with_its_leader(self):
        """MoBeE's own kinematics put joint3 where it follows, whatever the plant says."""
        q = np.array([0.3, 0.8])
        tip = self._Tip(q)
        self.arm.Set([q[0], q[1], 1.0])  # joint3 elsewhere in the plant: MoBeE ignores it
        np.testing.assert_allclose(self.arm.Out("marker_positions")[:3], tip)

    def test_jacobians_and_forces_follow_the_chain_rule(self):
        """The tip's Jacobian column of joint2 is d tip / d q2 with joint3 following (finite
        differences), so a workspace force acts on the motor as J^T f."""
        q, h = np.array([0.3, 0.8]), 1e-6
        J = np.empty((3, 2))
        for j in range(2):
            step = np.eye(2)[j] * h
            J[:, j] = (self._Tip(q + step) - self._Tip(q - step)) / (2 * h)
        self._Tip(q)
        np.testing.assert_allclose(
            self.arm.Out("marker_jacobians").reshape(2, 3, 2)[0], J, atol=1e-6
        )

    def test_a_follower_cannot_be_controlled_on_its_own(self):
        with self.assertRaisesRegex(ValueError, "joint 'joint3' follows 'joint2'"):
            ArmDiagram(joints=["joint1", "joint2", "joint3"], couplings=(COUPLING,))


class TestKatanaGripper(unittest.TestCase):
    def test_both_fingers_move_with_the_gripper_motor(self):
        """The Katana's gripper motor is one degree of freedom of MoBeE: pulled to a new angle,
        both finger joints move, each by its own share of the motor's interval (App. B)."""
        (finger,) = BuildScenario(LoadScenario("katana")).mobee.followers
        target_deg = 150.0
        scenario = LoadScenario(
            "katana",
            "{duration: 4.0, data_log: {enabled: false}, attractor: !FixedAttractor "
            f"{{joints_deg: {{{finger.leader}: {target_deg}}}}}}}",
        )
        station = BuildScenario(scenario)
        simulator = MakeSimulator(station)
        simulator.Initialize()
        context = simulator.get_context()
        plant = station.plant
        to_plant = station.diagram.GetSubsystemByName("to_plant_state")

        def Fingers():
            x = to_plant.get_output_port().Eval(to_plant.GetMyContextFromRoot(context))
            return [
                x[plant.GetJointByName(j).position_start()]
                for j in (finger.leader, finger.follower)
            ]

        before = Fingers()
        simulator.AdvanceTo(scenario.duration)
        leader, follower = Fingers()
        self.assertAlmostEqual(np.degrees(leader), target_deg, delta=1.0)
        self.assertAlmostEqual(follower, finger.ratio * leader + finger.offset)
        self.assertGreater(abs(follower - before[1]), np.radians(5))  # the second finger moved


if __name__ == "__main__":
    unittest.main()
