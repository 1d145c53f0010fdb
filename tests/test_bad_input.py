"""Bad input stops with an error that names the file, line, joint, marker and value."""

import pathlib
import tempfile
import textwrap
import unittest

from arm_diagram import MODELS, ArmDiagram
import numpy as np
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from mobee_drake.mobee.barrier import BarrierParams
from mobee_drake.mobee.params import MobeeParams, SquashParams
from mobee_drake.mobee.system import Mobee
from mobee_drake.robots.assembly import AddRobotWithOverlay
from mobee_drake.robots.icub import AddIcub, IcubConfig
from mobee_drake.robots.overlay import LoadOverlay
from mobee_drake.yaml_io import YamlFileError


class TestBadCommands(unittest.TestCase):
    def setUp(self):
        self.arm = ArmDiagram()
        self.arm.Set([0.1, 0.2, 0.3])

    def _Fix(self, port, value):
        self.arm.dut.GetInputPort(port).FixValue(self.arm.context, np.array(value, dtype=float))

    def test_non_finite_attractor(self):
        self._Fix("attractor", [0.0, np.nan, 0.0])
        with self.assertRaisesRegex(ValueError, "attractor for 'joint2' is not finite: nan"):
            self.arm.Out("total")

    def test_attractor_outside_the_joint_limits(self):
        self._Fix("attractor", [0.0, 0.0, 3.5])
        with self.assertRaisesRegex(
            ValueError,
            r"attractor for joint 'joint3' is 200\.5\d* deg, "
            r"outside its limits \[-171\.8\d*, 171\.8\d*\] deg",
        ):
            self.arm.Out("total")

    def test_non_finite_forces(self):
        self._Fix("config_force", [np.inf, 0.0, 0.0])
        with self.assertRaisesRegex(ValueError, "config_force for 'joint1' is not finite: inf"):
            self.arm.Out("f_config")
        arm = ArmDiagram()
        arm.dut.GetInputPort("marker_forces").FixValue(arm.context, [0, 0, 0, 0, np.nan, 0])
        with self.assertRaisesRegex(ValueError, r"marker_forces for 'elbow\[y\]' is not finite"):
            arm.Out("total")

    def test_non_finite_state(self):
        # The plant itself refuses non-finite positions; a MoBeE fed by another source checks.
        dut = Mobee(self.arm.plant, self.arm.robot, joints=["joint1", "joint2", "joint3"])
        context = dut.CreateDefaultContext()
        dut.GetInputPort("state").FixValue(context, [0.1, 0.2, 0.3, 0.0, 0.0, -np.inf])
        with self.assertRaisesRegex(ValueError, "state for 'joint3 velocity' is not finite: -inf"):
            dut.GetOutputPort("total").Eval(context)

    def test_unknown_marker_and_joint_names(self):
        with self.assertRaisesRegex(ValueError, "unknown marker 'palm'; markers are: tip, elbow"):
            self.arm.dut.marker_index("palm")
        with self.assertRaisesRegex(ValueError, "unknown joint 'joint9'"):
            self.arm.dut.joint_index("joint9")
        builder = DiagramBuilder()
        plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
        robot = AddRobotWithOverlay(
            plant,
            scene_graph,
            model_file=MODELS / "three_link_arm.urdf",
            overlay_file=MODELS / "three_link_arm_overlay.yaml",
            controlled_joints=["joint1", "joint2", "joint3"],
        )
        plant.Finalize()
        with self.assertRaisesRegex(ValueError, "unknown joint 'joint4'; the robot's joints are"):
            Mobee(plant, robot, joints=["joint1", "joint4"])

    def test_bad_parameters(self):
        with self.assertRaisesRegex(ValueError, r"collision_squash\.m must be > 0, got -1"):
            ArmDiagram(params=MobeeParams(collision_squash=SquashParams(m=-1.0, k=1.0)))
        # A gain of zero is refused (a mutation of "> 0" into ">= 0" survived every test), and
        # a damping of zero only with the barrier on.
        with self.assertRaisesRegex(ValueError, r"collision_gain must be > 0, got 0"):
            MobeeParams(collision_gain=0.0).Validate(["a"])
        with self.assertRaisesRegex(ValueError, r"damping must be > 0 while the safety barrier"):
            MobeeParams(damping=0.0).Validate(["a"])
        MobeeParams(damping=0.0, barrier=BarrierParams(enabled=False)).Validate(["a"])


