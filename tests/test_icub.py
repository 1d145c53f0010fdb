"""The iCub from icub-models with MoBeE's overlay: joints, limits, geometry, markers, clauses."""

import unittest

import numpy as np
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from mobee_drake.mobee.params import MobeeParams, SquashParams
from mobee_drake.mobee.squash import Squash
from mobee_drake.mobee.system import Mobee
from mobee_drake.robots.icub import UPPER_BODY_JOINTS, AddIcub, IcubConfig

# Joint limits of icub-models iCubGazeboV2_5 in degrees (docs: facts, "iCub joint limits").
EXPECTED_LIMITS_DEG = {
    "torso_pitch": (-20, 70),
    "torso_roll": (-30, 30),
    "torso_yaw": (-50, 50),
    "r_shoulder_pitch": (-95.5, 10),
    "r_shoulder_roll": (0, 160.8),
    "r_shoulder_yaw": (-37, 80),
    "r_elbow": (15, 106),
    "r_wrist_prosup": (-60, 60),
    "r_wrist_pitch": (-80, 25),
    "r_wrist_yaw": (-20, 25),
}


class IcubDiagram:
    def __init__(self, config=None, params=None):
        builder = DiagramBuilder()
        self.plant, self.scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
        self.config = config or IcubConfig()
        self.robot = AddIcub(self.plant, self.scene_graph, self.config)
        self.plant.Finalize()
        self.dut = Mobee.AddToBuilder(
            builder,
            plant=self.plant,
            scene_graph=self.scene_graph,
            robot=self.robot,
            joints=self.config.controlled_joints,
            params=params,
        )
        self.diagram = builder.Build()
        self.root_context = self.diagram.CreateDefaultContext()
        self.context = self.dut.GetMyMutableContextFromRoot(self.root_context)
        self.plant_context = self.plant.GetMyMutableContextFromRoot(self.root_context)

    def SetDegrees(self, **angles):
        q = self.dut.home
        for name, value in angles.items():
            q[self.dut.joint_index(name)] = np.radians(value)
        self.SetPositions(q)
        return q

    def SetPositions(self, q):
        x = self.plant.GetPositions(self.plant_context)
        for i, name in enumerate(self.dut.joints):
            x[self.plant.GetJointByName(name).position_start()] = q[i]
        self.plant.SetPositions(self.plant_context, x)

    def Out(self, name):
        return self.dut.GetOutputPort(name).Eval(self.context)


