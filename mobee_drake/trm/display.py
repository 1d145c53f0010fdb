"""Roadmaps in Meshcat: the marker cloud and edges of a TRM, and motions along its paths."""

import numpy as np
from pydrake.geometry import Meshcat, Rgba
from pydrake.perception import BaseField, Fields, PointCloud

from mobee_drake.ngik.kinematic_model import KinematicModel
from mobee_drake.trm.roadmap import TaskRelevantRoadmap


def MarkerCloud(model: KinematicModel, roadmap: TaskRelevantRoadmap, marker: int) -> np.ndarray:
    """(V, 3) the marker's position in each vertex's pose."""
    return np.array([model.Evaluate(q).marker_positions[marker] for q in roadmap.q])


def ShowRoadmap(
    meshcat: Meshcat, points: np.ndarray, roadmap: TaskRelevantRoadmap, path: str = "trm"
) -> None:
    """Draws the vertices' marker positions as points and the edges as line segments."""
    cloud = PointCloud(len(points), Fields(BaseField.kXYZs))
    cloud.mutable_xyzs()[:] = points.T
    meshcat.SetObject(f"{path}/vertices", cloud, point_size=0.012, rgba=Rgba(0.1, 0.3, 0.9, 1))
    if len(roadmap.edges):
        a, b = roadmap.edges.T
        meshcat.SetLineSegments(
            f"{path}/edges", points[a].T, points[b].T, 1.0, Rgba(0.4, 0.4, 0.4, 0.6)
        )


def PathMotion(
    roadmap: TaskRelevantRoadmap, path: list[int], steps_per_edge: int = 10
) -> np.ndarray:
    """Poses along ``path``, each edge interpolated linearly in joint space."""
    poses = [roadmap.q[path[0]]]
    for a, b in zip(path[:-1], path[1:]):
        s = np.linspace(0.0, 1.0, steps_per_edge + 1)[1:, None]
        poses.extend((1 - s) * roadmap.q[a] + s * roadmap.q[b])
    return np.array(poses)


def RecordMotion(model: KinematicModel, poses: np.ndarray, period: float = 0.05) -> None:
    """Records the poses as an animation in the model's Meshcat (played by its slider)."""
    visualizer = model.visualizer
    visualizer.StartRecording(set_transforms_while_recording=False)
    for k, q in enumerate(poses):
        model.Publish(q, k * period)
    visualizer.StopRecording()
    visualizer.PublishRecording()
