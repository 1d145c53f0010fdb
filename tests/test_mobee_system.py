"""MoBeE 2.0's LeafSystem on a three-link planar arm: every output port against closed forms."""

import unittest

from arm_diagram import ArmDiagram
import numpy as np

from mobee_drake.mobee.params import JointParams, MobeeParams, SquashParams
from mobee_drake.mobee.squash import Squash
from mobee_drake.mobee.system import FORCE_TERMS


class TestPorts(unittest.TestCase):
    def test_port_names_and_sizes(self):
        arm = ArmDiagram()
        dut = arm.dut
        self.assertEqual(dut.GetInputPort("state").size(), 6)
        for name in ("attractor", "config_force"):
            self.assertEqual(dut.GetInputPort(name).size(), 3)
        self.assertEqual(dut.GetInputPort("marker_forces").size(), 6)
        for name in FORCE_TERMS + ("total",):
            self.assertEqual(dut.GetOutputPort(name).size(), 3)
        self.assertEqual(dut.GetOutputPort("marker_jacobians").size(), 2 * 3 * 3)
        self.assertEqual(dut.marker_names, ["tip", "elbow"])


class TestConfigurationSpaceTerms(unittest.TestCase):
    def test_spring_damping_config_and_total(self):
        params = MobeeParams(damping=7.0, stiffness=30.0)
        arm = ArmDiagram(params=params)
        q, v = np.array([0.2, -0.4, 0.5]), np.array([0.3, -1.0, 2.0])
        q_star = np.array([0.0, 0.1, 0.4])
        f_q = np.array([5.0, -50.0, 0.0])
        arm.Set(q, v)
        arm.dut.GetInputPort("attractor").FixValue(arm.context, q_star)
        arm.dut.GetInputPort("config_force").FixValue(arm.context, f_q)
        m, k = params.spring_squash.m, params.spring_squash.k
        spring = -m * 30.0 * (q - q_star) / (m / k + np.abs(30.0 * (q - q_star)))
        np.testing.assert_allclose(arm.Out("spring"), spring)
        np.testing.assert_allclose(arm.Out("damping"), -7.0 * v)
        np.testing.assert_allclose(arm.Out("f_config"), Squash(f_q, 20.0, 1.0))
        np.testing.assert_allclose(arm.Out("f_lim"), 0.0)  # far from the +-3 rad limits
        total = sum(arm.Out(term) for term in FORCE_TERMS)
        np.testing.assert_allclose(arm.Out("total"), total)

    def test_unconnected_attractor_holds_home(self):
        arm = ArmDiagram()
        arm.Set([0.1, 0.0, 0.0])
        self.assertLess(arm.Out("spring")[0], 0.0)
        np.testing.assert_allclose(arm.Out("spring")[1:], 0.0)

    def test_limit_and_constraint_terms(self):
        params = MobeeParams()
        arm = ArmDiagram(params=params)
        arm.dut.GetInputPort("attractor").FixValue(arm.context, np.zeros(3))
        # joint1 5 degrees from its upper limit of 3 rad; joint2 + joint3 = 145 deg, 5 deg short
        # of the "fold" constraint (joint2 + joint3 <= 150 deg).
        q = np.array([3.0 - np.radians(5), np.radians(70), np.radians(75)])
        arm.Set(q)
        delta = params.limit_delta
        np.testing.assert_allclose(
            arm.Out("f_lim"), [-params.limit_force * (delta - np.radians(5)) / delta, 0, 0]
        )
        g = np.radians(5) / np.sqrt(2)
        delta = params.constraint_delta
        magnitude = params.constraint_force * (delta - g) / delta
        np.testing.assert_allclose(arm.Out("f_cst"), magnitude * np.array([0, -1, -1]) / np.sqrt(2))


class TestPerJointConstants(unittest.TestCase):
    def test_squash_and_limits_per_joint(self):
        """Eq. 5.8's m_i, k_i and eq. 5.12's delta_i, f_max,i per joint; the others keep the
        robot-wide values, and a joint's own mass alone keeps the robot-wide damping."""
        own = JointParams(
            mass=2.0, spring_squash=SquashParams(5.0, 2.0), limit_delta=0.2, limit_force=10.0
        )
        params = MobeeParams(damping=7.0, stiffness=50.0, joint_overrides={"joint2": own})
        values = params.PerJoint(["joint1", "joint2", "joint3"])
        np.testing.assert_array_equal(values.mass, [1.0, 2.0, 1.0])
        np.testing.assert_array_equal(values.damping, [7.0, 7.0, 7.0])
        arm = ArmDiagram(params=params)
        arm.dut.GetInputPort("attractor").FixValue(arm.context, np.zeros(3))
        q = np.array([0.5, 3.0 - 0.05, 0.5])  # joint2 0.05 rad from its upper limit of 3 rad
        arm.Set(q)
        stretch = 50.0 * q
        np.testing.assert_allclose(
            arm.Out("spring"),
            -np.array(
                [Squash(stretch[0], 20, 1), Squash(stretch[1], 5, 2), Squash(stretch[2], 20, 1)]
            ),
        )
        np.testing.assert_allclose(arm.Out("f_lim"), [0.0, -10.0 * (0.2 - 0.05) / 0.2, 0.0])

    def test_a_joints_bad_value_is_named(self):
        params = MobeeParams(joint_overrides={"joint2": JointParams(limit_force=-1.0)})
        with self.assertRaisesRegex(
            ValueError, r"joint_overrides\[joint2\]\.limit_force must be > 0"
        ):
            params.Validate(["joint1", "joint2", "joint3"])


