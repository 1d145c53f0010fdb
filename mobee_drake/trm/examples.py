"""The dissertation's one-hand roadmaps on the iCub (ch. 3.4): "Reach Into" (Fig. 3.8), "Raise a
glass" (Fig. 3.3), the elbow kept down (Fig. 3.1, right), the palm to the side and down (Fig.
3.2) and "Inspect" (Fig. 3.5); the two-hand ones are in :mod:`mobee_drake.trm.bimanual`.

All search the torso and the right arm (10 joints) with the rest at home, biased toward the home
posture (h_home over the searched joints, weight 0.1). The source describes each task in a
sentence and gives no numbers; ours (a height, a point, a spacing) are in each function's
docstring.

- **Reach Into**: an open box (a floor and four walls, 1 cm thick) stands in front of the right
  hand; the robot must not collide with it (h_collision) and the palm must stay in the box's
  inside (a user-defined term, :class:`MarkerInBox`), so the roadmap covers the inside of the box
  without touching it.
- **Raise a glass**: the hand's orientation is fixed as when holding a glass upright: the palm's
  normal toward the body's midline (world -y) and the hand's axis pointing forward (world -x),
  each within 10 degrees (two orientation terms of Table 3.1); the palm spreads over a region in
  front of the robot, above the table height.
"""

from collections.abc import Callable
import dataclasses as dc

import numpy as np
from pydrake.geometry import Meshcat

from mobee_drake.ngik.costs import (
    CollisionCost,
    HomeCost,
    MarkerInBox,
    MarkerOrientationCost,
    MarkerPositionCost,
)
from mobee_drake.ngik.kinematic_model import KinematicModel
from mobee_drake.ngik.nes import NesConfig
from mobee_drake.ngik.solver import IkProblem, SolveNgik
from mobee_drake.robots.icub import RIGHT_ARM_JOINTS, TORSO_JOINTS, IcubConfig
from mobee_drake.trm.task_space import MarkerAngle, MarkerCoordinates, TaskSpace
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
    spacing: float = 0.03  # d of eq. 3.6 in the task space's units (m, or rad for angles)
    sigma: float = 0.15  # NES's spread around an expanding vertex (rad): small for tight tasks


def HomeBias(model: KinematicModel, joints=JOINTS) -> HomeCost:
    """h_home over ``joints`` with the weak weight HOME_WEIGHT: a bias, never a requirement."""
    return HomeCost(
        model.home, joints=np.array([model.JointIndex(j) for j in joints]), weight=HOME_WEIGHT
    )


def HeightBand(marker: int, low: float, high: float) -> MarkerInBox:
    """The marker's height kept in [low, high] (m, root frame), anywhere across."""
    return MarkerInBox(
        marker, np.array([-np.inf, -np.inf, low]), np.array([np.inf, np.inf, high]), weight=10.0
    )


# NGIK's search for a first vertex when home does not meet a task's terms.
START_SEARCH = NesConfig(variant="snes", max_evaluations=6000, target_cost=-1.0)


def StartPose(problem: IkProblem, seed: int = 0) -> np.ndarray:
    """A pose meeting the problem's terms found by NGIK from home (Alg. 4 grows a roadmap from
    a valid vertex); RuntimeError naming the terms not met if the search fails."""
    model = problem.model
    solution = SolveNgik(problem, model.home, 0.3, START_SEARCH, np.random.default_rng(seed))
    if not solution.solved:
        evaluation, _ = problem.Evaluate(problem.SearchVector(solution.q))
        unmet = [type(t).__name__ for t in problem.terms if t(evaluation) > t.tolerance]
        raise RuntimeError(f"TRM: no start pose meets the task's terms {unmet}")
    return solution.q


