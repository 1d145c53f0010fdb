"""Adds a robot for MoBeE to a plant: root welded, uncontrolled joints welded, overlay applied."""

from collections.abc import Callable, Iterable, Mapping
import dataclasses as dc
import pathlib

import numpy as np
from pydrake.common.eigen_geometry import AngleAxis
from pydrake.geometry import SceneGraph
from pydrake.math import RigidTransform
from pydrake.multibody.parsing import PackageMap, Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import ModelInstanceIndex, RevoluteJoint

from mobee_drake.robots.couplings import Followers, JointCoupling
from mobee_drake.robots.overlay import (
    ApplyOverlay,
    LoadOverlay,
    Overlay,
    RobotOverlay,
    ZeroConfigurationPoses,
)


def ModelParser(
    plant: MultibodyPlant, model_name: str | None, package_map: PackageMap | None = None
) -> Parser:
    """Drake's parser for ``plant`` (models named ``model_name``), resolving ``package://`` URIs
    with ``package_map`` besides its own."""
    parser = Parser(plant, model_name)
    if package_map is not None:
        parser.package_map().AddMap(package_map)
    return parser


def AddRobotWithOverlay(
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    *,
    model_file: str | pathlib.Path,
    overlay_file: str | pathlib.Path,
    controlled_joints: Iterable[str],
    home: Mapping[str, float] | None = None,
    X_WRoot: RigidTransform | None = None,
    model_name: str | None = None,
    couplings: tuple[JointCoupling, ...] = (),
    model_source: str | None = None,
    package_map: PackageMap | None = None,
) -> RobotOverlay:
    """Adds the robot of ``model_file`` (URDF or SDFormat) with its MoBeE overlay to ``plant``.

    The overlay's ``reference_link`` is the robot's root: unless the model already fixes it, it is
    welded to the world at ``X_WRoot``. Joints not in ``controlled_joints`` are welded at their
    ``home`` angle (radians, zero by default), but for those that follow a controlled joint by
    ``couplings`` (one motor driving several joints). The parser resolves the model's
    ``package://`` URIs with ``package_map`` besides its own. Must be called before
    ``plant.Finalize()``.

    Raises:
        ValueError: naming the file (or ``model_source``: what the user named, where the file is
            one we made) and the element, for unknown joints or links, home angles outside their
            limits, or a malformed overlay.
    """
    model_file = str(model_file)

    return AddModelWithOverlay(
        plant,
        scene_graph,
        add_model=lambda p: ModelParser(p, model_name, package_map).AddModels(model_file)[0],
        overlay=LoadOverlay(overlay_file),
        controlled_joints=controlled_joints,
        home=home,
        X_WRoot=X_WRoot,
        model_source=model_source or model_file,
        overlay_source=str(overlay_file),
        couplings=couplings,
    )


def AddModelWithOverlay(
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    *,
    add_model: Callable[[MultibodyPlant], ModelInstanceIndex],
    overlay: Overlay,
    controlled_joints: Iterable[str],
    home: Mapping[str, float] | None,
    X_WRoot: RigidTransform | None,
    model_source: str,
    overlay_source: str,
    couplings: tuple[JointCoupling, ...] = (),
) -> RobotOverlay:
    """:func:`AddRobotWithOverlay` for a model that ``add_model(plant)`` adds (to the plant and to
    the scratch plant that finds the links' poses at zero) and an overlay already loaded; the
    joints that follow a controlled one by ``couplings`` move with it (they are not welded)."""
    instance = add_model(plant)
    if not plant.HasBodyNamed(overlay.reference_link, instance):
        raise ValueError(
            f"{overlay_source}: reference_link '{overlay.reference_link}' is not a "
            f"link of {model_source}"
        )
    WeldRootUnlessFixed(plant, instance, overlay.reference_link, X_WRoot or RigidTransform())
    reference = ZeroConfigurationPoses(add_model, overlay.reference_link)
    controlled_joints = list(controlled_joints)
    followers = Followers(couplings, controlled_joints, model_source)
    frozen = FreezeJoints(
        plant,
        instance,
        keep=controlled_joints + [c.follower for c in followers],
        home=home or {},
        source=model_source,
    )
    robot = ApplyOverlay(
        plant,
        scene_graph,
        instance,
        overlay,
        reference,
        frozen_joints=frozen,
        source=overlay_source,
    )
    return dc.replace(robot, couplings=tuple(followers))


