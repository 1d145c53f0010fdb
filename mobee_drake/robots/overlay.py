"""MoBeE's collision overlay: primitives with force fields, collision filters, markers, constraints.

The overlay is what MoBeE knows of a robot beyond its kinematics (dissertation ch. 2.3.1, ch. 5):

- *primitives* (spheres, capsules, boxes) attached to links. Each has a solid size and a *field*:
  a margin around the solid inside which another geometry is repelled (MoBeE's ``radius`` and
  ``field``). They become the robot's proximity geometry in SceneGraph.
- *exclusions*: groups of primitives whose pairs never interact (pairs that always overlap or sit
  close by construction). Drake already filters pairs on bodies joined by one joint or welded.
- *markers*: named points with a direction on links (palms, hands, elbows, head), where workspace
  forces act and whose positions and Jacobians MoBeE reports.
- *constraint clauses*: linear joint-space constraints in conjunctive normal form (eq. 5.14-5.17);
  see :mod:`mobee_drake.mobee.constraints` for how a clause's forces switch on.

Coordinates follow MoBeE's zero-reference-position convention (ch. 2.3.1): every position and
direction is given in metres in the frame of ``reference_link`` with *every joint of the model at
zero*, so a capsule is written as the two end points of the bone it covers. The loader converts
them into each link's frame.
"""

from collections.abc import Callable, Mapping
import dataclasses as dc
import math
import pathlib
import re

import numpy as np
from pydrake.geometry import (
    AddContactMaterial,
    CollisionFilterDeclaration,
    GeometryId,
    GeometrySet,
    ProximityProperties,
    SceneGraph,
)
from pydrake.geometry import (
    Box as DrakeBox,
)
from pydrake.geometry import (
    Capsule as DrakeCapsule,
)
from pydrake.geometry import (
    Sphere as DrakeSphere,
)
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.plant import CoulombFriction, MultibodyPlant
from pydrake.multibody.tree import FixedOffsetFrame, FrameIndex, ModelInstanceIndex

from mobee_drake.robots.couplings import JointCoupling
from mobee_drake.yaml_io import LineOf, LoadYamlFile


def _Zeros3() -> list[float]:
    return [0.0, 0.0, 0.0]


@dc.dataclass
class Sphere:
    center: list[float] = dc.field(default_factory=_Zeros3)
    radius: float = 0.0


@dc.dataclass
class Capsule:
    """A cylinder with round caps around the segment ``start``-``end``."""

    start: list[float] = dc.field(default_factory=_Zeros3)
    end: list[float] = dc.field(default_factory=_Zeros3)
    radius: float = 0.0


@dc.dataclass
class Box:
    center: list[float] = dc.field(default_factory=_Zeros3)
    # Edge lengths along the box's own x, y, z axes.
    size: list[float] = dc.field(default_factory=_Zeros3)
    # Orientation of the box axes in the reference frame (roll, pitch, yaw in degrees).
    rpy_deg: list[float] = dc.field(default_factory=_Zeros3)


@dc.dataclass
class Primitive:
    name: str = ""
    link: str = ""
    shape: Sphere | Capsule | Box = dc.field(default_factory=Sphere)
    # Field margin in metres around the solid; ``None`` takes the overlay's ``default_field``.
    field: float | None = None


@dc.dataclass
class Marker:
    name: str = ""
    link: str = ""
    position: list[float] = dc.field(default_factory=_Zeros3)
    # A direction attached to the marker (the palm's normal, the gaze); normalised on load.
    direction: list[float] = dc.field(default_factory=lambda: [0.0, 0.0, 1.0])


@dc.dataclass
class Literal:
    """One linear constraint ``sum_j a_j q_j + b >= 0`` with ``q_j`` in degrees (eq. 5.14)."""

    # a_j by joint name.
    coefficients: dict[str, float] = dc.field(default_factory=dict)
    # b, in degrees.
    offset: float = 0.0


@dc.dataclass
class Clause:
    """A disjunction of literals: satisfied while any of them holds (eq. 5.16)."""

    name: str = ""
    literals: list[Literal] = dc.field(default_factory=list)


