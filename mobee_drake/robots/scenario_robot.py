"""The robot of a scenario: the iCub (icub-models), a robot from a MoBeE XML file, or one from
a URDF or SDFormat file with its MoBeE overlay."""

import math
import re

from pydrake.geometry import SceneGraph
from pydrake.math import RigidTransform
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import ModelInstanceIndex

from mobee_drake.robots.assembly import WeldRootUnlessFixed
from mobee_drake.robots.icub import AddIcub, IcubConfig
from mobee_drake.robots.model_cache import PreparedIcubModel
from mobee_drake.robots.model_file import AddModelFileRobot, AddTintedModel, ModelFileConfig
from mobee_drake.robots.overlay import RobotOverlay
from mobee_drake.robots.zero_position import AddZeroPositionRobot, ZeroPositionConfig

RobotConfig = IcubConfig | ZeroPositionConfig | ModelFileConfig


def AddScenarioRobot(
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    config: RobotConfig,
    *,
    X_WRoot: RigidTransform | None = None,
    model_name: str | None = None,
    meshes: str = "light",
) -> tuple[RobotOverlay, list[str]]:
    """Adds the configured robot, its root at ``X_WRoot``, to an unfinalized plant; returns its
    overlay and the joints MoBeE controls. An iCub is drawn with its ``meshes`` (see
    :func:`~mobee_drake.robots.icub.AddIcub`)."""
    if isinstance(config, IcubConfig):
        overlay = AddIcub(plant, scene_graph, config, X_WRoot, meshes)
        return overlay, list(config.controlled_joints)
    if isinstance(config, ModelFileConfig):
        return AddModelFileRobot(plant, scene_graph, config, X_WRoot=X_WRoot, model_name=model_name)
    robot = config.Load()
    joints = config.Joints(robot)
    return AddZeroPositionRobot(
        plant, scene_graph, robot, controlled_joints=joints, X_WRoot=X_WRoot, model_name=model_name
    ), joints


def AddGhostRobot(
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    config: RobotConfig,
    alpha: float,
    meshes: str = "light",
) -> tuple[ModelInstanceIndex, dict[str, float]]:
    """Adds the robot's model alone to ``plant`` as the model instance "attractor", every visual
    drawn with opacity ``alpha`` (and an iCub with its ``meshes``), its root welded at the world's
    origin; returns the instance and the robot's home angles (radians)."""
    if isinstance(config, ModelFileConfig):
        instance, root = AddTintedModel(plant, scene_graph, config, alpha)
        home = config.Home()
    else:
        text, extension, root, home = _TintedModelText(config, alpha, meshes)
        (instance,) = Parser(plant, "attractor").AddModelsFromString(text, extension)
    plant.RenameModelInstance(instance, "attractor")
    WeldRootUnlessFixed(plant, instance, root, RigidTransform())
    return instance, home


def _TintedModelText(
    config: IcubConfig | ZeroPositionConfig, alpha: float, meshes: str
) -> tuple[str, str, str, dict[str, float]]:
    """The robot's model drawn with opacity ``alpha`` (for the attractor's ghost robot) and,
    for an iCub, its ``meshes``: its text, its format ("urdf" or "sdf"), its root link and its
    home angles (radians)."""
    if isinstance(config, IcubConfig):
        text = PreparedIcubModel(config.model, meshes).read_text()
        text = re.sub(
            r'rgba="([\d.]+) ([\d.]+) ([\d.]+) [\d.]+"', rf'rgba="\1 \2 \3 {alpha}"', text
        )
        # A model parsed from a string must name its meshes by URI.
        text = text.replace('filename="/', 'filename="file:///')
        home = {name: math.radians(v) for name, v in config.home_deg.items()}
        return text, "urdf", "root_link", home
    robot = config.Load()
    text = re.sub(
        r"<diffuse>([\d.]+) ([\d.]+) ([\d.]+) [\d.]+</diffuse>",
        rf"<diffuse>\1 \2 \3 {alpha}</diffuse>",
        robot.sdf,
    )
    return text, "sdf", "base", robot.home
