"""A picture of a MoBeE XML robot: its primitives and markers in 3-D, in given configurations
(the Katana of App. B in ``docs/zero_position.md``)."""

from matplotlib.patches import Patch
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
import numpy as np
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix

from mobee_drake.experiments.plots import Figure
from mobee_drake.robots.overlay import Box, Sphere
from mobee_drake.robots.zero_position import ROOT_BODY, BodyPoses, ZeroPositionRobot

_KINDS = {"box": "box", "link": "link capsule", "joint": "joint capsule", "sphere": "sphere"}


def _DrawBox(axis, X: RigidTransform, shape: Box, colour: str) -> np.ndarray:
    """Draws a box posed by ``X``; returns its corners."""
    R = X.rotation() @ RollPitchYaw(np.radians(shape.rpy_deg)).ToRotationMatrix()
    corners = np.array(
        [
            X @ np.asarray(shape.center) + R @ (np.array(s) * shape.size / 2)
            for s in np.ndindex(2, 2, 2)
            for s in [np.array(s) * 2 - 1]
        ]
    )
    faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
    axis.add_collection3d(
        Poly3DCollection([corners[f] for f in faces], facecolor=colour, edgecolor="k", alpha=0.6)
    )
    return corners


def _DrawRound(axis, X: RigidTransform, shape, colour: str) -> list[np.ndarray]:
    """Draws a sphere (rings of circles) or a capsule (its cylinder, the round ends left out)
    posed by ``X``; returns two points that bound it."""
    if isinstance(shape, Sphere):
        start = end = X @ np.asarray(shape.center)
    else:
        start, end = X @ np.asarray(shape.start), X @ np.asarray(shape.end)
    along = end - start
    frame = RotationMatrix.MakeFromOneVector(along if np.any(along) else [0, 0, 1], 2)
    e1, e2 = np.array(frame.matrix()[:, :2]).T  # copies (col() views die with frame)
    u = np.linspace(0, 2 * np.pi, 24)
    if isinstance(shape, Sphere):
        v = np.linspace(-np.pi / 2, np.pi / 2, 12)
        ring = np.outer(np.cos(v), np.ones_like(u)), np.outer(np.sin(v), np.ones_like(u))
        surface = [
            start[k]
            + shape.radius * (ring[0] * (np.cos(u) * e1[k] + np.sin(u) * e2[k]))
            + shape.radius * ring[1] * (np.cross(e1, e2)[k])
            for k in range(3)
        ]
    else:
        t = np.array([0.0, 1.0])[:, None]
        surface = [
            start[k] + t * along[k] + shape.radius * (np.cos(u) * e1[k] + np.sin(u) * e2[k])
            for k in range(3)
        ]
    axis.plot_surface(*surface, color=colour, alpha=0.6, linewidth=0)
    return [start - shape.radius, end + shape.radius]


def PrimitivesFigure(
    robot: ZeroPositionRobot, configurations: dict[str, dict[str, float]]
) -> Figure:
    """A matplotlib figure of ``robot``'s primitives and markers, one 3-D axes per
    configuration (title: joint angles in radians by joint name; joints not named at zero)."""
    zero = BodyPoses(robot, {})
    figure = Figure(figsize=(6.0 * len(configurations), 5.5))
    for i, (title, q) in enumerate(configurations.items()):
        axis = figure.add_subplot(1, len(configurations), i + 1, projection="3d")
        poses = BodyPoses(robot, q)
        colours, points = {}, []
        for primitive in robot.overlay.primitives:
            X = poses[primitive.link] @ zero[primitive.link].inverse()  # zero -> q
            kind = _KINDS.get(primitive.name.split("_line")[0], primitive.name)
            if isinstance(primitive.shape, Box):
                kind = f"box on {primitive.link}"
            colour = colours.setdefault(kind, f"C{len(colours)}")
            if isinstance(primitive.shape, Box):
                points.extend(_DrawBox(axis, X, primitive.shape, colour))
            else:
                points.extend(_DrawRound(axis, X, primitive.shape, colour))
        joints = np.array([poses[b].translation() for b in poses if b != ROOT_BODY])
        axis.scatter(*joints.T, color="k", marker="x", s=25, label="joint points", depthshade=False)
        for marker in robot.overlay.markers:
            X = poses[marker.link] @ zero[marker.link].inverse()
            p = X @ np.asarray(marker.position)
            axis.scatter(*p, color="m", s=40, label=f"marker '{marker.name}'", depthshade=False)
            points.append(p)
        centre = (np.min(points, axis=0) + np.max(points, axis=0)) / 2
        half = float(np.max(np.ptp(points, axis=0))) / 2 * 1.05
        axis.set(
            xlim=(centre[0] - half, centre[0] + half),
            ylim=(centre[1] - half, centre[1] + half),
            zlim=(centre[2] - half, centre[2] + half),
            xlabel="x [m]",
            ylabel="y [m]",
            zlabel="z [m]",
            title=f"{robot.name}: {title}",
        )
        axis.set_box_aspect((1, 1, 1))
        axis.view_init(elev=20, azim=-60)
        handles, _ = axis.get_legend_handles_labels()
        handles += [Patch(color=colour, label=kind) for kind, colour in colours.items()]
        axis.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize="small")
    return figure