@dc.dataclass
class Overlay:
    """A robot's collision overlay, as written in ``models/*_overlay.yaml``."""

    # The frame of every coordinate below, taken with all joints of the model at zero.
    reference_link: str = "root_link"
    # Field margin (m) of primitives that do not give their own.
    default_field: float = 0.03
    primitives: list[Primitive] = dc.field(default_factory=list)
    # Groups of primitive names; no pair inside a group interacts.
    exclude: list[list[str]] = dc.field(default_factory=list)
    markers: list[Marker] = dc.field(default_factory=list)
    # The constraint set: the conjunction of these clauses (eq. 5.16).
    clauses: list[Clause] = dc.field(default_factory=list)


class OverlayError(ValueError):
    """An overlay that is inconsistent with itself or with its robot."""


# The largest magnitude of a length (m), an angle (deg) or a constraint's coefficient or offset;
# anything beyond is a typing error (and 1e308 would overflow a norm to inf or a unit to zero).
MAX_MAGNITUDE = 1e6
# Names of primitives and markers (and of everything a MoBeE XML file names): letters, digits,
# '_', '-', '.'; never a Drake scope separator '::', nothing to escape in a model's text.
_NAME = re.compile(r"[A-Za-z0-9_.\-]+")


def NameProblem(name: str) -> str | None:
    """Why ``name`` cannot name a part of a model, or None when it can."""
    if not _NAME.fullmatch(name):
        return f"{name!r} is not a name: use letters, digits, '_', '-' and '.'"
    if name.startswith("__") or name == "world":
        return f"{name!r} is reserved (SDFormat keeps 'world' and names starting with '__')"
    return None


