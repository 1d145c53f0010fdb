"""The iCub humanoid from icub-models in a MultibodyPlant, mounted on its pole.

As in the dissertation (ch. 2-8), the iCub stands on a pole: its ``root_link`` is welded to the
world. The joints MoBeE controls stay revolute; every other joint (by default the legs) is replaced
by a weld at its home angle, so the plant's positions are exactly the controlled joints.

The world frame is placed at the root link (the waist) unless told otherwise. The iCub's root
frame has x pointing backwards, y to the robot's right and z up: the robot faces -x.
"""

import dataclasses as dc
import math

from pydrake.geometry import SceneGraph
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant

from mobee_drake.resources import ResolveModelFile
from mobee_drake.robots.assembly import AddRobotWithOverlay
from mobee_drake.robots.model_cache import PreparedIcubModel
from mobee_drake.robots.overlay import RobotOverlay

DEFAULT_ICUB_MODEL = "iCubGazeboV2_5"

TORSO_JOINTS = ("torso_pitch", "torso_roll", "torso_yaw")
NECK_JOINTS = ("neck_pitch", "neck_roll", "neck_yaw")
ARM_JOINT_SUFFIXES = (
    "shoulder_pitch",
    "shoulder_roll",
    "shoulder_yaw",
    "elbow",
    "wrist_prosup",
    "wrist_pitch",
    "wrist_yaw",
)
RIGHT_ARM_JOINTS = tuple(f"r_{s}" for s in ARM_JOINT_SUFFIXES)
LEFT_ARM_JOINTS = tuple(f"l_{s}" for s in ARM_JOINT_SUFFIXES)
UPPER_BODY_JOINTS = TORSO_JOINTS + NECK_JOINTS + RIGHT_ARM_JOINTS + LEFT_ARM_JOINTS
# The shoulder and elbow of each arm: the joints of ch. 7-8's learning agents.
RIGHT_SHOULDER_ELBOW_JOINTS = RIGHT_ARM_JOINTS[:4]
LEFT_SHOULDER_ELBOW_JOINTS = LEFT_ARM_JOINTS[:4]

# The home posture of the original MoBeE iCub model (degrees): arms slightly forward and out, elbows
# bent; all other joints at zero. Joints not listed here start at zero.
HOME_POSTURE_DEG = {
    **{f"{side}_shoulder_pitch": -26.0 for side in "rl"},
    **{f"{side}_shoulder_roll": 20.0 for side in "rl"},
    **{f"{side}_elbow": 50.0 for side in "rl"},
}


@dc.dataclass
class IcubConfig:
    """Which iCub to load and which of its joints MoBeE controls."""

    # Any robot of the icub-models package (see ``IcubModelNames()``).
    model: str = DEFAULT_ICUB_MODEL
    # The controlled joints; every other joint is welded at its home angle.
    controlled_joints: list[str] = dc.field(default_factory=lambda: list(UPPER_BODY_JOINTS))
    # Home angles in degrees for joints that should not start at zero.
    home_deg: dict[str, float] = dc.field(default_factory=lambda: dict(HOME_POSTURE_DEG))
    # MoBeE's collision overlay: package://mobee_drake/..., a path, or a shipped model's name.
    overlay: str = "icub_overlay.yaml"


def AddIcub(
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    config: IcubConfig | None = None,
    X_WRoot: RigidTransform | None = None,
    meshes: str = "light",
) -> RobotOverlay:
    """Adds the iCub with its collision overlay to an unfinalized ``plant``, drawn with its
    ``meshes`` ("light", decimated for viewers, or "full"; see ``model_cache``).

    The root link is welded to the world at ``X_WRoot`` (identity by default); joints that are not
    in ``config.controlled_joints`` are welded at their home angles.

    Raises:
        ValueError: for an unknown model, an unknown joint name in ``config``, a home angle
            outside its joint's limits, or a malformed overlay file.
    """
    config = config or IcubConfig()
    return AddRobotWithOverlay(
        plant,
        scene_graph,
        model_file=PreparedIcubModel(config.model, meshes),
        overlay_file=ResolveModelFile(config.overlay),
        controlled_joints=config.controlled_joints,
        home={name: math.radians(value) for name, value in config.home_deg.items()},
        X_WRoot=X_WRoot,
        model_name=f"icub_{config.model}",
        model_source=f"robot (the iCub model {config.model})",
    )