def ReachInto(meshcat: Meshcat | None = None) -> TrmExample:
    model = KinematicModel(IcubConfig(), OpenBox(), meshcat=meshcat)
    palm = model.MarkerIndex("r_palm")
    # The palm stays 3 cm inside the walls and floor, up to the rim.
    inside = BOX_INSIDE / 2 - 0.03
    lower = np.array([*(BOX_CENTRE - inside), BOX_FLOOR + 0.03])
    upper = np.array([*(BOX_CENTRE + inside), BOX_RIM])
    terms = [HomeBias(model), CollisionCost(), MarkerInBox(palm, lower, upper, weight=10.0)]
    problem = IkProblem(model, terms, joints=JOINTS)
    return TrmExample(
        "reach_into", model, problem, TaskSpace((MarkerCoordinates(palm),)), model.home, palm
    )


def RaiseAGlass(meshcat: Meshcat | None = None) -> TrmExample:
    model = KinematicModel(IcubConfig(), meshcat=meshcat)
    palm, hand = model.MarkerIndex("r_palm"), model.MarkerIndex("r_hand")
    terms = [
        HomeBias(model),
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


def _RightPalmTask(
    name: str,
    terms: Callable[[KinematicModel], list],
    task: Callable[[KinematicModel], tuple],
    spacing: float,
    meshcat: Meshcat | None,
) -> TrmExample:
    """A one-hand roadmap of the right palm: the home bias, no collision and ``terms``."""
    model = KinematicModel(IcubConfig(), meshcat=meshcat)
    problem = IkProblem(model, [HomeBias(model), CollisionCost(), *terms(model)], joints=JOINTS)
    return TrmExample(
        name,
        model,
        problem,
        TaskSpace(task(model)),
        StartPose(problem),
        model.MarkerIndex("r_palm"),
        spacing,
    )


def ElbowDown(meshcat: Meshcat | None = None) -> TrmExample:
    """Fig. 3.1, right: the elbow kept down (the r_elbow marker no higher than at home, 4.2 cm)
    while the palm spreads over the 3-D workspace."""
    return _RightPalmTask(
        "elbow_down",
        lambda m: [HeightBand(m.MarkerIndex("r_elbow"), -np.inf, 0.042)],
        lambda m: (MarkerCoordinates(m.MarkerIndex("r_palm")),),
        0.03,
        meshcat,
    )


def PalmToTheSide(meshcat: Meshcat | None = None) -> TrmExample:
    """Fig. 3.2, left: the palm's normal toward the midline (world -y, within 10 degrees), the
    palm within 5 cm of its home height (1.3 cm), spread left/right and forward/back."""
    return _RightPalmTask(
        "palm_to_the_side",
        lambda m: [
            MarkerOrientationCost(m.MarkerIndex("r_palm"), np.array([0.0, -1.0, 0.0])),
            HeightBand(m.MarkerIndex("r_palm"), -0.037, 0.063),
        ],
        lambda m: (MarkerCoordinates(m.MarkerIndex("r_palm"), (0, 1)),),
        0.03,
        meshcat,
    )


def PalmDown(meshcat: Meshcat | None = None) -> TrmExample:
    """Fig. 3.2, right: the palm's normal down (world -z), otherwise as palm_to_the_side."""
    return _RightPalmTask(
        "palm_down",
        lambda m: [
            MarkerOrientationCost(m.MarkerIndex("r_palm"), np.array([0.0, 0.0, -1.0])),
            HeightBand(m.MarkerIndex("r_palm"), -0.037, 0.063),
        ],
        lambda m: (MarkerCoordinates(m.MarkerIndex("r_palm"), (0, 1)),),
        0.03,
        meshcat,
    )


# Where "Inspect" holds the hand: 25 cm in front of the head marker, 13 cm below it (m, root).
INSPECT_POINT = np.array([-0.25, 0.05, 0.23])


def Inspect(meshcat: Meshcat | None = None) -> TrmExample:
    """Fig. 3.5: the palm held at :data:`INSPECT_POINT` (1 cm), the task space the angle between
    its normal and the direction back toward the eyes (world +x; the gaze at home is -x), so the
    map turns the hand in front of the eyes; spacing 0.1 rad."""
    return _RightPalmTask(
        "inspect",
        lambda m: [MarkerPositionCost(m.MarkerIndex("r_palm"), INSPECT_POINT)],
        lambda m: (MarkerAngle(m.MarkerIndex("r_palm"), (1.0, 0.0, 0.0)),),
        0.1,
        meshcat,
    )
