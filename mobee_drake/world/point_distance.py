"""The signed distance from a point to a world object's surface, in closed form.

For an object MoBeE does not see (a target or a ghost has no proximity role, so SceneGraph's
queries skip it): whether a marker reached a target. Negative inside.
"""

import numpy as np
from pydrake.geometry import Box, Convex, Cylinder, Shape, Sphere
from pydrake.math import RigidTransform
from scipy.spatial import ConvexHull


def _Outside(excess: np.ndarray) -> float:
    """The signed distance of a point whose coordinates exceed a solid's half extents by
    ``excess`` along the solid's axes (a box's three, a cylinder's radial and axial)."""
    return float(np.linalg.norm(np.maximum(excess, 0.0)) + min(excess.max(), 0.0))


def _HullPlanes(shape: Convex) -> np.ndarray:
    hull = shape.GetConvexHull()
    points = np.array([hull.vertex(i) for i in range(hull.num_vertices())])
    return ConvexHull(points).equations  # rows (n, d): n . p + d <= 0 inside


def SignedDistance(shape: Shape, X_WO: RigidTransform, p_W) -> float:
    """The signed distance (m) from the point ``p_W`` to the surface of ``shape`` posed at
    ``X_WO``. Exact for spheres, boxes and cylinders; for a mesh (its convex hull) exact inside
    and along its faces, and a lower bound near its edges and corners."""
    p = X_WO.inverse() @ np.asarray(p_W, dtype=float)
    if isinstance(shape, Sphere):
        return float(np.linalg.norm(p) - shape.radius())
    if isinstance(shape, Box):
        return _Outside(np.abs(p) - np.asarray(shape.size()) / 2)
    if isinstance(shape, Cylinder):
        radial = np.linalg.norm(p[:2]) - shape.radius()
        return _Outside(np.array([radial, abs(p[2]) - shape.length() / 2]))
    if isinstance(shape, Convex):
        planes = _HullPlanes(shape)
        return float((planes[:, :3] @ p + planes[:, 3]).max())
    raise TypeError(f"no closed-form distance to a {type(shape).__name__}")
