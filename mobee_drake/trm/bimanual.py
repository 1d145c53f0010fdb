"""The dissertation's two-hand roadmaps on the iCub (ch. 3.4, Fig. 3.1, 3.4, 3.6, 3.7, 3.9-3.11).

Each searches the torso and both arms (17 joints; "Bimanual Inspect" also the neck), biased
toward home, with no collision pair. The source names what each task constrains and what its
task space is, in a sentence and a figure; the numbers are ours and are in each docstring. The
hands "hold" an object when their palms are a fixed distance apart (:data:`HOLD`, Table 3.1's
two-hand term) and face each other (:class:`~mobee_drake.ngik.costs.OpposedDirections`).
Positions are in the robot's root frame (x back, y right, z up; at home the palms are at
(-0.31, +-0.14, 0.01) facing each other, the gaze along -x).
"""

from collections.abc import Callable

import numpy as np
from pydrake.geometry import Meshcat

from mobee_drake.ngik.costs import (
    CollisionCost,
    MarkerOrientationCost,
    MarkerPositionCost,
    OpposedDirections,
    TwoHandHoldCost,
)
from mobee_drake.ngik.kinematic_model import KinematicModel
from mobee_drake.ngik.solver import IkProblem
from mobee_drake.robots.icub import (
    LEFT_ARM_JOINTS,
    NECK_JOINTS,
    RIGHT_ARM_JOINTS,
    TORSO_JOINTS,
    IcubConfig,
)
from mobee_drake.trm.examples import HeightBand, HomeBias, StartPose, TrmExample
from mobee_drake.trm.task_space import MarkerAlong, MarkerCoordinates, MarkerHeading, TaskSpace

JOINTS = list(TORSO_JOINTS + RIGHT_ARM_JOINTS + LEFT_ARM_JOINTS)
# The distance between the palms of a held object (m).
HOLD = 0.25
# The palms' height band of the pushing tasks (m): around their height at home.
PUSH_HEIGHT = (-0.01, 0.04)
# Where Bimanual Inspect and the torso map hold the hands: the palms' points, facing each other.
HELD_AT = np.array([-0.25, 0.0, 0.08])
# Unscrew: the left palm holds the bottle, the right palm is on the cap above it.
BOTTLE, CAP = np.array([-0.26, 0.02, -0.02]), np.array([-0.26, 0.06, 0.1])

# NES's spread around an expanding vertex (rad): with both hands placed, 0.15 rad (the one-hand
# maps') rarely lands back within the terms' tolerances in 800 evaluations.
SIGMA = 0.05

Terms = Callable[[KinematicModel, int, int], list]


def _Hold(model: KinematicModel, right: int, left: int) -> list:
    return [TwoHandHoldCost(left, right, HOLD), OpposedDirections(left, right)]


def _TwoHandTask(
    name: str,
    terms: Terms,
    task: Callable[[KinematicModel], tuple],
    spacing: float,
    meshcat: Meshcat | None,
    joints: list[str] = JOINTS,
) -> TrmExample:
    """A two-hand roadmap: the home bias, no collision and ``terms(model, right, left)`` (the
    palms' marker indices)."""
    model = KinematicModel(IcubConfig(), meshcat=meshcat)
    right, left = model.MarkerIndex("r_palm"), model.MarkerIndex("l_palm")
    problem = IkProblem(
        model,
        [HomeBias(model, joints), CollisionCost(), *terms(model, right, left)],
        joints=joints,
    )
    return TrmExample(
        name, model, problem, TaskSpace(task(model)), StartPose(problem), right, spacing, SIGMA
    )


def _Facing(right: int, left: int, direction) -> list:
    """Both palms' normals along ``direction`` (pushing with both palms)."""
    return [
        MarkerOrientationCost(right, np.asarray(direction, dtype=float)),
        MarkerOrientationCost(left, np.asarray(direction, dtype=float)),
    ]


def Carry(meshcat: Meshcat | None = None) -> TrmExample:
    """Fig. 3.1, left: the hands hold an object (25 cm apart, palms facing each other); the task
    space is the right palm's forward/back and up/down; spacing 3 cm."""
    return _TwoHandTask(
        "carry",
        _Hold,
        lambda m: (MarkerCoordinates(m.MarkerIndex("r_palm"), (0, 2)),),
        0.03,
        meshcat,
    )


def _HeldInFront(model: KinematicModel, right: int, left: int) -> list:
    """Both palms at fixed points around :data:`HELD_AT`, facing each other."""
    offset = np.array([0.0, HOLD / 2, 0.0])
    return [
        MarkerPositionCost(right, HELD_AT + offset),
        MarkerPositionCost(left, HELD_AT - offset),
        MarkerOrientationCost(right, np.array([0.0, -1.0, 0.0])),
        MarkerOrientationCost(left, np.array([0.0, 1.0, 0.0])),
    ]


