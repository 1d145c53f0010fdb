"""MoBeE's ZeroPositionKinematicTree XML: the Katana of App. B, closed forms, and bad files."""

import math
import pathlib
import tempfile
import unittest

import numpy as np
from pydrake.geometry import SceneGraph
from pydrake.multibody.plant import MultibodyPlant

from mobee_drake.mobee.constraints import ClauseSet
from mobee_drake.robots.overlay import Box, Capsule, Sphere
from mobee_drake.robots.zero_position import (
    AddZeroPositionRobot,
    LoadZeroPositionTree,
    ZeroPositionError,
)
from mobee_drake.scenario import BuildScenario, LoadScenario, RunScenario
from mobee_drake.station.world_events import MakeSimulator
from mobee_drake.yaml_io import YamlFileError

MODELS = pathlib.Path(__file__).resolve().parents[1] / "models"


def _Write(text: str) -> pathlib.Path:
    path = pathlib.Path(tempfile.mkdtemp()) / "robot.xml"
    path.write_text(text)
    return path


def _Tree(body: str) -> str:
    return (
        '<?xml version="1.0"?>\n<ZeroPositionKinematicTree version="1.0" robotName="r">\n'
        f'<bodypart name="arm">\n{body}\n</bodypart>\n</ZeroPositionKinematicTree>\n'
    )


def _Plant(robot, **kwargs):
    plant, scene_graph = MultibodyPlant(0.0), SceneGraph()
    plant.RegisterAsSourceForSceneGraph(scene_graph)
    overlay = AddZeroPositionRobot(plant, scene_graph, robot, **kwargs)
    plant.Finalize()
    return plant, overlay


class TestKatana(unittest.TestCase):
    def setUp(self):
        self.robot = LoadZeroPositionTree(MODELS / "katana.xml")

    def test_joints_motors_and_home(self):
        robot = self.robot
        self.assertEqual(robot.name, "katana400")
        self.assertEqual(len(robot.joints), 7)  # 5 arm joints and the gripper's two
        self.assertEqual(len(robot.motors), 6)
        gripper = robot.motors[5]
        self.assertEqual(gripper.joints, ("arm_5", "arm_6"))
        # The gripper motor's interval [-121.58, 8.7] maps onto [90, 180] for both fingers.
        expected = 90 + (-50 + 121.58) / (8.7 + 121.58) * 90
        np.testing.assert_allclose(gripper.JointAngles(-50.0), [expected, expected])
        self.assertAlmostEqual(robot.home["arm_5"], math.radians(expected))
        # A motor without home sits in the middle of its interval.
        self.assertAlmostEqual(robot.motors[2].home, (52.7 + 302.69) / 2)
        plant, _ = _Plant(robot)
        joint = plant.GetJointByName("arm_1")
        self.assertAlmostEqual(joint.position_lower_limits()[0], math.radians(-15.75))
        self.assertAlmostEqual(joint.position_upper_limits()[0], math.radians(124.25))
        np.testing.assert_allclose(joint.revolute_axis(), [0, 1, 0])

    def test_primitives_from_links_joints_and_boxes(self):
        shapes = [p.shape for p in self.robot.overlay.primitives]
        # The base plate and the two finger boxes; four link capsules (radius > 0) and three
        # joint capsules (radius and length > 0).
        self.assertEqual(sum(isinstance(s, Box) for s in shapes), 3)
        self.assertEqual(sum(isinstance(s, Capsule) for s in shapes), 7)
        first_link = next(p for p in self.robot.overlay.primitives if p.name == "link_line11")
        # "z=1 length=0.19" from the point (0, 0, -0.2) that the base link "z=- .2" reached.
        np.testing.assert_allclose(first_link.shape.start, [0, 0, -0.2])
        np.testing.assert_allclose(first_link.shape.end, [0, 0, -0.01], atol=1e-12)
        self.assertEqual(first_link.shape.radius, 0.04)
        self.assertIsNone(first_link.field)  # no field given: the overlay's default margin

    def test_forward_kinematics_closed_form(self):
        plant, overlay = _Plant(self.robot)
        context = plant.CreateDefaultContext()
        (wrist,) = overlay.markers

        def Wrist(q):
            plant.SetPositions(context, q)
            body = plant.GetBodyByName(wrist.body_name)
            return plant.EvalBodyPoseInWorld(context, body) @ wrist.p_BM

        # The controlled joints are arm_0..arm_6; with all at zero the wrist is the sum of the
        # body vectors (ZP notation): (0,0,-.2) + (0,0,.19) + (-.19,0,0) + (.139,0,0) + (-.185,0,0).
        q = np.zeros(plant.num_positions())
        np.testing.assert_allclose(Wrist(q), [-0.236, 0, -0.01], atol=1e-12)
        # The first joint turns everything about the z axis through (0, 0, -0.2).
        q[0] = math.radians(30)
        c, s = math.cos(q[0]), math.sin(q[0])
        np.testing.assert_allclose(Wrist(q), [-0.236 * c, -0.236 * s, -0.01], atol=1e-12)
        # The second joint (axis y through (0, 0, -0.01)) raises the rest of the arm.
        q[:] = 0
        q[1] = math.radians(90)
        np.testing.assert_allclose(Wrist(q), [0, 0, -0.01 + 0.236], atol=1e-12)

    def test_gripper_frozen_at_home(self):
        plant, overlay = _Plant(self.robot, controlled_joints=[f"arm_{i}" for i in range(5)])
        self.assertEqual(plant.num_positions(), 5)
        self.assertAlmostEqual(overlay.frozen_joints["arm_6"], self.robot.home["arm_6"])


