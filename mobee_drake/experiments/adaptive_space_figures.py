"""Figures of a space as it reshaped itself (ch. 9.4.5; docs/adaptive_space.md): a PNG and a
Meshcat scene of one maintained run per arm and space.

Each state is drawn where its centre puts the arm's reaching marker (the iCub's palm, the
Katana's wrist): the states the space started with and kept, those it removed, and those it
added; the Meshcat scene is a recording of the space as it changed, round by round.
"""

import dataclasses as dc
import pathlib

import matplotlib.pyplot as plt
import numpy as np
from pydrake.geometry import Meshcat, Rgba, Sphere
from pydrake.math import RigidTransform

from mobee_drake.atomic_files import WriteTextAtomically
from mobee_drake.experiments.arms import Arms
from mobee_drake.experiments.plots import Legend, SaveFigure
from mobee_drake.ngik.kinematic_model import KinematicModel
from mobee_drake.station.viewer import ReleaseMeshcats
from mobee_drake.world.live_world import ROLE_COLORS, MakeShape, ObjectPose

# The colours of the kept, removed and added states.
KEPT, REMOVED, ADDED, TARGET = "tab:blue", "tab:red", "tab:purple", "tab:green"
# The Meshcat recording's pace: the maintenance's steps (actions; the reach learner's
# problem-tries) per second, one round at the default period.
STEPS_PER_SECOND = 100.0
# A state's sphere in the Meshcat scene (m).
STATE_RADIUS = 0.006
_RGBA = {"kept": Rgba(0.12, 0.47, 0.71, 1), "removed": Rgba(0.84, 0.15, 0.16, 1)}
_RGBA["added"] = Rgba(0.58, 0.40, 0.74, 1)
# (the "target" role's colour: in the reach learner's world a target is an obstacle until its
# reach, but here it is drawn as what it is)
_RGBA["target"] = Rgba(*ROLE_COLORS["target"][:3], 0.25)


@dc.dataclass
class SpaceHistory:
    """One maintained run's space as it changed: every state it ever had, where the marker is at
    its centre (m, world), and when (the maintenance's steps done: actions, or the reach
    learner's problem-tries) it was added and pruned."""

    title: str
    points: np.ndarray  # (s, 3): the initial space's states first, then those added, in order
    added_at: np.ndarray  # (s,): 0 for the initial space's
    pruned_at: np.ndarray  # (s,): inf for a state never pruned
    # The reach targets (k, 3) and their radius (m), for the reach learner's space.
    targets: np.ndarray = dc.field(default_factory=lambda: np.zeros((0, 3)))
    target_radius: float = 0.0

    @property
    def kept(self) -> np.ndarray:
        """(k, 3): the initial space's states still there at the end."""
        return self.points[(self.added_at == 0) & np.isinf(self.pruned_at)]

    @property
    def removed(self) -> np.ndarray:
        """(r, 3): the states pruned, of the initial space or added before (one per prune)."""
        return self.points[np.isfinite(self.pruned_at)]

    @property
    def added_then_removed(self) -> int:
        """How many of :attr:`removed` were added first."""
        return int(np.sum((self.added_at > 0) & np.isfinite(self.pruned_at)))

    @property
    def added(self) -> np.ndarray:
        """(a, 3): the states added and still there at the end."""
        return self.points[(self.added_at > 0) & np.isinf(self.pruned_at)]