class TestWorkspaceForces(unittest.TestCase):
    def test_f_work_is_squashed_jacobian_transpose(self):
        arm = ArmDiagram(params=MobeeParams(work_squash=SquashParams(m=1e6, k=1.0)))
        q = np.array([0.3, -0.7, 1.1])
        arm.Set(q)
        f_tip, f_elbow = np.array([1.0, -2.0, 0.5]), np.array([-0.5, 0.0, 0.0])
        arm.dut.GetInputPort("marker_forces").FixValue(
            arm.context, np.concatenate([f_tip, f_elbow])
        )
        p = arm.Out("marker_positions").reshape(2, 3)
        J_tip, J_elbow = arm.Jacobian("link3", p[0]), arm.Jacobian("link2", p[1])
        expected = Squash(J_tip.T @ f_tip + J_elbow.T @ f_elbow, 1e6, 1.0)
        np.testing.assert_allclose(arm.Out("f_work"), expected, atol=1e-12)
        # Planar closed form for the tip: J^T f = sum over joints of (p_tip - p_joint) x f.
        c = np.cumsum(q)
        joints = np.array([[0, 0], [0.3 * np.cos(c[0]), 0.3 * np.sin(c[0])]])
        joints = np.vstack([joints, joints[1] + 0.3 * np.array([np.cos(c[1]), np.sin(c[1])])])
        tip = joints[2] + 0.3 * np.array([np.cos(c[2]), np.sin(c[2])])
        np.testing.assert_allclose(p[0], [*tip, 0.0], atol=1e-12)
        r = tip - joints
        np.testing.assert_allclose(J_tip.T @ f_tip, r[:, 0] * f_tip[1] - r[:, 1] * f_tip[0])

    def test_marker_jacobians_match_finite_differences(self):
        arm = ArmDiagram()
        q = np.array([0.3, -0.7, 1.1])
        arm.Set(q)
        J = arm.Out("marker_jacobians").reshape(2, 3, 3)
        h = 1e-6
        for j in range(3):
            dq = np.zeros(3)
            dq[j] = h
            arm.Set(q + dq)
            plus = arm.Out("marker_positions").reshape(2, 3)
            arm.Set(q - dq)
            minus = arm.Out("marker_positions").reshape(2, 3)
            np.testing.assert_allclose(J[:, :, j], (plus - minus) / (2 * h), atol=1e-8)

    def test_marker_directions(self):
        arm = ArmDiagram()
        arm.Set([np.pi / 2, 0.0, 0.0])
        np.testing.assert_allclose(
            arm.Out("marker_directions").reshape(2, 3)[0], [0, 1, 0], atol=1e-12
        )