class TestFormat(unittest.TestCase):
    def test_numbers_with_blanks_sphere_field_and_marker(self):
        robot = LoadZeroPositionTree(
            _Write(
                _Tree(
                    '<link z="- .5" radius="0.1" field="0.15">'
                    '<sphere radius=".05" px="1" field="true"/><marker name="tip"/></link>'
                )
            )
        )
        capsule, sphere = (p.shape for p in robot.overlay.primitives)
        np.testing.assert_allclose(capsule.end, [0, 0, -0.5])
        self.assertAlmostEqual(robot.overlay.primitives[0].field, 0.05)  # 0.15 - 0.1
        self.assertIsInstance(sphere, Sphere)
        np.testing.assert_allclose(sphere.center, [1, 0, -0.5])
        self.assertAlmostEqual(sphere.radius + robot.overlay.primitives[1].field, 0.05)
        (marker,) = robot.overlay.markers
        np.testing.assert_allclose(marker.position, [0, 0, -0.5])
        np.testing.assert_allclose(marker.direction, [0, 0, -1])

    def test_box_orientation(self):
        robot = LoadZeroPositionTree(
            _Write(_Tree('<box width="1" depth="2" height="3" hx="1" angle="90"/>'))
        )
        from pydrake.math import RollPitchYaw

        (box,) = (p.shape for p in robot.overlay.primitives)
        R = RollPitchYaw(np.radians(box.rpy_deg)).ToRotationMatrix().matrix()
        np.testing.assert_allclose(R[:, 2], [1, 0, 0], atol=1e-12)  # height along (hx, hy, hz)
        np.testing.assert_allclose(R[:, 0], [0, 1, 0], atol=1e-12)  # width turned by 90 deg
        self.assertEqual(box.size, [1, 2, 3])

    def test_constraints_over_motors(self):
        # Motor 0 drives joint arm_0 one to one; motor 1 maps [0, 100] onto arm_1's [-50, 50].
        robot = LoadZeroPositionTree(
            _Write(
                _Tree(
                    '<motor minPos="-90" maxPos="90"><joint z="1" minPos="-90" maxPos="90">'
                    '<link x="1"><motor minPos="0" maxPos="100">'
                    '<joint z="1" minPos="-50" maxPos="50"/></motor></link></joint></motor>'
                    '<constraintList><constraint a="1 2" q="0 1" b="100"/></constraintList>'
                )
            )
        )
        (clause,) = robot.overlay.clauses
        clauses = ClauseSet(robot.overlay.clauses, ["arm_0", "arm_1"], {})
        # a . m < b  <=>  100 - m0 - 2 m1 > 0 with m0 = q0, m1 = q1 + 50 (degrees).
        for q_deg in ([0, 0], [10, -20], [-30, 40]):
            m0, m1 = q_deg[0], q_deg[1] + 50
            literal = clause.literals[0]
            value = sum(literal.coefficients[j] * v for j, v in zip(["arm_0", "arm_1"], q_deg))
            self.assertAlmostEqual(value + literal.offset, 100 - m0 - 2 * m1)
        self.assertEqual(len(clauses.Clearances(np.zeros(2))), 1)


