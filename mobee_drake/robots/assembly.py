"""Turns a parsed robot into the robot MoBeE controls: uncontrolled joints become welds."""

from collections.abc import Iterable, Mapping

import numpy as np
from pydrake.common.eigen_geometry import AngleAxis
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import ModelInstanceIndex, RevoluteJoint


def FreezeJoints(plant: MultibodyPlant, instance: ModelInstanceIndex, *, keep: Iterable[str],
                 home: Mapping[str, float], source: str) -> None:
    """Welds every joint of ``instance`` not named in ``keep`` at its ``home`` angle (radians).

    The kept joints get their ``home`` angle as default position. Must be called before
    ``plant.Finalize()``.

    Raises:
        ValueError: naming ``source`` and the joint, for a name in ``keep`` or ``home`` that the
            model does not have, a kept joint that is not revolute, or a home angle outside the
            joint's limits.
    """
    keep = list(keep)
    joints = {plant.get_joint(i).name(): plant.get_joint(i)
              for i in plant.GetJointIndices(instance)}
    movable = sorted(n for n, j in joints.items() if j.num_positions() > 0)
    for name in list(keep) + list(home):
        if name not in joints or joints[name].num_positions() == 0:
            raise ValueError(f"{source}: unknown joint '{name}'; its joints are: "
                             + ", ".join(movable))
    if len(set(keep)) != len(keep):
        raise ValueError(f"{source}: controlled joints listed twice in {keep}")
    for name, angle in home.items():
        joint = joints[name]
        lower, upper = joint.position_lower_limits()[0], joint.position_upper_limits()[0]
        if not (np.isfinite(angle) and lower <= angle <= upper):
            raise ValueError(
                f"{source}: home angle of joint '{name}' is {np.degrees(angle):.6g} deg, outside "
                f"its limits [{np.degrees(lower):.6g}, {np.degrees(upper):.6g}] deg")
    for name in movable:
        joint = joints[name]
        if name in keep and not isinstance(joint, RevoluteJoint):
            raise ValueError(f"{source}: joint '{name}' is a {joint.type_name()} joint; MoBeE "
                             "controls revolute joints only")
        lower, upper = joint.position_lower_limits()[0], joint.position_upper_limits()[0]
        # A joint without a home angle starts at zero, or at the limit nearest to zero.
        angle = home.get(name, float(np.clip(0.0, lower, upper)))
        if name in keep:
            joint.set_default_angle(angle)
            continue
        frame_on_parent, frame_on_child = joint.frame_on_parent(), joint.frame_on_child()
        X_FM = RigidTransform(AngleAxis(angle, joint.revolute_axis()), np.zeros(3))
        plant.RemoveJoint(joint)
        plant.WeldFrames(frame_on_parent, frame_on_child, X_FM)