class TestCollisionForce(unittest.TestCase):
    """f_coll (eq. 5.11) with a box just above the tip of the straight arm.

    The arm lies along +x; link3's capsule (radius 0.03) ends at x = 0.9. A box whose bottom face is
    at height 0.03 + d and which starts at x = 0.9 is nearest to the capsule at the unique witness
    point (0.9, 0.03, 0): the force on the arm is gain (margin - d) along -y, whose torques about
    the three joints are -0.9 F, -0.6 F and -0.3 F.
    """

    def _Arm(self, d, params):
        bottom = 0.03 + d
        return ArmDiagram(boxes=[((0.2, 0.1, 0.1), (1.0, bottom + 0.05, 0.0))], params=params)

    def test_direction_magnitude_and_witness(self):
        params = MobeeParams(collision_squash=SquashParams(m=1e6, k=1.0), collision_gain=1e3)
        d = 0.02
        arm = self._Arm(d, params)
        arm.Set([0.0, 0.0, 0.0])
        (contact,) = arm.Out("field_contacts")
        self.assertEqual((contact.name_A, contact.name_B), ("link3", "box0"))
        np.testing.assert_allclose(contact.distance, d, atol=1e-5)  # GJK accuracy
        # Drake's GJK places witness points on the curved cap to within a fraction of a millimetre.
        np.testing.assert_allclose(contact.p_WCa, [0.9, 0.03, 0.0], atol=1e-3)
        np.testing.assert_allclose(contact.nhat_BA_W, [0, -1, 0], atol=1e-2)
        F = 1e3 * (0.05 - d)
        np.testing.assert_allclose(
            arm.Out("f_coll"), Squash(-F * np.array([0.9, 0.6, 0.3]), 1e6, 1.0), rtol=1e-4
        )

    def test_a_robot_geometry_reported_as_b_is_pushed_away_all_the_same(self):
        """The box registered before the robot: SceneGraph reports the pair as (box, link3), and
        MoBeE turns it round (A is the robot's, the normal from the box to it), so the force and
        witness point are the ones above."""
        params = MobeeParams(collision_squash=SquashParams(m=1e6, k=1.0), collision_gain=1e3)
        d = 0.02
        arm = ArmDiagram(
            boxes=[((0.2, 0.1, 0.1), (1.0, 0.03 + d + 0.05, 0.0))], params=params, boxes_first=True
        )
        arm.Set([0.0, 0.0, 0.0])
        query = arm.dut.GetInputPort("geometry_query").Eval(arm.context)
        (reported,) = query.ComputeSignedDistancePairwiseClosestPoints(0.05)
        self.assertEqual(query.inspector().GetName(reported.id_A), "box0")
        (contact,) = arm.Out("field_contacts")
        self.assertEqual((contact.name_A, contact.name_B), ("link3", "box0"))
        np.testing.assert_allclose(contact.p_WCa, [0.9, 0.03, 0.0], atol=1e-3)
        np.testing.assert_allclose(contact.p_WCb, [0.9, 0.03 + d, 0.0], atol=1e-3)
        np.testing.assert_allclose(contact.nhat_BA_W, [0, -1, 0], atol=1e-2)
        F = 1e3 * (0.05 - d)
        np.testing.assert_allclose(
            arm.Out("f_coll"), Squash(-F * np.array([0.9, 0.6, 0.3]), 1e6, 1.0), rtol=1e-2
        )

    def test_grows_with_penetration_and_vanishes_outside_the_field(self):
        params = MobeeParams()
        magnitudes = []
        for d in (0.06, 0.049, 0.04, 0.02, 0.005, -0.01):
            arm = self._Arm(d, params)
            arm.Set([0.0, 0.0, 0.0])
            f = arm.Out("f_coll")
            magnitudes.append(np.linalg.norm(f))
            if d < 0.05:
                self.assertTrue(np.all(f < 0), f)  # pushes the arm down, away from the box
        self.assertEqual(magnitudes[0], 0.0)  # d = 0.06 > margin 0.05: outside the field
        self.assertTrue(np.all(np.diff(magnitudes) > 0), magnitudes)
        self.assertTrue(np.all(np.array(magnitudes) < params.collision_squash.m * np.sqrt(3)))

    def test_self_collision_pushes_both_links_apart(self):
        params = MobeeParams(collision_squash=SquashParams(m=1e6, k=1.0), collision_gain=1e3)
        arm = ArmDiagram(params=params)
        # Folded: link3 comes back near link1 (non-adjacent links, so not filtered), 2.7 cm apart.
        q = np.array([0.0, np.radians(100), np.radians(124)])
        arm.Set(q)
        contacts = [
            c for c in arm.Out("field_contacts") if {c.name_A, c.name_B} == {"link1", "link3"}
        ]
        self.assertEqual(len(contacts), 1)
        (c,) = contacts
        f_W = 1e3 * c.penetration * c.nhat_BA_W
        J_A, J_B = arm.Jacobian(c.name_A, c.p_WCa), arm.Jacobian(c.name_B, c.p_WCb)
        expected = J_A.T @ f_W - J_B.T @ f_W
        for other in arm.Out("field_contacts"):
            if other is not c:
                g = 1e3 * other.penetration * other.nhat_BA_W
                expected += arm.Jacobian(other.name_A, other.p_WCa).T @ g
                expected -= arm.Jacobian(other.name_B, other.p_WCb).T @ g
        np.testing.assert_allclose(
            arm.Out("f_coll"), Squash(expected, 1e6, 1.0), rtol=1e-9, atol=1e-9
        )
        # A small step along the force separates the two links.
        before = c.distance
        arm.Set(q + 1e-4 * arm.Out("f_coll") / np.linalg.norm(arm.Out("f_coll")))
        after = [
            x.distance
            for x in arm.Out("field_contacts")
            if {x.name_A, x.name_B} == {"link1", "link3"}
        ]
        self.assertGreater(after[0], before)


if __name__ == "__main__":
    unittest.main()
