"""Figures of a space as it reshaped itself (ch. 9.4.5; docs/adaptive_space.md): a PNG and a
Meshcat scene of one maintained run per arm and space.

Each state is drawn where its centre puts the arm's reaching marker (the iCub's palm, the
Katana's wrist): the states the space started with and kept, those it removed, and those it
added; the Meshcat scene is a recording of the space as it changed, round by round.
"""

import dataclasses as dc

import matplotlib.pyplot as plt
import numpy as np
from pydrake.geometry import Meshcat, Rgba, Sphere
from pydrake.math import RigidTransform

from mobee_drake.experiments.plots import Legend
from mobee_drake.ngik.kinematic_model import KinematicModel
from mobee_drake.world.live_world import MakeShape, ObjectPose

# The colours of the kept, removed and added states.
KEPT, REMOVED, ADDED = "tab:blue", "tab:red", "tab:green"


# The Meshcat recording's pace: actions (100, one round at the default period) per second.
ACTIONS_PER_SECOND = 100.0
# A state's sphere in the Meshcat scene (m).
STATE_RADIUS = 0.006
_RGBA = {"kept": Rgba(0.12, 0.47, 0.71, 1), "removed": Rgba(0.84, 0.15, 0.16, 1)}
_RGBA["added"] = Rgba(0.17, 0.63, 0.17, 1)


@dc.dataclass
class SpaceHistory:
    """One maintained run's space as it changed: every state it ever had, where the marker is at
    its centre (m, world), and when (actions done) it was added and pruned."""

    title: str
    points: np.ndarray  # (s, 3): the initial space's states first, then those added, in order
    added_at: np.ndarray  # (s,): 0 for the initial space's
    pruned_at: np.ndarray  # (s,): inf for a state never pruned

    @property
    def kept(self) -> np.ndarray:
        """(k, 3): the initial space's states still there at the end."""
        return self.points[(self.added_at == 0) & np.isinf(self.pruned_at)]

    @property
    def removed(self) -> np.ndarray:
        """(r, 3): the initial space's states pruned."""
        return self.points[(self.added_at == 0) & np.isfinite(self.pruned_at)]

    @property
    def added(self) -> np.ndarray:
        """(a, 3): the states added and still there at the end."""
        return self.points[(self.added_at > 0) & np.isinf(self.pruned_at)]


def History(title: str, arm, initial: np.ndarray, changes: list[dict]) -> SpaceHistory:
    """The history of a space that began with centres ``initial`` (fractions of ``arm``'s joints'
    ranges) and changed by ``changes`` (a maintenance's, in order: each its ``actions_done``,
    ``rule`` and, for a pruned or new state, its ``centre``).

    Raises:
        ValueError: if a pruned state's centre is none of the space's states then.
    """
    centres, added_at = [np.asarray(c, dtype=float) for c in initial], [0.0] * len(initial)
    pruned_at = [np.inf] * len(initial)
    for change in changes:
        if change["rule"] == "prune":
            alive = [k for k, t in enumerate(pruned_at) if np.isinf(t)]
            gaps = [np.abs(centres[k] - change["centre"]).max() for k in alive]
            if not alive or min(gaps) > 1e-9:  # (a state keeps its centre; only rounding)
                raise ValueError(f"{title}: pruned state {change['centre']} is not in the space")
            pruned_at[alive[int(np.argmin(gaps))]] = change["actions_done"]
        elif change["centre"]:  # (a new state: grow or develop)
            centres.append(np.asarray(change["centre"], dtype=float))
            added_at.append(change["actions_done"])
            pruned_at.append(np.inf)
    return SpaceHistory(
        title, _MarkerPositions(arm, centres), np.array(added_at), np.array(pruned_at)
    )


def _MarkerPositions(arm, centres) -> np.ndarray:
    """(k, 3): the arm's marker at each of ``centres`` (fractions of its joints' ranges; the other
    joints at home)."""
    model = KinematicModel(arm.robot, list(arm.objects))
    columns = [model.JointIndex(j) for j in arm.joints]
    marker = model.MarkerIndex(arm.marker)
    lower, upper = model.lower[columns], model.upper[columns]
    points = []
    for f in centres:
        q = model.home.copy()
        q[columns] = lower + np.asarray(f) * (upper - lower)
        points.append(model.Evaluate(q).marker_positions[marker])
    return np.array(points).reshape(-1, 3)


def Figure(histories: list[SpaceHistory]):
    """Per space, the states seen from above (world x, y) and from the side (x, z)."""
    figure, axes = plt.subplots(
        len(histories), 2, figsize=(12, 4.6 * len(histories)), squeeze=False
    )
    for history, row in zip(histories, axes):
        for axis, (i, j, name) in zip(row, ((0, 1, "from above"), (0, 2, "from the side"))):
            axis.scatter(*history.kept[:, [i, j]].T, s=10, color=KEPT, label="kept")
            if len(history.removed):
                axis.scatter(
                    *history.removed[:, [i, j]].T, s=28, marker="x", color=REMOVED,
                    label="removed",
                )  # fmt: skip
            if len(history.added):
                axis.scatter(
                    *history.added[:, [i, j]].T, s=14, color=ADDED, label="added",
                )  # fmt: skip
            axis.set(
                xlabel=f"{'xyz'[i]} [m]",
                ylabel=f"{'xyz'[j]} [m]",
                title=f"{history.title}, {name}: {len(history.kept)} kept, "
                f"{len(history.removed)} removed, {len(history.added)} added",
                aspect="equal",
            )
            Legend(axis)
    figure.tight_layout()
    return figure


def ShowSpace(meshcat: Meshcat, history: SpaceHistory, path: str) -> None:
    """Draws a space's states under ``path`` as it changed, in the recording under way (one
    second per :data:`ACTIONS_PER_SECOND` actions): the initial space's states blue, those added
    green from when they were added, a pruned state red from when it was pruned; shown live as
    at the end."""
    for i, (point, added_at, pruned_at) in enumerate(
        zip(history.points, history.added_at, history.pruned_at)
    ):
        node = f"{path}/{i}"
        meshcat.SetObject(node, Sphere(STATE_RADIUS), _RGBA["kept" if added_at == 0 else "added"])
        meshcat.SetTransform(node, RigidTransform(point))
        meshcat.SetProperty(node, "visible", added_at == 0, 0.0)
        if added_at > 0:
            meshcat.SetProperty(node, "visible", True, added_at / ACTIONS_PER_SECOND)
        if np.isfinite(pruned_at):
            meshcat.SetProperty(node, "visible", False, pruned_at / ACTIONS_PER_SECOND)
            meshcat.SetObject(f"{node}_pruned", Sphere(STATE_RADIUS), _RGBA["removed"])
            meshcat.SetTransform(f"{node}_pruned", RigidTransform(point))
            meshcat.SetProperty(f"{node}_pruned", "visible", False, 0.0)
            meshcat.SetProperty(f"{node}_pruned", "visible", True, pruned_at / ACTIONS_PER_SECOND)
        meshcat.SetProperty(node, "visible", bool(np.isinf(pruned_at)))  # (live: the end)


def ShowObjects(meshcat: Meshcat, objects, path: str = "objects") -> None:
    """Draws the world's ``objects`` (SceneObjects), translucent grey, under ``path``."""
    for obj in objects:
        meshcat.SetObject(f"{path}/{obj.name}", MakeShape(obj.shape), Rgba(0.5, 0.5, 0.5, 0.5))
        meshcat.SetTransform(f"{path}/{obj.name}", ObjectPose(obj.position, obj.rpy_deg))
