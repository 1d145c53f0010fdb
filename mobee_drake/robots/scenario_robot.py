"""The robot of a scenario: the iCub (icub-models) or a robot from a MoBeE XML file."""

import math
import re

from pydrake.geometry import SceneGraph
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant

from mobee_drake.robots.icub import AddIcub, IcubConfig
from mobee_drake.robots.model_cache import PreparedIcubModel
from mobee_drake.robots.overlay import RobotOverlay
from mobee_drake.robots.zero_position import AddZeroPositionRobot, ZeroPositionConfig

RobotConfig = IcubConfig | ZeroPositionConfig


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
    robot = config.Load()
    joints = config.Joints(robot)
    return AddZeroPositionRobot(
        plant, scene_graph, robot, controlled_joints=joints, X_WRoot=X_WRoot, model_name=model_name
    ), joints


def RobotModelText(
    config: RobotConfig, alpha: float, meshes: str = "light"
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