def TorsoOverHeldHands(meshcat: Meshcat | None = None) -> TrmExample:
    """Fig. 3.1, centre: both hands fixed (:func:`_HeldInFront`), the task space the top of the
    torso left/right and forward/back. The overlay has no marker on the torso; with the neck at
    home the head marker moves with the torso's top, so its (x, y) stands for it; spacing 2 cm."""
    return _TwoHandTask(
        "torso_over_held_hands",
        _HeldInFront,
        lambda m: (MarkerCoordinates(m.MarkerIndex("head"), (0, 1)),),
        0.02,
        meshcat,
    )


def BimanualInspect(meshcat: Meshcat | None = None) -> TrmExample:
    """Fig. 3.4: both hands fixed as in :func:`TorsoOverHeldHands`, the neck searched too, the
    task space the head marker's position (the head moves around the held object); 2 cm."""
    return _TwoHandTask(
        "bimanual_inspect",
        _HeldInFront,
        lambda m: (MarkerCoordinates(m.MarkerIndex("head")),),
        0.02,
        meshcat,
        joints=list(TORSO_JOINTS + NECK_JOINTS + RIGHT_ARM_JOINTS + LEFT_ARM_JOINTS),
    )


def _Push(name: str, facing: tuple, along: tuple, meshcat: Meshcat | None) -> TrmExample:
    """Both palms facing ``facing``, 25 cm apart, in the height band :data:`PUSH_HEIGHT`; the
    task space the right palm's position along ``along``; spacing 2 cm."""
    return _TwoHandTask(
        name,
        lambda m, right, left: [
            TwoHandHoldCost(left, right, HOLD),
            *_Facing(right, left, facing),
            HeightBand(right, *PUSH_HEIGHT),
            HeightBand(left, *PUSH_HEIGHT),
        ],
        lambda m: (MarkerAlong(m.MarkerIndex("r_palm"), along),),
        0.02,
        meshcat,
    )


def PushForward(meshcat: Meshcat | None = None) -> TrmExample:
    """Fig. 3.6: the palms face forward (-x) and move forward/back (:func:`_Push`)."""
    return _Push("push_forward", (-1.0, 0.0, 0.0), (-1.0, 0.0, 0.0), meshcat)


def PushOver(meshcat: Meshcat | None = None) -> TrmExample:
    """Fig. 3.7: the palms face left (-y) and move left/right (:func:`_Push`)."""
    return _Push("push_over", (0.0, -1.0, 0.0), (0.0, 1.0, 0.0), meshcat)


def _HeldTurn(name: str, axis: tuple, meshcat: Meshcat | None) -> TrmExample:
    """The hands hold an object; the task space the right palm normal's angle about ``axis``,
    from -y; spacing 0.1 rad."""
    return _TwoHandTask(
        name,
        _Hold,
        lambda m: (MarkerHeading(m.MarkerIndex("r_palm"), axis, (0.0, -1.0, 0.0)),),
        0.1,
        meshcat,
    )


def BimanualRotate(meshcat: Meshcat | None = None) -> TrmExample:
    """Fig. 3.9: the held object turns in the up/down, left/right plane (about forward)."""
    return _HeldTurn("bimanual_rotate", (1.0, 0.0, 0.0), meshcat)


def BimanualTwist(meshcat: Meshcat | None = None) -> TrmExample:
    """Fig. 3.10: the held object turns in the table plane (about the vertical)."""
    return _HeldTurn("bimanual_twist", (0.0, 0.0, 1.0), meshcat)


def Unscrew(meshcat: Meshcat | None = None) -> TrmExample:
    """Fig. 3.11: the left palm at :data:`BOTTLE` facing right (+y) with its hand axis forward,
    the right palm at :data:`CAP` facing down; the task space the right hand's axis angle about
    the vertical (the palm normal), from forward (-x); spacing 0.1 rad."""
    return _TwoHandTask(
        "unscrew",
        lambda m, right, left: [
            MarkerPositionCost(left, BOTTLE),
            MarkerPositionCost(right, CAP),
            MarkerOrientationCost(left, np.array([0.0, 1.0, 0.0])),
            MarkerOrientationCost(m.MarkerIndex("l_hand"), np.array([-1.0, 0.0, 0.0])),
            MarkerOrientationCost(right, np.array([0.0, 0.0, -1.0])),
        ],
        lambda m: (MarkerHeading(m.MarkerIndex("r_hand"), (0.0, 0.0, 1.0), (-1.0, 0.0, 0.0)),),
        0.1,
        meshcat,
    )