def _Vector(where: Callable[[], str], what: str, values, *, nonzero: bool = False) -> np.ndarray:
    """Three finite numbers within +-MAX_MAGNITUDE; ``where()`` names them in an error."""
    v = np.asarray(values, dtype=float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise OverlayError(f"{where()}: {what} must be three finite numbers, got {values}")
    if np.max(np.abs(v)) > MAX_MAGNITUDE:
        raise OverlayError(f"{where()}: {what} must be within +-{MAX_MAGNITUDE:g}, got {values}")
    if nonzero and np.linalg.norm(v) < 1e-12:
        raise OverlayError(f"{where()}: {what} must not be zero, got {values}")
    return v


def _Positive(
    where: Callable[[], str], what: str, value: float, *, allow_zero: bool = False
) -> float:
    if not (math.isfinite(value) and (value > 0 or (allow_zero and value == 0))):
        bound = ">= 0" if allow_zero else "> 0"
        raise OverlayError(f"{where()}: {what} must be {bound}, got {value}")
    if value > MAX_MAGNITUDE:
        raise OverlayError(f"{where()}: {what} must be <= {MAX_MAGNITUDE:g}, got {value}")
    return value


def ValidateOverlay(overlay: Overlay, source: str = "overlay", text: str | None = None) -> None:
    """Checks what can be checked without the robot: sizes, names, vectors.

    Raises:
        OverlayError: naming ``source`` (and the line, when ``text`` is given) and the element.
    """

    def where(name: str) -> str:
        line = LineOf(text, [name]) if text else None
        return f"{source}:{line}: '{name}'" if line else f"{source}: '{name}'"

    def At(name: str):
        """Where ``name`` is, found only when an error is raised (LineOf reads the whole text)."""
        return lambda: where(name)

    _Positive(lambda: source, "default_field", overlay.default_field, allow_zero=True)
    names = set()
    for p in overlay.primitives:
        w = At(p.name or "<unnamed primitive>")
        if not p.name or p.name in names:
            raise OverlayError(f"{w()}: every primitive needs a unique name")
        if problem := NameProblem(p.name):
            raise OverlayError(f"{w()}: {problem}")
        names.add(p.name)
        shape = p.shape
        if isinstance(shape, Sphere):
            _Vector(w, "center", shape.center)
            _Positive(w, "radius", shape.radius)
        elif isinstance(shape, Capsule):
            start, end = _Vector(w, "start", shape.start), _Vector(w, "end", shape.end)
            _Positive(w, "radius", shape.radius)
            _Positive(w, "capsule length |end - start|", float(np.linalg.norm(end - start)))
        else:
            _Vector(w, "center", shape.center)
            _Vector(w, "rpy_deg", shape.rpy_deg)
            for extent in _Vector(w, "size", shape.size):
                _Positive(w, "size", float(extent))
        if p.field is not None:
            _Positive(w, "field", p.field, allow_zero=True)
    for group in overlay.exclude:
        for name in group:
            if name not in names:
                raise OverlayError(f"{where(name)}: exclusion names an unknown primitive")
    marker_names = set()
    for m in overlay.markers:
        w = At(m.name or "<unnamed marker>")
        if not m.name or m.name in marker_names:
            raise OverlayError(f"{w()}: every marker needs a unique name")
        if problem := NameProblem(m.name):
            raise OverlayError(f"{w()}: {problem}")
        marker_names.add(m.name)
        _Vector(w, "position", m.position)
        _Vector(w, "direction", m.direction, nonzero=True)
    for clause in overlay.clauses:
        w = At(clause.name or "<unnamed clause>")
        if not clause.literals:
            raise OverlayError(f"{w()}: a clause needs at least one literal")
        for literal in clause.literals:
            a = np.array(list(literal.coefficients.values()), dtype=float)
            if (
                a.size == 0
                or not np.all(np.isfinite(a))
                or not np.any(a != 0)
                or np.max(np.abs(a)) > MAX_MAGNITUDE
            ):
                raise OverlayError(
                    f"{w()}: a literal needs finite, not all zero coefficients within "
                    f"+-{MAX_MAGNITUDE:g}, got {literal.coefficients}"
                )
            if not (math.isfinite(literal.offset) and abs(literal.offset) <= MAX_MAGNITUDE):
                raise OverlayError(
                    f"{w()}: offset must be finite and within +-{MAX_MAGNITUDE:g}, "
                    f"got {literal.offset}"
                )


def LoadOverlay(filename: str | pathlib.Path) -> Overlay:
    """Loads and validates an overlay file (see ``models/icub_overlay.yaml``)."""
    overlay = LoadYamlFile(schema=Overlay, filename=filename)
    ValidateOverlay(overlay, str(filename), pathlib.Path(filename).read_text(encoding="utf-8"))
    return overlay


@dc.dataclass(frozen=True)
class BodyMarker:
    """A marker fixed on a body: point ``p_BM`` and unit direction ``u_B``, in the body frame."""

    name: str
    body_name: str
    p_BM: np.ndarray
    u_B: np.ndarray


def MarkerStates(markers, bodies, plant_context, out: np.ndarray | None = None) -> np.ndarray:
    """(2, m, 3): each marker's position and unit direction in world, for markers fixed on
    ``bodies`` (one per marker) of the plant whose ``plant_context`` is given."""
    out = np.empty((2, len(markers), 3)) if out is None else out
    if not markers:
        return out
    # One numpy product over all markers (pydrake's shape-matching product costs ~5 us a call).
    X_WB = np.array([body.EvalPoseInWorld(plant_context).GetAsMatrix34() for body in bodies])
    p_BM = np.array([marker.p_BM for marker in markers])
    u_B = np.array([marker.u_B for marker in markers])
    out[0] = np.einsum("mij,mj->mi", X_WB[:, :, :3], p_BM) + X_WB[:, :, 3]
    out[1] = np.einsum("mij,mj->mi", X_WB[:, :, :3], u_B)
    return out


@dc.dataclass(frozen=True)
class RobotOverlay:
    """An overlay applied to one robot of a plant."""

    overlay: Overlay
    instance: ModelInstanceIndex
    # The field margin (m) of each of the robot's proximity geometries.
    field_margins: Mapping[GeometryId, float]
    geometry_names: Mapping[GeometryId, str]
    # A frame of the plant fixed to each geometry's frame (where SceneGraph reports witness points).
    geometry_frames: Mapping[GeometryId, FrameIndex]
    markers: tuple[BodyMarker, ...]
    # The angle (rad) of each joint of the model that was welded instead of controlled.
    frozen_joints: Mapping[str, float] = dc.field(default_factory=dict)
    # The joints that move with a controlled one (a motor's other joints: robots/couplings.py).
    couplings: tuple[JointCoupling, ...] = ()


def ZeroConfigurationPoses(
    add_model: Callable[[MultibodyPlant], ModelInstanceIndex], reference_link: str
) -> dict[str, RigidTransform]:
    """Poses ``X_RL`` of every link L in the reference link R with every joint at zero.

    ``add_model`` adds the robot to a scratch plant, exactly as it was added to the real one.
    """
    scratch = MultibodyPlant(0.0)
    instance = add_model(scratch)
    reference = scratch.GetBodyByName(reference_link, instance)
    has_parent = any(
        scratch.get_joint(j).child_body().index() == reference.index()
        for j in scratch.GetJointIndices(instance)
    )
    if not has_parent:  # A free root: fix it where the real robot is fixed.
        scratch.WeldFrames(scratch.world_frame(), reference.body_frame())
    scratch.Finalize()
    context = scratch.CreateDefaultContext()
    scratch.SetPositions(context, np.zeros(scratch.num_positions()))
    X_RW = reference.EvalPoseInWorld(context).inverse()
    return {
        scratch.get_body(i).name(): X_RW @ scratch.get_body(i).EvalPoseInWorld(context)
        for i in scratch.GetBodyIndices(instance)
    }


def ApplyOverlay(
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    instance: ModelInstanceIndex,
    overlay: Overlay,
    reference_poses: Mapping[str, RigidTransform],
    frozen_joints: Mapping[str, float] | None = None,
    source: str = "overlay",
) -> RobotOverlay:
    """Registers the overlay's primitives as proximity geometry of ``instance`` and its exclusions.

    Must be called before ``plant.Finalize()``. ``reference_poses`` comes from
    :func:`ZeroConfigurationPoses`; ``frozen_joints`` the angles of the joints that were welded.

    Raises:
        OverlayError: naming ``source`` and the element, for a link the robot does not have.
    """
    ValidateOverlay(overlay, source)

    def link_pose(link: str, element: str) -> RigidTransform:
        if link not in reference_poses or not plant.HasBodyNamed(link, instance):
            raise OverlayError(f"{source}: '{element}' is attached to unknown link '{link}'")
        return reference_poses[link]

    margins, names, frames, by_name = {}, {}, {}, {}
    for p in overlay.primitives:
        X_RL = link_pose(p.link, p.name)
        shape = p.shape
        if isinstance(shape, Sphere):
            X_RG = RigidTransform(shape.center)
            drake_shape = DrakeSphere(shape.radius)
        elif isinstance(shape, Capsule):
            start, end = np.asarray(shape.start), np.asarray(shape.end)
            axis = end - start
            X_RG = RigidTransform(RotationMatrix.MakeFromOneVector(axis, 2), (start + end) / 2)
            drake_shape = DrakeCapsule(shape.radius, float(np.linalg.norm(axis)))
        else:
            X_RG = RigidTransform(RollPitchYaw(np.radians(shape.rpy_deg)), shape.center)
            drake_shape = DrakeBox(*shape.size)
        properties = ProximityProperties()
        AddContactMaterial(friction=CoulombFriction(0.5, 0.5), properties=properties)
        body = plant.GetBodyByName(p.link, instance)
        X_BG = X_RL.inverse() @ X_RG
        geometry_id = plant.RegisterCollisionGeometry(body, X_BG, drake_shape, p.name, properties)
        frames[geometry_id] = plant.AddFrame(
            FixedOffsetFrame(f"{p.name}_geometry", body.body_frame(), X_BG)
        ).index()
        margins[geometry_id] = overlay.default_field if p.field is None else p.field
        names[geometry_id] = p.name
        by_name[p.name] = geometry_id

    manager = scene_graph.collision_filter_manager()
    for group in overlay.exclude:
        manager.Apply(
            CollisionFilterDeclaration().ExcludeWithin(
                GeometrySet([by_name[name] for name in group])
            )
        )

    markers = []
    for m in overlay.markers:
        X_LR = link_pose(m.link, m.name).inverse()
        u = np.asarray(m.direction, dtype=float)
        markers.append(
            BodyMarker(
                name=m.name,
                body_name=m.link,
                p_BM=X_LR @ np.asarray(m.position),
                u_B=X_LR.rotation() @ (u / np.linalg.norm(u)),
            )
        )
    return RobotOverlay(
        overlay=overlay,
        instance=instance,
        field_margins=margins,
        geometry_names=names,
        geometry_frames=frames,
        markers=tuple(markers),
        frozen_joints=dict(frozen_joints or {}),
    )
