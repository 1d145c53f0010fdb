"""Lever arms bounded over every configuration: how fast a point fixed in a body can move per
unit velocity of each plant joint, whatever the other joints do.

A revolute joint moves a point p at ``|w x (p - a)| <= |p - a|`` per rad/s, for a point a of its
axis. Up the kinematic chain from p's body to the joint, the distance ``|p - a|`` is at most the
sum of the chain's rigid segments: from p to the origin of its body's inboard joint, across each
joint (nothing for a revolute joint, whose two frames share their origin on the axis; the fixed
offset of a weld; the offset plus the travel of a prismatic joint), and from each joint's parent
frame to the origin of the joint above it (both fixed in one body). A prismatic joint moves every
point downstream at 1 m/s per m/s.
"""

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import BodyIndex, Joint, PrismaticJoint, RevoluteJoint, WeldJoint


def _Origin(frame, context) -> np.ndarray:
    return frame.CalcPoseInWorld(context).translation()


def _Crossing(joint: Joint, context) -> float:
    """The largest distance (m) between the origins of the joint's two frames."""
    if isinstance(joint, RevoluteJoint):
        return 0.0
    offset = float(
        np.linalg.norm(
            _Origin(joint.frame_on_child(), context) - _Origin(joint.frame_on_parent(), context)
        )
    )
    if isinstance(joint, WeldJoint):
        return offset
    if isinstance(joint, PrismaticJoint):
        return offset + max(abs(joint.position_lower_limit()), abs(joint.position_upper_limit()))
    raise ValueError(
        f"MoBeE's safety barrier: joint '{joint.name()}' ({joint.type_name()}) is neither "
        "revolute, prismatic nor welded"
    )


def LeverBounds(
    plant: MultibodyPlant,
    velocities: np.ndarray,
    bodies: list[int],
    points_B: list[np.ndarray],
    radii: np.ndarray,
) -> np.ndarray:
    """(G, r): for each of G solids (balls of ``radii[g]`` around the points ``points_B[g]``
    (m, 3), fixed in body ``bodies[g]``), the largest speed (m/s) of any of their points per
    unit of each plant velocity in ``velocities`` (r), over every configuration; 0 where the
    velocity does not move the body."""
    context = plant.CreateDefaultContext()
    inboard = {}
    for index in plant.GetJointIndices():
        joint = plant.get_joint(index)
        inboard[int(joint.child_body().index())] = joint
    column = {int(v): c for c, v in enumerate(velocities)}
    bounds = np.zeros((len(bodies), len(velocities)))
    for g, (body, points) in enumerate(zip(bodies, points_B)):
        chain = []  # the joints from the body up to the highest one with a column
        joint = inboard.get(body)
        while joint is not None:
            chain.append(joint)
            joint = inboard.get(int(joint.parent_body().index()))
        columns = [
            [column[v] for v in range(j.velocity_start(), j.velocity_start() + j.num_velocities())
             if v in column]
            for j in chain
        ]  # fmt: skip
        while chain and not columns[-1]:
            chain.pop(), columns.pop()
        if not chain:
            continue
        frame = plant.get_body(BodyIndex(body)).body_frame()
        p_W = frame.CalcPoseInWorld(context).multiply(np.asarray(points).T).T
        reach = np.linalg.norm(p_W - _Origin(chain[0].frame_on_child(), context), axis=1).max()
        reach += radii[g]
        for i, joint in enumerate(chain):
            prismatic = isinstance(joint, PrismaticJoint)
            bounds[g, columns[i]] = 1.0 if prismatic else reach
            if i + 1 < len(chain):  # across the joint, then up its parent body
                reach += _Crossing(joint, context) + np.linalg.norm(
                    _Origin(joint.frame_on_parent(), context)
                    - _Origin(chain[i + 1].frame_on_child(), context)
                )
    return bounds