class TestIcubModel(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.icub = IcubDiagram()

    def test_joints_and_limits(self):
        plant = self.icub.plant
        self.assertEqual(plant.num_positions(), 20)
        self.assertEqual(self.icub.dut.joints, list(UPPER_BODY_JOINTS))
        for name, (lower, upper) in EXPECTED_LIMITS_DEG.items():
            joint = plant.GetJointByName(name)
            limits = [joint.position_lower_limits()[0], joint.position_upper_limits()[0]]
            np.testing.assert_allclose(np.degrees(limits), [lower, upper], atol=0.05)
        # The legs are welded (the iCub on its pole).
        self.assertFalse(plant.HasJointNamed("r_knee"))
        # The root is welded to the world.
        self.assertEqual(len(plant.GetFloatingBaseBodies()), 0)

    def test_overlay_geometry_and_markers(self):
        robot = self.icub.robot
        self.assertEqual(len(robot.field_margins), 14)
        for name in ("head", "r_palm", "l_palm", "r_hand", "l_hand", "r_elbow", "l_elbow"):
            self.icub.dut.marker_index(name)
        inspector = self.icub.scene_graph.model_inspector()
        by_name = {name: gid for gid, name in robot.geometry_names.items()}
        # Adjacent links (Drake's own filter) and the overlay's exclusions never interact ...
        for a, b in (
            ("r_upper_arm", "r_elbow"),
            ("r_elbow", "r_forearm"),
            ("r_upper_arm", "r_forearm"),
            ("r_forearm", "r_hand"),
            ("chest", "r_upper_arm"),
            ("chest", "head"),
        ):
            self.assertTrue(inspector.CollisionFiltered(by_name[a], by_name[b]), (a, b))
        # ... but the hand and the head, the two hands, the forearm and the hips do.
        for a, b in (("r_hand", "head"), ("r_hand", "l_hand"), ("r_forearm", "hips")):
            self.assertFalse(inspector.CollisionFiltered(by_name[a], by_name[b]), (a, b))

    def test_home_is_at_rest(self):
        icub = IcubDiagram()
        icub.SetPositions(icub.dut.home)
        self.assertEqual(icub.Out("field_contacts"), [])
        np.testing.assert_allclose(icub.Out("total"), 0.0, atol=1e-12)

    def test_palm_markers_are_on_the_hands(self):
        icub = IcubDiagram()
        icub.SetPositions(icub.dut.home)
        p = icub.Out("marker_positions").reshape(-1, 3)
        names = icub.dut.marker_names
        r_palm, l_palm = p[names.index("r_palm")], p[names.index("l_palm")]
        # Mirror images of each other, in front of (x < 0) and below the shoulders.
        np.testing.assert_allclose(r_palm * [1, -1, 1], l_palm, atol=1e-3)
        self.assertLess(r_palm[0], -0.05)
        self.assertGreater(r_palm[1], 0.05)
        # The right palm faces the body's midline at home (its normal points to -y).
        u = icub.Out("marker_directions").reshape(-1, 3)[names.index("r_palm")]
        self.assertLess(u[1], -0.5)


class TestIcubForces(unittest.TestCase):
    def test_f_work_matches_finite_differences_of_the_palm(self):
        icub = IcubDiagram(params=MobeeParams(work_squash=SquashParams(m=1e6, k=1.0)))
        q = icub.SetDegrees(r_shoulder_pitch=-40, r_shoulder_roll=30, r_elbow=60, torso_yaw=10)
        i = icub.dut.marker_index("r_palm")
        f = np.array([3.0, -1.0, 2.0])
        forces = np.zeros(3 * len(icub.dut.marker_names))
        forces[3 * i : 3 * i + 3] = f
        icub.dut.GetInputPort("marker_forces").FixValue(icub.context, forces)
        f_work = icub.Out("f_work")
        h = 1e-6
        J = np.zeros((3, len(q)))
        for j in range(len(q)):
            dq = np.zeros(len(q))
            dq[j] = h
            icub.SetPositions(q + dq)
            plus = icub.Out("marker_positions")[3 * i : 3 * i + 3]
            icub.SetPositions(q - dq)
            minus = icub.Out("marker_positions")[3 * i : 3 * i + 3]
            J[:, j] = (plus - minus) / (2 * h)
        np.testing.assert_allclose(f_work, Squash(J.T @ f, 1e6, 1.0), atol=1e-7)
        # Only the torso and the right arm move the right palm.
        moving = {icub.dut.joints[j] for j in np.flatnonzero(np.abs(f_work) > 1e-9)}
        self.assertTrue(
            moving
            <= {
                "torso_pitch",
                "torso_roll",
                "torso_yaw",
                "r_shoulder_pitch",
                "r_shoulder_roll",
                "r_shoulder_yaw",
                "r_elbow",
                "r_wrist_prosup",
                "r_wrist_pitch",
                "r_wrist_yaw",
            },
            moving,
        )

    def test_shoulder_cable_constraint(self):
        icub = IcubDiagram()
        # 1.71 (q0 - q1) >= -347 deg with q0 - q1 = -195.5 deg: inside the band, while every
        # other cable constraint is clear of it.
        icub.SetDegrees(r_shoulder_pitch=-95.5, r_shoulder_roll=100, r_shoulder_yaw=-10)
        p = MobeeParams()
        g = np.radians(1.71 * (-195.5) + 347.0) / (1.71 * np.sqrt(2))
        self.assertLess(g, p.constraint_delta)
        magnitude = p.constraint_force * (p.constraint_delta - g) / p.constraint_delta
        expected = np.zeros(20)
        expected[icub.dut.joint_index("r_shoulder_pitch")] = magnitude / np.sqrt(2)
        expected[icub.dut.joint_index("r_shoulder_roll")] = -magnitude / np.sqrt(2)
        np.testing.assert_allclose(icub.Out("f_cst"), expected, atol=1e-9)

    def test_forearm_disjunction(self):
        icub = IcubDiagram()
        elbow, prosup = icub.dut.joint_index("r_elbow"), icub.dut.joint_index("r_wrist_prosup")
        # Elbow bent beyond 90 deg with the forearm turned 50 deg: both literals violated, the
        # clause pushes the elbow open and the forearm back.
        icub.SetDegrees(r_elbow=95, r_wrist_prosup=50)
        f = icub.Out("f_cst")
        self.assertLess(f[elbow], 0)
        self.assertLess(f[prosup], 0)
        self.assertEqual(np.count_nonzero(f), 2)
        # Either literal clear of its band keeps the clause off.
        for angles in (
            {"r_elbow": 95, "r_wrist_prosup": 20},
            {"r_elbow": 70, "r_wrist_prosup": 50},
        ):
            icub.SetDegrees(**angles)
            np.testing.assert_array_equal(icub.Out("f_cst"), 0.0)


class TestOtherModels(unittest.TestCase):
    def test_another_icub_and_a_subset_of_joints(self):
        config = IcubConfig(
            model="iCubGazeboV2_7",
            controlled_joints=["r_shoulder_pitch", "r_shoulder_roll", "r_elbow"],
        )
        icub = IcubDiagram(config)
        self.assertEqual(icub.plant.num_positions(), 3)
        # The five shoulder clauses of the right arm remain (the frozen yaw enters as a constant).
        # The forearm clauses always hold with the pronation frozen at zero, and the left arm is
        # frozen at home where its clauses hold: all dropped.
        self.assertEqual(icub.dut.clauses.names, [f"r_shoulder_cable_{i}" for i in range(1, 6)])
        self.assertEqual(icub.Out("total").shape, (3,))


if __name__ == "__main__":
    unittest.main()
