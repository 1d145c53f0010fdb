"""MoBeE's ZeroPositionKinematicTree XML: the Katana of App. B, closed forms, and bad files."""

import math
import pathlib
import tempfile
import unittest

import numpy as np
from pydrake.geometry import Box as DrakeBox
from pydrake.geometry import SceneGraph
from pydrake.multibody.plant import MultibodyPlant

from mobee_drake.experiments.plots import SaveFigure
from mobee_drake.experiments.robot_figure import PrimitivesFigure
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
        self.assertEqual(wrist.body_name, "arm_4_link")

        def Points(q):
            """The wrist marker and the hand's end (where the finger joints sit)."""
            plant.SetPositions(context, q)
            body = plant.GetBodyByName(wrist.body_name)
            hand_end = plant.GetBodyByName("arm_5_link")
            return (
                plant.EvalBodyPoseInWorld(context, body) @ wrist.p_BM,
                plant.EvalBodyPoseInWorld(context, hand_end).translation(),
            )

        # The controlled joints are arm_0..arm_6; with all at zero a point is the sum of the
        # body vectors (ZP notation): (0,0,-.2) + (0,0,.19) + (-.19,0,0) + (.139,0,0) reach the
        # wrist (the marker sits at the start of the hand's link, like the original's markers),
        # and + (-.185,0,0) the hand's end.
        q = np.zeros(plant.num_positions())
        np.testing.assert_allclose(Points(q), [[-0.051, 0, -0.01], [-0.236, 0, -0.01]], atol=1e-12)
        # The first joint turns everything about the z axis through (0, 0, -0.2).
        q[0] = math.radians(30)
        c, s = math.cos(q[0]), math.sin(q[0])
        np.testing.assert_allclose(
            Points(q),
            [[-0.051 * c, -0.051 * s, -0.01], [-0.236 * c, -0.236 * s, -0.01]],
            atol=1e-12,
        )
        # The second joint (axis y through (0, 0, -0.01)) raises the rest of the arm.
        q[:] = 0
        q[1] = math.radians(90)
        np.testing.assert_allclose(
            Points(q), [[0, 0, -0.01 + 0.051], [0, 0, -0.01 + 0.236]], atol=1e-12
        )

    def _Boxes(self, q_deg: dict[str, float]):
        """Each box's centre, rotation and size (width, height, depth along its own x, y, z) in
        the root's frame, as SceneGraph holds them, with the joints at ``q_deg`` (others 0)."""
        plant, scene_graph = MultibodyPlant(0.0), SceneGraph()
        plant.RegisterAsSourceForSceneGraph(scene_graph)
        AddZeroPositionRobot(plant, scene_graph, self.robot)
        plant.Finalize()
        context = plant.CreateDefaultContext()
        q = np.zeros(plant.num_positions())
        for joint, angle in q_deg.items():
            q[plant.GetJointByName(joint).position_start()] = math.radians(angle)
        plant.SetPositions(context, q)
        inspector = scene_graph.model_inspector()
        boxes = {}
        for body in ("base", "arm_5_link", "arm_6_link"):
            X_WB = plant.EvalBodyPoseInWorld(context, plant.GetBodyByName(body))
            for geometry in plant.GetCollisionGeometriesForBody(plant.GetBodyByName(body)):
                shape = inspector.GetShape(geometry)
                if isinstance(shape, DrakeBox):
                    X_WG = X_WB @ inspector.GetPoseInFrame(geometry)
                    name = inspector.GetName(geometry).split("::")[-1]
                    size = [shape.width(), shape.depth(), shape.height()]  # Drake's x, y, z
                    boxes[name] = (X_WG.translation(), X_WG.rotation().matrix(), size)
        return plant, context, boxes

    def test_base_plate_flat_and_fingers_forward(self):
        """App. B's geometry under the original's readings (primitives placed from the start of
        their link, a box's height along y): the base plate lies flat at the base joint, and
        the fingers reach forward along the hand."""
        plant, context, boxes = self._Boxes({})
        centre, R, size = boxes["box_line8"]  # the base plate: width .12, height .1, depth .012
        base_joint = plant.GetBodyByName("arm_0_link").EvalPoseInWorld(context).translation()
        np.testing.assert_allclose(base_joint, [0, 0, -0.2])
        np.testing.assert_allclose(centre, base_joint, atol=1e-12)  # at the base joint
        thin = int(np.argmin(size))
        self.assertAlmostEqual(size[thin], 0.012)
        np.testing.assert_allclose(abs(R[:, thin] @ [0, 0, 1]), 1.0, atol=1e-12)  # lying flat

        def Hand(context):
            """The hand's end (the finger joints' point) and its unit direction (x = -1)."""
            X_WH = plant.GetBodyByName("arm_4_link").EvalPoseInWorld(context)
            end = plant.GetBodyByName("arm_5_link").EvalPoseInWorld(context).translation()
            return end, X_WH.rotation() @ [-1.0, 0.0, 0.0]

        # With every joint at zero (as App. B writes it) the fingers stand across the hand,
        # their centres 1 cm beyond its end (px=-.01 along the hand, which points along -x).
        end, forward = Hand(context)
        for finger in ("box_line28", "box_line33"):
            centre, R, size = boxes[finger]
            self.assertEqual(size, [0.01, 0.03, 0.13])
            self.assertAlmostEqual((centre - end) @ forward, 0.01)
            np.testing.assert_allclose(abs(R[:, 2] @ [0, 0, 1]), 1.0, atol=1e-12)
        # Closed (both finger joints at their lower limit, 90 deg): both fingers reach forward
        # along the hand, 6.6 cm beyond its end, their long sides 2 cm apart.
        plant, context, boxes = self._Boxes({"arm_5": 90.0, "arm_6": 90.0})
        end, forward = Hand(context)
        for finger, side in (("box_line28", -1), ("box_line33", 1)):
            centre, R, size = boxes[finger]
            np.testing.assert_allclose(
                centre - end, 0.066 * forward + [0, 0, side * 0.01], atol=1e-12
            )
            np.testing.assert_allclose(abs(R[:, 2] @ forward), 1.0, atol=1e-12)
        # At home (the gripper's motor at -50 deg: 139.4 deg at both finger joints) they open
        # forward in a V, 49.4 deg to either side of the hand, wherever the arm has turned it.
        home = {j: math.degrees(a) for j, a in self.robot.home.items()}
        plant, context, boxes = self._Boxes(home)
        end, forward = Hand(context)
        opening = self.robot.home["arm_5"] - math.pi / 2
        for finger in ("box_line28", "box_line33"):
            centre, R, _ = boxes[finger]
            self.assertAlmostEqual(
                (centre - end) @ forward, 0.066 * math.cos(opening) - 0.01 * math.sin(opening)
            )
            self.assertAlmostEqual(abs(R[:, 2] @ forward), math.cos(opening))

    def test_figure_of_the_primitives(self):
        figure = PrimitivesFigure(self.robot, {"zero": {}, "home": self.robot.home})
        for axis in figure.axes:
            self.assertTrue(axis.get_title())
            self.assertIn("[m]", axis.get_xlabel() + axis.get_ylabel() + axis.get_zlabel())
            labels = [t.get_text() for t in axis.get_legend().get_texts()]
            self.assertIn("box on base", labels)
            self.assertIn("marker 'wrist'", labels)
        with tempfile.TemporaryDirectory() as folder:
            SaveFigure(figure, pathlib.Path(folder) / "katana.png", dpi=20)

    def test_gripper_frozen_at_home(self):
        plant, overlay = _Plant(self.robot, controlled_joints=[f"arm_{i}" for i in range(5)])
        self.assertEqual(plant.num_positions(), 5)
        self.assertAlmostEqual(overlay.frozen_joints["arm_6"], self.robot.home["arm_6"])


