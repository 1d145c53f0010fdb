"""Cost functions of NGIK (dissertation eq. 3.1-3.3, Table 3.1).

Each cost term is a non-negative function ``h_i`` of a :class:`PoseEvaluation` (the pose ``q``,
the marker states ``X`` and the collision pairs ``K``). A term also says when it is *met*: its
value at most ``tolerance``. A user-defined term is any object with the same two members (see
:class:`CostTerm`); :class:`MarkerInBox` is one such, used by the "Reach Into" roadmap.

Table 3.1's orientation cost reads ``u . u* + 1``, which is zero when the marker points *against*
``u*``. We align the marker *with* ``u*``: ``1 - u . u*`` (the table's formula with ``u*``
negated), which is what its purpose column asks for.
"""

import dataclasses as dc
import math
from typing import Protocol

import numpy as np

from mobee_drake.ngik.kinematic_model import PoseEvaluation


class CostTerm(Protocol):
    """A non-negative cost ``h_i(q, B)`` (eq. 3.2) and the value below which it is met."""

    tolerance: float

    def __call__(self, evaluation: PoseEvaluation) -> float: ...


@dc.dataclass
class HomeCost:
    """h_home = w |q - q*| over some joints: a bias toward a posture, never a requirement."""

    posture: np.ndarray  # q* of all the model's joints (rad)
    joints: np.ndarray | None = None  # indices of the joints it applies to (None: all)
    weight: float = 1.0
    tolerance: float = math.inf

    def __call__(self, evaluation: PoseEvaluation) -> float:
        error = evaluation.q - self.posture
        if self.joints is not None:
            error = error[self.joints]
        return self.weight * float(np.linalg.norm(error))


@dc.dataclass
class CollisionCost:
    """h_collision = w |K|: the number of colliding pairs; met only with none."""

    weight: float = 1.0
    tolerance: float = 0.0

    def __call__(self, evaluation: PoseEvaluation) -> float:
        return self.weight * len(evaluation.collision_pairs)


@dc.dataclass
class MarkerPositionCost:
    """h_position = w |x - x*|: put a marker on a workspace point."""

    marker: int
    target: np.ndarray  # x* in world (m)
    weight: float = 1.0
    tolerance: float = 0.01

    def __call__(self, evaluation: PoseEvaluation) -> float:
        x = evaluation.marker_positions[self.marker]
        return self.weight * float(np.linalg.norm(x - self.target))


@dc.dataclass
class MarkerOrientationCost:
    """h_orientation = w (1 - u . u*): align a marker's direction with a workspace direction."""

    marker: int
    direction: np.ndarray  # unit u* in world
    weight: float = 1.0
    # 1 - cos(10 deg).
    tolerance: float = 1.0 - math.cos(math.radians(10.0))

    def __call__(self, evaluation: PoseEvaluation) -> float:
        u = evaluation.marker_directions[self.marker]
        return self.weight * float(1.0 - u @ self.direction)


@dc.dataclass
class TwoHandHoldCost:
    """h_hold = w | |x_left - x_right| - d |: hold two hand markers a fixed distance apart."""

    left: int
    right: int
    distance: float
    weight: float = 1.0
    tolerance: float = 0.01

    def __call__(self, evaluation: PoseEvaluation) -> float:
        x = evaluation.marker_positions
        return self.weight * abs(
            float(np.linalg.norm(x[self.left] - x[self.right])) - self.distance
        )


@dc.dataclass
class OpposedDirections:
    """h = w (1 + u_a . u_b): turn two markers' directions against each other (two palms facing
    each other, as when holding an object between them), whatever their common direction."""

    a: int
    b: int
    weight: float = 1.0
    # 1 - cos(10 deg), as the orientation term.
    tolerance: float = 1.0 - math.cos(math.radians(10.0))

    def __call__(self, evaluation: PoseEvaluation) -> float:
        u = evaluation.marker_directions
        return self.weight * float(1.0 + u[self.a] @ u[self.b])


@dc.dataclass
class MarkerInBox:
    """A user-defined term: w times how far a marker is outside an axis-aligned box (m)."""

    marker: int
    lower: np.ndarray
    upper: np.ndarray
    weight: float = 1.0
    tolerance: float = 0.0

    def __call__(self, evaluation: PoseEvaluation) -> float:
        x = evaluation.marker_positions[self.marker]
        outside = np.maximum(self.lower - x, 0.0) + np.maximum(x - self.upper, 0.0)
        return self.weight * float(np.linalg.norm(outside))
