"""Task spaces (dissertation eq. 3.4-3.5, Table 3.2): what a roadmap's poses should spread over.

A task space maps a pose's evaluation (``q``, marker states, collision pairs) to a point ``y`` of
R^n; it concatenates task functions, each giving one or more coordinates:

- :class:`MarkerCoordinates`: some coordinates of a marker's position ("move the hand in all three
  workspace dimensions", or a plane of them);
- :class:`MarkerAlong`: a marker's position along one direction ("move the hand back and forth",
  Table 3.2's ``x_1 + x_2 + x_3`` is the direction (1, 1, 1) unnormalised);
- :class:`JointCoordinates`: some joint positions ("move in the null space of the cost");
- :class:`JointFractions`: the same as fractions of each joint's range (a roadmap over the
  configurations themselves, an MDP's state space, ch. 9.4.5);
- :class:`MarkerAngle`: the angle between a marker's direction and a fixed one ("turn the hand
  with respect to the gaze", Fig. 3.5);
- :class:`MarkerHeading`: the angle of a marker's direction in a plane, from a reference axis
  ("rotate the palms in the up/down, left/right plane", Fig. 3.9-3.11).
"""

import dataclasses as dc

import numpy as np

from mobee_drake.ngik.kinematic_model import PoseEvaluation


@dc.dataclass(frozen=True)
class MarkerCoordinates:
    marker: int
    axes: tuple[int, ...] = (0, 1, 2)

    @property
    def size(self) -> int:
        return len(self.axes)

    def __call__(self, evaluation: PoseEvaluation) -> np.ndarray:
        return evaluation.marker_positions[self.marker, list(self.axes)]


@dc.dataclass(frozen=True)
class MarkerAlong:
    marker: int
    direction: tuple[float, float, float]

    @property
    def size(self) -> int:
        return 1

    def __call__(self, evaluation: PoseEvaluation) -> np.ndarray:
        return np.array([evaluation.marker_positions[self.marker] @ np.asarray(self.direction)])


@dc.dataclass(frozen=True)
class JointCoordinates:
    joints: tuple[int, ...]  # indices into the model's joints

    @property
    def size(self) -> int:
        return len(self.joints)

    def __call__(self, evaluation: PoseEvaluation) -> np.ndarray:
        return evaluation.q[list(self.joints)]


@dc.dataclass(frozen=True)
class JointFractions:
    """Some joint positions as fractions of their ranges (0 at ``lower``, 1 at ``upper``): a
    roadmap over the configurations themselves, spread evenly in the units of an MDP's states
    (ch. 9.4.5)."""

    joints: tuple[int, ...]  # indices into the model's joints
    lower: tuple[float, ...]
    upper: tuple[float, ...]

    @property
    def size(self) -> int:
        return len(self.joints)

    def __call__(self, evaluation: PoseEvaluation) -> np.ndarray:
        lower = np.asarray(self.lower)
        return (evaluation.q[list(self.joints)] - lower) / (np.asarray(self.upper) - lower)


@dc.dataclass(frozen=True)
class MarkerAngle:
    """arccos(u . direction) (rad): how far a marker's direction is turned from ``direction``."""

    marker: int
    direction: tuple[float, float, float]  # unit, in world

    @property
    def size(self) -> int:
        return 1

    def __call__(self, evaluation: PoseEvaluation) -> np.ndarray:
        cosine = evaluation.marker_directions[self.marker] @ np.asarray(self.direction)
        return np.array([np.arccos(np.clip(cosine, -1.0, 1.0))])


@dc.dataclass(frozen=True)
class MarkerHeading:
    """The angle (rad, in (-pi, pi]) of a marker's direction projected on the plane normal to
    ``normal``, from ``reference`` (a unit vector in that plane), positive about ``normal``."""

    marker: int
    normal: tuple[float, float, float]  # unit, in world
    reference: tuple[float, float, float]  # unit, normal to ``normal``

    @property
    def size(self) -> int:
        return 1

    def __call__(self, evaluation: PoseEvaluation) -> np.ndarray:
        u, n, r = (
            evaluation.marker_directions[self.marker],
            np.asarray(self.normal),
            np.asarray(self.reference),
        )
        return np.array([np.arctan2(np.cross(r, u) @ n, r @ u)])


TaskFunction = (
    MarkerCoordinates
    | MarkerAlong
    | JointCoordinates
    | JointFractions
    | MarkerAngle
    | MarkerHeading
)


@dc.dataclass(frozen=True)
class TaskSpace:
    """Y = (y_1, ..., y_n) (eq. 3.4): the task functions' coordinates, concatenated."""

    functions: tuple[TaskFunction, ...]

    @property
    def dimension(self) -> int:
        return sum(f.size for f in self.functions)

    def __call__(self, evaluation: PoseEvaluation) -> np.ndarray:
        return np.concatenate([f(evaluation) for f in self.functions])