def History(
    title: str, arm, initial: np.ndarray, changes: list[dict], targets=None
) -> SpaceHistory:
    """The history of a space that began with centres ``initial`` (fractions of ``arm``'s joints'
    ranges) and changed by ``changes`` (a maintenance's, in order: each its ``actions_done``,
    ``rule`` and, for a pruned or new state, its ``centre``), with the reach learner's
    ``targets`` (a :class:`~mobee_drake.reaching.targets.TargetGrid`), if given.

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
    history = SpaceHistory(
        title, _MarkerPositions(arm, centres), np.array(added_at), np.array(pruned_at)
    )
    if targets is not None:
        history.targets, history.target_radius = targets.Centres(), targets.radius
    return history


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
            if len(history.targets):
                axis.scatter(
                    *history.targets[:, [i, j]].T, s=40, marker="+", color=TARGET,
                    label="target centres",
                )  # fmt: skip
            axis.set(
                xlabel=f"{'xyz'[i]} [m]",
                ylabel=f"{'xyz'[j]} [m]",
                title=f"{history.title}, {name}:\n{_Counts(history)}",
                aspect="equal",
            )
            Legend(axis)
    figure.tight_layout()
    return figure


def _Counts(history: SpaceHistory) -> str:
    """The figure's count of the states kept, removed and added (kept + added: the space at the
    end; removed: one per prune)."""
    first = history.added_then_removed
    return (
        f"{len(history.kept)} kept, {len(history.removed)} removed"
        + (f" ({first} of them added first)" if first else "")
        + f", {len(history.added)} added"
    )


def ShowSpace(meshcat: Meshcat, history: SpaceHistory, path: str) -> None:
    """Draws a space's states under ``path`` as it changed, in the recording under way (one
    second per :data:`STEPS_PER_SECOND` steps): the initial space's states blue, those added
    purple from when they were added, a pruned state red from when it was pruned; shown live as
    at the end."""
    for i, (point, added_at, pruned_at) in enumerate(
        zip(history.points, history.added_at, history.pruned_at)
    ):
        node = f"{path}/{i}"
        meshcat.SetObject(node, Sphere(STATE_RADIUS), _RGBA["kept" if added_at == 0 else "added"])
        meshcat.SetTransform(node, RigidTransform(point))
        meshcat.SetProperty(node, "visible", added_at == 0, 0.0)
        if added_at > 0:
            meshcat.SetProperty(node, "visible", True, added_at / STEPS_PER_SECOND)
        if np.isfinite(pruned_at):
            meshcat.SetProperty(node, "visible", False, pruned_at / STEPS_PER_SECOND)
            meshcat.SetObject(f"{node}_pruned", Sphere(STATE_RADIUS), _RGBA["removed"])
            meshcat.SetTransform(f"{node}_pruned", RigidTransform(point))
            meshcat.SetProperty(f"{node}_pruned", "visible", False, 0.0)
            meshcat.SetProperty(f"{node}_pruned", "visible", True, pruned_at / STEPS_PER_SECOND)
        meshcat.SetProperty(node, "visible", bool(np.isinf(pruned_at)))  # (live: the end)


def ShowObjects(meshcat: Meshcat, objects, path: str = "objects") -> None:
    """Draws the world's ``objects`` (SceneObjects) under ``path`` in their role's colour, as the
    viewer does, but translucent (the states behind them stay visible)."""
    for obj in objects:
        rgba = Rgba(*ROLE_COLORS[obj.role][:3], 0.5)
        meshcat.SetObject(f"{path}/{obj.name}", MakeShape(obj.shape), rgba)
        meshcat.SetTransform(f"{path}/{obj.name}", ObjectPose(obj.position, obj.rpy_deg))


def WriteSpaceFigures(
    histories: dict[str, list[SpaceHistory]], output: pathlib.Path, stem: str
) -> list[str]:
    """``<stem>.png`` and, per robot, ``<stem>_<robot>.html`` (Meshcat, with the robot at home,
    its world's objects and the reach targets: a recording of its spaces as they changed) in
    ``output``, of ``histories`` (per robot, its spaces' histories, titled "<robot>, <space>" or
    "<robot>, <space>, <strategy>, seed <n>"); their names."""
    if not histories:
        return []
    written = [f"{stem}.png"]
    SaveFigure(Figure([h for hs in histories.values() for h in hs]), output / written[0])
    for robot, robot_histories in histories.items():
        written.append(f"{stem}_{robot}.html")
        _WriteScene(robot, robot_histories, output / written[-1])
        ReleaseMeshcats()  # (its Meshcat, on this thread)
    return written


def _WriteScene(robot: str, histories: list[SpaceHistory], path: pathlib.Path) -> None:
    """The Meshcat scene of ``robot``'s ``histories`` (:func:`WriteSpaceFigures`) at ``path``."""
    meshcat, arm = Meshcat(), Arms()[robot]
    model = KinematicModel(arm.robot, list(arm.objects), meshcat=meshcat)
    model.Publish(model.home)
    ShowObjects(meshcat, arm.objects)
    meshcat.StartRecording(frames_per_second=10, set_visualizations_while_recording=False)
    # (the space that changed most is shown; the rest are in the tree)
    shown = max(histories, key=lambda h: len(h.removed) + len(h.added))
    for history in histories:
        node = "spaces/" + "/".join(history.title.split(", ")[1:3])  # (space, strategy)
        ShowSpace(meshcat, history, node)
        meshcat.SetProperty(node, "visible", history is shown)
    meshcat.PublishRecording()
    for k, centre in enumerate(shown.targets):
        meshcat.SetObject(f"targets/{k}", Sphere(shown.target_radius), _RGBA["target"])
        meshcat.SetTransform(f"targets/{k}", RigidTransform(centre))
    points = np.vstack([h.points for h in histories])
    centre = points.mean(axis=0)
    spread = np.linalg.norm(points - centre, axis=1).max()  # (all in view: 1.5 times it)
    direction = np.array([-0.9, 0.5, 0.45]) / np.linalg.norm([-0.9, 0.5, 0.45])
    meshcat.SetCameraPose(centre + max(1.5 * spread, 0.3) * direction, centre)
    WriteTextAtomically(path, meshcat.StaticHtml())
