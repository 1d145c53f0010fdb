"""A dense collision overlay fitted to a robot's visual meshes: Fig. 2.4 on a model as heavy as
the source's (issue 34).

The source's iCub overlay had 129 primitives (ch. 2.4); ours has 14, one or two per link. The
generator keeps the base overlay's links, markers and clauses and replaces each link's primitives
by ``slices`` oriented boxes fitted to the link's visual mesh: the mesh's vertices, taken at the
zero configuration in the overlay's reference frame, are cut into ``slices`` slabs of equal length
along their principal axis, and each slab gets the smallest box that holds its vertices with one
edge along that axis (the least-area rectangle around the slab's section, by rotating calipers
over its convex hull). A box keeps the field margin of its link's base primitive. The
base overlay's exclusion groups become groups of links: every dense primitive on a link of a base
group joins that group. Each box is named ``<link>_<k>``.

``python scripts/make_dense_overlay.py`` writes ``models/icub_dense_overlay.yaml`` (14 links x 9
slices = 126 primitives); ``tests/test_dense_overlay.py`` checks that the file is what the
generator makes.
"""

import math
import pathlib
import xml.etree.ElementTree as ET

import numpy as np
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.parsing import Parser
from scipy.spatial import ConvexHull, QhullError

from mobee_drake.robots.overlay import Box, Overlay, Primitive, ZeroConfigurationPoses

# Slabs per link of the shipped dense iCub overlay: 14 links x 9 = 126 primitives (the source's
# 129).
SLICES = 9


def _Floats(text: str | None, default: str) -> np.ndarray:
    return np.array([float(x) for x in (text or default).split()])


def LinkMeshVertices(urdf: pathlib.Path, links: set[str]) -> dict[str, np.ndarray]:
    """The vertices (link frame, m) of every visual mesh of ``links`` in a URDF."""
    import trimesh  # (Imported lazily, as the model cache does.)

    vertices: dict[str, list[np.ndarray]] = {}
    for link in ET.parse(urdf).getroot().findall("link"):
        if link.get("name") not in links:
            continue
        for visual in link.findall("visual"):
            mesh = visual.find("geometry/mesh")
            if mesh is None:
                continue
            origin = visual.find("origin")
            attributes = origin.attrib if origin is not None else {}
            X_LV = RigidTransform(
                RollPitchYaw(_Floats(attributes.get("rpy"), "0 0 0")),
                _Floats(attributes.get("xyz"), "0 0 0"),
            )
            points = trimesh.load(mesh.get("filename"), force="mesh").vertices
            points = points * _Floats(mesh.get("scale"), "1 1 1")
            vertices.setdefault(link.get("name"), []).append(X_LV.multiply(points.T).T)
    return {name: np.vstack(parts) for name, parts in vertices.items()}


def _Axes(points: np.ndarray) -> np.ndarray:
    """The points' principal axes as the columns of a proper rotation matrix."""
    _, _, vt = np.linalg.svd(points - points.mean(axis=0), full_matrices=True)
    axes = vt.T
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    return axes


def _LeastRectangle(section: np.ndarray) -> np.ndarray:
    """The 2 x 2 rotation whose columns are the axes of the least-area rectangle around 2-D
    points (one of its sides lies along an edge of their convex hull)."""
    try:
        hull = section[ConvexHull(section).vertices]
    except QhullError:  # (collinear or too few points: any axes hold them)
        return np.eye(2)
    edges = np.roll(hull, -1, axis=0) - hull
    angles = np.arctan2(edges[:, 1], edges[:, 0])
    best, best_area = np.eye(2), np.inf
    for angle in angles:
        rotation = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
        local = hull @ rotation
        area = np.prod(local.max(axis=0) - local.min(axis=0))
        if area < best_area:
            best, best_area = rotation, area
    return best


def SlabBoxes(points: np.ndarray, slices: int) -> list[Box]:
    """``slices`` boxes covering ``points``: slabs of equal length along their principal axis,
    each the least box around its points with one edge along that axis (an empty slab, none)."""
    link_axes = _Axes(points)
    along = points @ link_axes[:, 0]
    edges = np.linspace(along.min(), along.max(), slices + 1)
    boxes = []
    for k in range(slices):
        slab = points[(along >= edges[k]) & (along <= edges[k + 1])]
        if not len(slab):
            continue
        axes = link_axes.copy()
        axes[:, 1:] = link_axes[:, 1:] @ _LeastRectangle(slab @ link_axes[:, 1:])
        local = slab @ axes
        low, high = local.min(axis=0), local.max(axis=0)
        rpy = RollPitchYaw(RotationMatrix(axes)).vector()
        boxes.append(
            Box(
                center=(axes @ ((low + high) / 2)).round(4).tolist(),
                size=np.maximum(high - low, 1e-3).round(4).tolist(),
                rpy_deg=np.degrees(rpy).round(3).tolist(),
            )
        )
    return boxes


def DenseOverlay(base: Overlay, urdf: pathlib.Path, slices: int = SLICES) -> Overlay:
    """The base overlay with each link's primitives replaced by boxes fitted to its meshes (see
    the module's docstring); ValueError naming a link of the base overlay without a mesh."""
    links = list(dict.fromkeys(p.link for p in base.primitives))
    meshes = LinkMeshVertices(urdf, set(links))
    missing = [link for link in links if link not in meshes]
    if missing:
        raise ValueError(f"{urdf}: no visual mesh for the overlay's links {missing}")
    poses = ZeroConfigurationPoses(
        lambda plant: Parser(plant).AddModels(str(urdf))[0], base.reference_link
    )
    field = {p.link: p.field for p in base.primitives}
    primitives = []
    for link in links:
        in_reference = poses[link].multiply(meshes[link].T).T
        for k, box in enumerate(SlabBoxes(in_reference, slices)):
            primitives.append(
                Primitive(name=f"{link}_{k}", link=link, shape=box, field=field[link])
            )
    link_of = {p.name: p.link for p in base.primitives}
    exclude = [
        [p.name for p in primitives if p.link in {link_of[name] for name in group}]
        for group in base.exclude
    ]
    exclude += [[p.name for p in primitives if p.link == link] for link in links]
    return Overlay(
        reference_link=base.reference_link,
        default_field=base.default_field,
        primitives=primitives,
        exclude=[group for group in exclude if len(group) > 1],
        markers=base.markers,
        clauses=base.clauses,
    )


def Volume(overlay: Overlay) -> float:
    """The summed volume of the overlay's boxes (m^3): the dense overlay's tightness, against the
    base overlay's primitives."""
    total = 0.0
    for p in overlay.primitives:
        shape = p.shape
        if isinstance(shape, Box):
            total += math.prod(shape.size)
        elif hasattr(shape, "start"):  # a capsule
            length = float(np.linalg.norm(np.subtract(shape.end, shape.start)))
            total += math.pi * shape.radius**2 * (length + 4 / 3 * shape.radius)
        else:
            total += 4 / 3 * math.pi * shape.radius**3
    return total