class TestFormat(unittest.TestCase):
    def test_numbers_with_blanks_sphere_field_and_marker(self):
        robot = LoadZeroPositionTree(
            _Write(
                _Tree(
                    '<link z="1"><link z=" - .5 " radius="0.1" field="0.15">'
                    '<sphere radius=".05" px="1" field="true"/><marker name="tip"/></link></link>'
                )
            )
        )
        capsule, sphere = (p.shape for p in robot.overlay.primitives)
        np.testing.assert_allclose(capsule.start, [0, 0, 1])
        np.testing.assert_allclose(capsule.end, [0, 0, 0.5])  # a sign apart from its digits
        self.assertAlmostEqual(robot.overlay.primitives[0].field, 0.05)  # 0.15 - 0.1
        self.assertIsInstance(sphere, Sphere)
        # Like the original: px, py, pz and a marker are placed from the start of their link.
        np.testing.assert_allclose(sphere.center, [1, 0, 1])
        self.assertAlmostEqual(sphere.radius + robot.overlay.primitives[1].field, 0.05)
        (marker,) = robot.overlay.markers
        np.testing.assert_allclose(marker.position, [0, 0, 1])
        np.testing.assert_allclose(marker.direction, [0, 0, -1])

    def test_length_zero_is_the_vector_as_given(self):
        robot = LoadZeroPositionTree(
            _Write(
                _Tree(
                    '<link z="2" length="0" radius="0.1"/><link x="2" length="0.5" radius="0.1"/>'
                    '<motor minPos="0" maxPos="1"><joint y="3" minPos="0" maxPos="1" '
                    'radius="0.1"/></motor>'
                )
            )
        )
        given, scaled, joint = (p.shape for p in robot.overlay.primitives)
        np.testing.assert_allclose([given.start, given.end], [[0, 0, 0], [0, 0, 2]])
        np.testing.assert_allclose([scaled.start, scaled.end], [[0, 0, 0], [0.5, 0, 0]])
        # A joint's capsule without a length: as long as its vector, centred on the joint.
        np.testing.assert_allclose([joint.start, joint.end], [[0, -1.5, 0], [0, 1.5, 0]])

    def test_elements_directly_inside_a_joint_stay_with_its_parent(self):
        robot = LoadZeroPositionTree(
            _Write(
                _Tree(
                    '<link z="1"><motor minPos="0" maxPos="1"><joint x="1" minPos="0" '
                    'maxPos="1" radius="0.1" length="0.2"><sphere radius="0.1" pz="0.3"/>'
                    '<marker name="m"/><link y="1"><sphere radius="0.1"/></link></joint>'
                    "</motor></link>"
                )
            )
        )
        capsule, on_joint, on_link = robot.overlay.primitives
        self.assertEqual(capsule.link, "arm_0_link")  # ours: the same solid at every angle
        self.assertEqual(on_joint.link, "base")  # drawn before the joint's turn
        np.testing.assert_allclose(on_joint.shape.center, [0, 0, 1.3])  # from the joint's point
        self.assertEqual(on_link.link, "arm_0_link")
        (marker,) = robot.overlay.markers
        self.assertEqual(marker.link, "base")
        np.testing.assert_allclose(marker.position, [0, 0, 1])

    def test_box_orientation(self):
        """The original's Box(width, height, depth) along its own x, y, z, the height axis y by
        default, turned as its setSpecialEulerOrientation turns it. Expected columns (where
        width, height, depth go) worked out by hand from its three steps: about y until x points
        along the axis's xz projection, y carried onto the axis, then ``angle`` about the axis."""
        from pydrake.math import RollPitchYaw

        for axis, angle, width, height, depth in (
            ("", 0, [1, 0, 0], [0, 1, 0], [0, 0, 1]),  # no axis: y
            ('hx="0" hy="0" hz="0"', 0, [1, 0, 0], [0, 1, 0], [0, 0, 1]),  # zero: y too
            ('hy="2"', 90, [0, 0, -1], [0, 1, 0], [1, 0, 0]),  # 90 deg about y
            ('hz="1"', 0, [0, 1, 0], [0, 0, 1], [1, 0, 0]),
            ('hz="-1"', 0, [0, -1, 0], [0, 0, -1], [1, 0, 0]),
            ('hx="1"', 90, [0, 0, -1], [1, 0, 0], [0, -1, 0]),
        ):
            with self.subTest(axis=axis, angle=angle):
                robot = LoadZeroPositionTree(
                    _Write(
                        _Tree(
                            f'<link z="1"><box width="1" depth="2" height="3" {axis} '
                            f'angle="{angle}" px="0.5"/></link>'
                        )
                    )
                )
                (box,) = (p.shape for p in robot.overlay.primitives)
                R = RollPitchYaw(np.radians(box.rpy_deg)).ToRotationMatrix().matrix()
                np.testing.assert_allclose(R, np.array([width, height, depth]).T, atol=1e-12)
                self.assertEqual(box.size, [1, 3, 2])  # width, height, depth
                np.testing.assert_allclose(box.center, [0.5, 0, 0])  # from the link's start

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
            _Tree('<link z="1"><box width="1" depth="1" height="1" field="true"/></link>'),
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
