"""Figures of a space as it reshaped itself (ch. 9.4.5; docs/adaptive_space.md): a PNG and a
Meshcat scene of one maintained run per arm and space.

Each state is drawn where its centre puts the arm's reaching marker (the iCub's palm, the
Katana's wrist): the states the space started with and kept, those it removed, and those it
added.
"""

import dataclasses as dc

import matplotlib.pyplot as plt
import numpy as np
from pydrake.geometry import Meshcat, Rgba
from pydrake.perception import BaseField, Fields, PointCloud

from mobee_drake.experiments.plots import Legend
from mobee_drake.ngik.kinematic_model import KinematicModel
from mobee_drake.world.live_world import MakeShape, ObjectPose

# The colours of the kept, removed and added states.
KEPT, REMOVED, ADDED = "tab:blue", "tab:red", "tab:green"


@dc.dataclass
class SpaceHistory:
    """One maintained run's space: where the marker is at each state's centre (m, world)."""

    title: str
    kept: np.ndarray  # (k, 3): the initial space's states still there at the end
    removed: np.ndarray  # (r, 3)
    added: np.ndarray  # (a, 3), at the end


def History(title: str, arm, initial: np.ndarray, final: np.ndarray) -> SpaceHistory:
    """The history of a space that began with centres ``initial`` and ended with ``final``
    (fractions of ``arm``'s joints' ranges)."""
    model = KinematicModel(arm.robot, list(arm.objects))
    columns = [model.JointIndex(j) for j in arm.joints]
    marker = model.MarkerIndex(arm.marker)
    lower, upper = model.lower[columns], model.upper[columns]

    def Marker(centres) -> np.ndarray:
        points = []
        for f in centres:
            q = model.home.copy()
            q[columns] = lower + np.asarray(f) * (upper - lower)
            points.append(model.Evaluate(q).marker_positions[marker])
        return np.array(points).reshape(-1, 3)

    def Among(centres: np.ndarray, others: np.ndarray) -> np.ndarray:
        """Whether each of ``centres`` is one of ``others`` (a state that stays keeps its
        centre; the tolerance only absorbs the limits' rounding)."""
        gaps = np.abs(np.asarray(centres)[:, None] - np.asarray(others)[None]).max(axis=2)
        return gaps.min(axis=1) <= 1e-9

    stays, new = Among(initial, final), ~Among(final, initial)
    return SpaceHistory(
        title=title,
        kept=Marker(initial[stays]),
        removed=Marker(initial[~stays]),
        added=Marker(final[new]),
    )


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
    """Draws a space's kept, removed and added states as point clouds under ``path``."""
    colours = {"kept": Rgba(0.12, 0.47, 0.71, 1), "removed": Rgba(0.84, 0.15, 0.16, 1)}
    colours["added"] = Rgba(0.17, 0.63, 0.17, 1)
    for name, points in (
        ("kept", history.kept), ("removed", history.removed), ("added", history.added),
    ):  # fmt: skip
        if len(points):
            cloud = PointCloud(len(points), Fields(BaseField.kXYZs))
            cloud.mutable_xyzs()[:] = points.T
            meshcat.SetObject(f"{path}/{name}", cloud, point_size=0.012, rgba=colours[name])


def ShowObjects(meshcat: Meshcat, objects, path: str = "objects") -> None:
    """Draws the world's ``objects`` (SceneObjects), translucent grey, under ``path``."""
    for obj in objects:
        meshcat.SetObject(f"{path}/{obj.name}", MakeShape(obj.shape), Rgba(0.5, 0.5, 0.5, 0.5))
        meshcat.SetTransform(f"{path}/{obj.name}", ObjectPose(obj.position, obj.rpy_deg))
