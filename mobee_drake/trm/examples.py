"""Two of the dissertation's roadmaps on the iCub: "Reach Into" (Fig. 3.8), "Raise a glass"
(Fig. 3.3).

Both search the torso and the right arm (10 joints) with the rest at home, biased toward the home
posture (h_home over the searched joints, weight 0.1), and spread the right palm over 3-D
workspace:

- **Reach Into**: an open box (a floor and four walls, 1 cm thick) stands in front of the right
  hand; the robot must not collide with it (h_collision) and the palm must stay in the box's
  inside (a user-defined term, :class:`MarkerInBox`), so the roadmap covers the inside of the box
  without touching it.
- **Raise a glass**: the hand's orientation is fixed as when holding a glass upright: the palm's
  normal toward the body's midline (world -y) and the hand's axis pointing forward (world -x),
  each within 10 degrees (two orientation terms of Table 3.1); the palm spreads over a region in
  front of the robot, above the table height.
"""

import dataclasses as dc

import numpy as np
from pydrake.geometry import Meshcat

from mobee_drake.ngik.costs import CollisionCost, HomeCost, MarkerInBox, MarkerOrientationCost
from mobee_drake.ngik.kinematic_model import KinematicModel
from mobee_drake.ngik.solver import IkProblem
from mobee_drake.robots.icub import RIGHT_ARM_JOINTS, TORSO_JOINTS, IcubConfig
from mobee_drake.trm.task_space import MarkerCoordinates, TaskSpace
from mobee_drake.world.objects import Box, SceneObject

JOINTS = list(TORSO_JOINTS + RIGHT_ARM_JOINTS)
HOME_WEIGHT = 0.1

# The open box of "Reach Into": inside 26 x 26 cm, 14 cm deep, walls 1 cm (root frame: x back,
# y right, z up; the right palm rests near (-0.31, 0.14, 0.01)).
BOX_CENTRE = np.array([-0.33, 0.17])
BOX_INSIDE = 0.26
BOX_FLOOR, BOX_RIM = -0.14, 0.0
WALL = 0.01


def OpenBox() -> list[SceneObject]:
    cx, cy = BOX_CENTRE
    half, height = BOX_INSIDE / 2 + WALL / 2, BOX_RIM - BOX_FLOOR
    zc = (BOX_FLOOR + BOX_RIM) / 2
    outer = BOX_INSIDE + 2 * WALL
    return [
        SceneObject(
            name="box_floor",
            shape=Box(size=[outer, outer, WALL]),
            position=[cx, cy, BOX_FLOOR - WALL / 2],
        ),
        SceneObject(
            name="box_front", shape=Box(size=[WALL, outer, height]), position=[cx - half, cy, zc]
        ),
        SceneObject(
            name="box_back", shape=Box(size=[WALL, outer, height]), position=[cx + half, cy, zc]
        ),
        SceneObject(
            name="box_left", shape=Box(size=[outer, WALL, height]), position=[cx, cy - half, zc]
        ),
        SceneObject(
            name="box_right", shape=Box(size=[outer, WALL, height]), position=[cx, cy + half, zc]
        ),
    ]


@dc.dataclass
class TrmExample:
    """A roadmap problem: the model, the costs, the task space and where to begin."""

    name: str
    model: KinematicModel
    problem: IkProblem
    task_space: TaskSpace
    q_init: np.ndarray
    marker: int  # the marker whose positions show the roadmap


def _Home(model: KinematicModel) -> HomeCost:
    return HomeCost(
        model.home, joints=np.array([model.JointIndex(j) for j in JOINTS]), weight=HOME_WEIGHT
    )


def ReachInto(meshcat: Meshcat | None = None) -> TrmExample:
    model = KinematicModel(IcubConfig(), OpenBox(), meshcat=meshcat)
    palm = model.MarkerIndex("r_palm")
    # The palm stays 3 cm inside the walls and floor, up to the rim.
    inside = BOX_INSIDE / 2 - 0.03
    lower = np.array([*(BOX_CENTRE - inside), BOX_FLOOR + 0.03])
    upper = np.array([*(BOX_CENTRE + inside), BOX_RIM])
    terms = [_Home(model), CollisionCost(), MarkerInBox(palm, lower, upper, weight=10.0)]
    problem = IkProblem(model, terms, joints=JOINTS)
    return TrmExample(
        "reach_into", model, problem, TaskSpace((MarkerCoordinates(palm),)), model.home, palm
    )


def RaiseAGlass(meshcat: Meshcat | None = None) -> TrmExample:
    model = KinematicModel(IcubConfig(), meshcat=meshcat)
    palm, hand = model.MarkerIndex("r_palm"), model.MarkerIndex("r_hand")
    terms = [
        _Home(model),
        CollisionCost(),
        MarkerOrientationCost(palm, np.array([0.0, -1.0, 0.0])),
        MarkerOrientationCost(hand, np.array([-1.0, 0.0, 0.0])),
        MarkerInBox(
            palm, np.array([-0.45, 0.0, -0.05]), np.array([-0.15, 0.35, 0.25]), weight=10.0
        ),
    ]
    problem = IkProblem(model, terms, joints=JOINTS)
    return TrmExample(
        "raise_a_glass", model, problem, TaskSpace((MarkerCoordinates(palm),)), model.home, palm
    )


EXAMPLES = {"reach_into": ReachInto, "raise_a_glass": RaiseAGlass}