def WeldRootUnlessFixed(
    plant: MultibodyPlant, instance: ModelInstanceIndex, root: str, X_WRoot: RigidTransform
) -> None:
    """Welds the body ``root`` of ``instance`` to the world at ``X_WRoot``, unless the model
    already attaches it by a joint of its own."""
    body = plant.GetBodyByName(root, instance)
    if not any(
        plant.get_joint(j).child_body().index() == body.index()
        for j in plant.GetJointIndices(instance)
    ):
        plant.WeldFrames(plant.world_frame(), body.body_frame(), X_WRoot)


def FreezeJoints(
    plant: MultibodyPlant,
    instance: ModelInstanceIndex,
    *,
    keep: Iterable[str],
    home: Mapping[str, float],
    source: str,
) -> dict[str, float]:
    """Welds every joint of ``instance`` not named in ``keep`` at its ``home`` angle (radians).

    The kept joints get their ``home`` angle as default position and an actuator (if the model
    has none), for the dynamic robot's controllers. Must be called before ``plant.Finalize()``.

    Returns:
        The angle (radians) at which each welded joint was frozen.

    Raises:
        ValueError: naming ``source`` and the joint, for a name in ``keep`` or ``home`` that the
            model does not have, a kept joint that is not revolute, or a home angle outside the
            joint's limits.
    """
    keep = list(keep)
    joints = {
        plant.get_joint(i).name(): plant.get_joint(i) for i in plant.GetJointIndices(instance)
    }
    movable = sorted(n for n, j in joints.items() if j.num_positions() > 0)
    for name in list(keep) + list(home):
        if name not in joints or joints[name].num_positions() == 0:
            raise ValueError(
                f"{source}: unknown joint '{name}'; its joints are: " + ", ".join(movable)
            )
    if len(set(keep)) != len(keep):
        raise ValueError(f"{source}: controlled joints listed twice in {keep}")
    for name, angle in home.items():
        joint = joints[name]
        lower, upper = joint.position_lower_limits()[0], joint.position_upper_limits()[0]
        if not (np.isfinite(angle) and lower <= angle <= upper):
            raise ValueError(
                f"{source}: home angle of joint '{name}' is {np.degrees(angle):.6g} deg, outside "
                f"its limits [{np.degrees(lower):.6g}, {np.degrees(upper):.6g}] deg"
            )
    frozen = {}
    for name in movable:
        joint = joints[name]
        if name in keep and not isinstance(joint, RevoluteJoint):
            raise ValueError(
                f"{source}: joint '{name}' is a {joint.type_name()} joint; MoBeE "
                "controls revolute joints only"
            )
        lower, upper = joint.position_lower_limits()[0], joint.position_upper_limits()[0]
        # A joint without a home angle starts at zero, or at the limit nearest to zero.
        angle = home.get(name, float(np.clip(0.0, lower, upper)))
        if name in keep:
            joint.set_default_angle(angle)
            if not any(
                plant.get_joint_actuator(a).joint().index() == joint.index()
                for a in plant.GetJointActuatorIndices(instance)
            ):
                plant.AddJointActuator(f"{name}_actuator", joint)
            continue
        frame_on_parent, frame_on_child = joint.frame_on_parent(), joint.frame_on_child()
        X_FM = RigidTransform(AngleAxis(angle, joint.revolute_axis()), np.zeros(3))
        plant.RemoveJoint(joint)
        plant.WeldFrames(frame_on_parent, frame_on_child, X_FM)
        frozen[name] = angle
    return frozen
