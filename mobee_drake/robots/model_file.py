"""A robot of one's own in a scenario: a URDF or SDFormat file and its MoBeE overlay.

Drake's parser reads the model, so everything it accepts works: meshes and other files named by
``package://`` URIs resolve through ``resources.MobeePackageMap`` (this package's
``package://mobee_drake/``, plus every package on ``ROS_PACKAGE_PATH``). The overlay (a YAML file,
see ``docs/overlay.md``) gives MoBeE its shapes, markers and constraints. The shipped example is
the planar three-link arm of ``models/three_link_arm.urdf`` (``diagrams/three_link_arm.yaml``).

A scenario file names both files by ``package://`` URI, by absolute path, or by a path relative
to the scenario file's folder (``LoadScenario`` makes it absolute); in Python, a relative path is
relative to the current folder.
"""

import dataclasses as dc
import math

from pydrake.geometry import IllustrationProperties, Rgba, RoleAssign, SceneGraph
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import ModelInstanceIndex

from mobee_drake.resources import MobeePackageMap, ResolveModelPath
from mobee_drake.robots.assembly import AddRobotWithOverlay, ModelParser
from mobee_drake.robots.overlay import LoadOverlay, RobotOverlay

# The colour of a visual without one of its own (Drake's default grey).
_DEFAULT_DIFFUSE = (0.9, 0.9, 0.9)


@dc.dataclass
class ModelFileConfig:
    """A robot from a URDF or SDFormat file and its MoBeE overlay (docs/tutorial.md, section 6)."""

    # The model: a package:// URI, an absolute path, or a path relative to the scenario's folder.
    file: str = "package://mobee_drake/three_link_arm.urdf"
    # Its MoBeE overlay (a YAML file, docs/overlay.md), named like the model.
    overlay: str = "package://mobee_drake/three_link_arm_overlay.yaml"
    # The controlled joints; empty: every joint that moves. The others are welded at home.
    controlled_joints: list[str] = dc.field(default_factory=list)
    # Home angles in degrees for joints that should not start at zero.
    home_deg: dict[str, float] = dc.field(default_factory=dict)

    def Home(self) -> dict[str, float]:
        """The home angles in radians."""
        return {name: math.radians(value) for name, value in self.home_deg.items()}


def MovingJoints(config: ModelFileConfig) -> list[str]:
    """The joints MoBeE controls: the configured ones, or every joint of the model that moves."""
    if config.controlled_joints:
        return list(config.controlled_joints)
    scratch = MultibodyPlant(0.0)
    (instance,) = ModelParser(scratch, None, MobeePackageMap()).AddModels(
        str(ResolveModelPath(config.file))
    )
    return [
        scratch.get_joint(i).name()
        for i in scratch.GetJointIndices(instance)
        if scratch.get_joint(i).num_positions() > 0
    ]


def AddModelFileRobot(
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    config: ModelFileConfig,
    *,
    X_WRoot: RigidTransform | None = None,
    model_name: str | None = None,
) -> tuple[RobotOverlay, list[str]]:
    """Adds the robot of ``config`` to an unfinalized plant, its overlay's reference link at
    ``X_WRoot``; returns its overlay and the joints MoBeE controls."""
    model = ResolveModelPath(config.file)
    overlay = ResolveModelPath(config.overlay)
    joints = MovingJoints(config)
    robot = AddRobotWithOverlay(
        plant,
        scene_graph,
        model_file=model,
        overlay_file=overlay,
        controlled_joints=joints,
        home=config.Home(),
        X_WRoot=X_WRoot,
        model_name=model_name,
        package_map=MobeePackageMap(),
        model_source=config.file,
    )
    return robot, joints


def AddTintedModel(
    plant: MultibodyPlant, scene_graph: SceneGraph, config: ModelFileConfig, alpha: float
) -> tuple[ModelInstanceIndex, str]:
    """Adds the robot's model alone (no overlay) to ``plant``, every visual drawn with opacity
    ``alpha``; returns its instance and its overlay's reference link."""
    (instance,) = ModelParser(plant, "attractor", MobeePackageMap()).AddModels(
        str(ResolveModelPath(config.file))
    )
    source = plant.get_source_id()
    inspector = scene_graph.model_inspector()
    for index in plant.GetBodyIndices(instance):
        for geometry in plant.GetVisualGeometriesForBody(plant.get_body(index)):
            old = inspector.GetIllustrationProperties(geometry)
            rgba = old.GetPropertyOrDefault("phong", "diffuse", Rgba(*_DEFAULT_DIFFUSE))
            properties = IllustrationProperties(old)
            properties.UpdateProperty("phong", "diffuse", Rgba(rgba.r(), rgba.g(), rgba.b(), alpha))
            scene_graph.AssignRole(source, geometry, properties, RoleAssign.kReplace)
    return instance, LoadOverlay(ResolveModelPath(config.overlay)).reference_link