class TestBadRobots(unittest.TestCase):
    def _Build(self, config):
        builder = DiagramBuilder()
        plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
        AddIcub(plant, scene_graph, config)

    def test_unknown_model(self):
        with self.assertRaisesRegex(
            ValueError, "unknown iCub model 'iCubMars'; icub-models provides: .*iCubGazeboV2_5"
        ):
            self._Build(IcubConfig(model="iCubMars"))

    def test_unknown_controlled_joint(self):
        with self.assertRaisesRegex(ValueError, "unknown joint 'r_pinky'"):
            self._Build(IcubConfig(controlled_joints=["r_elbow", "r_pinky"]))

    def test_home_outside_limits(self):
        with self.assertRaisesRegex(
            ValueError,
            "home angle of joint 'r_elbow' is 0 deg, outside "
            r"its limits \[15, 106\] deg",
        ):
            self._Build(IcubConfig(home_deg={"r_elbow": 0.0}))


class TestBadOverlays(unittest.TestCase):
    GOOD = (MODELS / "three_link_arm_overlay.yaml").read_text()

    def _Load(self, text):
        folder = tempfile.mkdtemp()
        path = pathlib.Path(folder) / "overlay.yaml"
        path.write_text(textwrap.dedent(text))
        return path

    def test_the_good_one_loads(self):
        self.assertEqual(len(LoadOverlay(self._Load(self.GOOD)).primitives), 3)

    def test_unknown_key_names_file_and_line(self):
        path = self._Load(self.GOOD.replace("markers:", "markerz:"))
        line = self.GOOD.splitlines().index("markers:") + 1
        with self.assertRaisesRegex(YamlFileError, f"{path}:{line}: .*'markerz'"):
            LoadOverlay(path)

    def test_wrong_type(self):
        path = self._Load(self.GOOD.replace("default_field: 0.05", "default_field: wide"))
        with self.assertRaisesRegex(YamlFileError, f"{path}:3: .*'wide'"):
            LoadOverlay(path)

    def test_invalid_yaml(self):
        path = self._Load(self.GOOD + "\n  - [unclosed\n")
        with self.assertRaisesRegex(YamlFileError, f"{path}:\\d+: invalid YAML"):
            LoadOverlay(path)

    def test_missing_file(self):
        with self.assertRaisesRegex(YamlFileError, "nowhere.yaml: no such file"):
            LoadOverlay("/nowhere.yaml")

    def test_bad_values_name_the_element_and_line(self):
        path = self._Load(
            self.GOOD.replace("end: [0.6, 0, 0], radius: 0.03", "end: [0.6, 0, 0], radius: -0.03")
        )
        line = next(i for i, text in enumerate(self.GOOD.splitlines(), 1) if "name: link2" in text)
        with self.assertRaisesRegex(
            ValueError, f"{path}:{line}: 'link2': radius must be > 0, got -0.03"
        ):
            LoadOverlay(path)
        path = self._Load(self.GOOD + "exclude:\n  - [link1, link9]\n")
        with self.assertRaisesRegex(ValueError, "'link9': exclusion names an unknown primitive"):
            LoadOverlay(path)
        path = self._Load(
            self.GOOD.replace(
                "direction: [1, 0, 0]}\n  - {name: elbow", "direction: [0, 0, 0]}\n  - {name: elbow"
            )
        )
        with self.assertRaisesRegex(ValueError, "'tip': direction must not be zero"):
            LoadOverlay(path)

    def test_unknown_link(self):
        path = self._Load(self.GOOD.replace("link: link3, shape", "link: link7, shape"))
        builder = DiagramBuilder()
        plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
        with self.assertRaisesRegex(ValueError, "'link3' is attached to unknown link 'link7'"):
            AddRobotWithOverlay(
                plant,
                scene_graph,
                model_file=MODELS / "three_link_arm.urdf",
                overlay_file=path,
                controlled_joints=["joint1"],
            )


if __name__ == "__main__":
    unittest.main()