class TestErrors(unittest.TestCase):
    def _Fails(self, text: str, pattern: str):
        with self.assertRaisesRegex(ZeroPositionError, pattern):
            LoadZeroPositionTree(_Write(text))

    def test_errors_name_file_line_and_element(self):
        self._Fails(_Tree('<link z="1">'), r"robot\.xml:\d+: malformed XML")
        self._Fails(_Tree('<wheel z="1"/>'), r"robot\.xml:4: <wheel>: unknown element")
        self._Fails(
            _Tree('<link z="1" colour="red"/>'),
            r"robot\.xml:4: <link>: unknown attribute\(s\) \['colour'\]",
        )
        self._Fails(
            _Tree('<motor minPos="0" maxPos="1">\n<joint z="1" minPos="5" maxPos="-5"/></motor>'),
            r"robot\.xml:5: <joint>: minPos 5.0 must be smaller",
        )
        self._Fails(
            _Tree(
                '<motor minPos="0" maxPos="1"><joint z="1" minPos="0" maxPos="1"/>'
                '</motor>\n<constraintList><constraint a="1" q="3" b="0"/>'
                "</constraintList>"
            ),
            r"robot\.xml:5: <constraint>: q names motor 3, but this bodypart has 1",
        )
        self._Fails(_Tree('<link z="abc"/>'), r'<link>: z="abc" is not a number')
        self._Fails(
            _Tree('<link z="1" radius="0.2" field="0.1"/>'), "field 0.1 is smaller than radius 0.2"
        )
        self._Fails(
            _Tree('<joint z="1" minPos="0" maxPos="1"/>'),
            "a joint must sit inside the motor that drives it",
        )
        self._Fails(
            _Tree('<box width="1" depth="1" height="1" field="true"/>'),
            "field volumes are supported for spheres only",
        )


class TestKatanaScenario(unittest.TestCase):
    def test_babbles_among_obstacles_without_touching_them(self):
        scenario = LoadScenario("katana", "{duration: 30.0}")
        summary = RunScenario(scenario)
        self.assertEqual(summary.safety.penetrating_steps, 0)
        # The arm came inside the field of at least one obstacle, and MoBeE kept it out.
        approaches = [
            d
            for name, d in summary.safety.closest_approach.items()
            if name in ("post", "ball", "shelf") and d is not None
        ]
        self.assertTrue(approaches)
        self.assertGreater(min(approaches), 0.0)


class TestTwoRobots(unittest.TestCase):
    """The iCub and the Katana in one world, each with its own MoBeE (ch. 4.1.2)."""

    def test_each_mobee_keeps_its_robot_off_the_other(self):
        scenario = LoadScenario("icub_and_katana")
        simulation = BuildScenario(scenario)
        simulator = MakeSimulator(simulation)
        simulator.Initialize()
        context = simulator.get_context()
        katana = simulation.diagram.GetSubsystemByName("katana_mobee")
        inspector = simulation.scene_graph.model_inspector()
        icub = simulation.robot.instance
        samples_with_icub_in_katana_fields = 0
        for t in np.arange(1.0, 61.0, 1.0):
            simulator.AdvanceTo(t)
            pairs = katana.GetOutputPort("field_pairs").Eval(katana.GetMyContextFromRoot(context))
            bodies = [
                simulation.plant.GetBodyFromFrameId(inspector.GetFrameId(b))
                for b in pairs.geometry_B
            ]
            samples_with_icub_in_katana_fields += any(
                b is not None and b.model_instance() == icub for b in bodies
            )
        self.assertGreater(samples_with_icub_in_katana_fields, 0)
        report = simulation.monitor.Report(simulation.monitor.GetMyContextFromRoot(context))
        self.assertEqual(report.penetrating_steps, 0)
        # The iCub's MoBeE saw the Katana (an "other object" to it) inside its fields too.
        self.assertGreater(report.closest_approach["(other objects)"], 0.0)

    def test_companions_need_the_kinematic_robot(self):

        with self.assertRaisesRegex(
            YamlFileError, "companion 'katana': other robots run with the kinematic robot only"
        ):
            LoadScenario(
                MODELS.parent / "diagrams" / "icub_and_katana.yaml", "{mover: !Dynamic {}}"
            )


if __name__ == "__main__":
    unittest.main()
