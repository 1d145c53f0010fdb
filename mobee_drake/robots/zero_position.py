"""MoBeE's robot format: the ``ZeroPositionKinematicTree`` XML (dissertation ch. 2.3.1, App. B).

In zero reference position (ZP) notation every vector is written in the global frame with every
joint at zero: a ``<link>`` is a displacement ``b`` from the current point, a ``<joint>`` an axis
``u`` through the current point, and the nesting of the elements is the kinematic tree. This
module reads such a file into a Drake model (an SDFormat string: one body per joint, its frame at
the joint's point and parallel to the world's at zero) and our own overlay
(:class:`~mobee_drake.robots.overlay.Overlay`: primitives, markers, constraint clauses in the
root's coordinates at zero), so a MoBeE robot file runs under MoBeE 2.0 like any other robot.

Where the source leaves a tag's meaning open, we chose (and ``docs/zero_position.md`` lists it):

- Numbers may contain blanks (``z="- .2"`` is -0.2). A ``<link>`` or ``<joint>`` with ``length``
  has the direction of its vector and that length; without, the vector itself.
- ``radius`` of a link is a solid capsule along it; of a joint with ``length``, a solid capsule of
  that length along its axis, centred on the joint; zero or absent: no geometry. ``field`` of a
  link or joint is the radius of its force-field volume, so the field margin is
  ``field - radius``; absent, the overlay's default margin (3 cm). Every primitive is attached to
  the body of its innermost enclosing joint (the root body outside every joint).
- ``px, py, pz`` of a ``<sphere>``, ``<cylinder>`` or ``<box>`` are relative to the current point,
  i.e. to the end of the enclosing link (the joint's point directly inside a joint). A box's
  ``height`` runs along ``(hx, hy, hz)`` (default z), ``width`` and ``depth`` along the axes that
  axis's shortest rotation carries x and y to, turned by ``angle`` degrees about it. The boolean
  ``field`` makes a sphere a pure field volume (a 1 mm solid with the rest as field margin);
  field boxes and cylinders are refused.
- A ``<marker>`` is the current point; its direction is the enclosing link's.
- A body's primitives do not interact with its parent's (Drake filters those) nor with its
  grandparent's: ZP models put consecutive joints at one point (a wrist), where the links on
  either side always touch. (Drake 1.51 also never returns from the signed distance of two
  capsules whose axes meet exactly at an end, as they do there.)
- A ``<motor>`` maps its interval ``[minPos, maxPos]`` affinely onto each of its joints' intervals;
  its ``home`` (motor degrees) defaults to the middle of its interval. Motors are numbered from 0
  in document order within their ``<bodypart>``, which is what a ``<constraint>``'s ``q`` indexes.
- A ``<constraintList>`` is one clause of the CNF (satisfied while any of its constraints holds);
  the robot's constraint set is the conjunction of all lists. A ``<constraint a q b>`` is
  ``a . m < b`` over motor angles in degrees, turned into a literal over the motors' (first)
  joints.
- Joints are named ``<bodypart>_<k>`` (``k`` counting the bodypart's joints in document order)
  unless they carry a ``name``; bodies ``<joint name>_link``; the root body is ``base``.
"""

import dataclasses as dc
import math
import pathlib
import xml.parsers.expat

import numpy as np
from pydrake.common.eigen_geometry import AngleAxis
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.parsing import Parser

from mobee_drake.resources import ResolveModelFile
from mobee_drake.robots.assembly import AddModelWithOverlay
from mobee_drake.robots.overlay import (
    Box,
    Capsule,
    Clause,
    Literal,
    Marker,
    Overlay,
    Primitive,
    Sphere,
    ValidateOverlay,
)

ROOT_BODY = "base"
# The solid core of a field sphere (m).
FIELD_SPHERE_CORE = 0.001

_ATTRIBUTES = {
    "ZeroPositionKinematicTree": {"version", "robotName"},
    "bodypart": {"name"},
    "link": {"x", "y", "z", "length", "radius", "field"},
    "joint": {"x", "y", "z", "minPos", "maxPos", "length", "radius", "field", "name"},
    "motor": {"minPos", "maxPos", "home", "name"},
    "constraintList": set(),
    "constraint": {"a", "q", "b"},
    "marker": {"name"},
    "sphere": {"radius", "px", "py", "pz", "field"},
    "cylinder": {"radius", "height", "px", "py", "pz", "hx", "hy", "hz", "field"},
    "box": {"height", "width", "depth", "px", "py", "pz", "hx", "hy", "hz", "angle", "field"},
}


class ZeroPositionError(ValueError):
    """A robot file that cannot be read: the message names the file, the line and the element."""


@dc.dataclass
class _Element:
    tag: str
    attributes: dict[str, str]
    line: int
    children: list["_Element"] = dc.field(default_factory=list)


@dc.dataclass(frozen=True)
class Motor:
    """One motor: ``joint = joint_min + (motor - motor_min) * scale`` for each of its joints."""

    name: str
    bodypart: str
    index: int  # within its bodypart
    joints: tuple[str, ...]
    motor_range: tuple[float, float]  # degrees
    joint_ranges: tuple[tuple[float, float], ...]  # degrees, one per joint
    home: float  # degrees of the motor

    def JointAngles(self, motor: float) -> list[float]:
        """The joints' angles (degrees) at a motor angle (degrees)."""
        low, high = self.motor_range
        t = (motor - low) / (high - low)
        return [a + t * (b - a) for a, b in self.joint_ranges]


@dc.dataclass(frozen=True)
class ZeroPositionRobot:
    """A robot read from a ``ZeroPositionKinematicTree`` file."""

    name: str
    source: str
    sdf: str  # the kinematic tree, for Drake's parser
    overlay: Overlay  # in the root body's coordinates with every joint at zero
    motors: tuple[Motor, ...]
    joints: tuple[str, ...]

    @property
    def home(self) -> dict[str, float]:
        """Every joint's home angle (radians), from its motor's home."""
        return {
            joint: math.radians(angle)
            for motor in self.motors
            for joint, angle in zip(motor.joints, motor.JointAngles(motor.home))
        }


def _ParseXml(text: str, source: str) -> _Element:
    """The element tree of ``text``, each element with the line it starts on."""
    parser = xml.parsers.expat.ParserCreate()
    stack: list[_Element] = []
    roots: list[_Element] = []

    def Start(tag, attributes):
        element = _Element(tag, dict(attributes), parser.CurrentLineNumber)
        (stack[-1].children if stack else roots).append(element)
        stack.append(element)

    parser.StartElementHandler = Start
    parser.EndElementHandler = lambda tag: stack.pop()
    try:
        parser.Parse(text, True)
    except xml.parsers.expat.ExpatError as error:
        raise ZeroPositionError(
            f"{source}:{error.lineno}: malformed XML: {xml.parsers.expat.ErrorString(error.code)}"
        ) from None
    return roots[0]


class _Reader:
    """Walks the element tree, keeping the current point and body, collecting the model."""

    def __init__(self, source: str):
        self.source = source
        self.joints_sdf: list[str] = []
        self.joint_points: dict[str, np.ndarray] = {ROOT_BODY: np.zeros(3)}
        self.parents: dict[str, str] = {}
        self.joints: list[str] = []
        self.motors: list[Motor] = []
        self.primitives: list[Primitive] = []
        self.markers: list[Marker] = []
        self.clauses: list[Clause] = []

    # ---- attributes -------------------------------------------------------------------------
    def Where(self, element: _Element) -> str:
        return f"{self.source}:{element.line}: <{element.tag}>"

    def Fail(self, element: _Element, message: str):
        raise ZeroPositionError(f"{self.Where(element)}: {message}")

    def Number(self, element: _Element, name: str, default: float | None = None) -> float:
        text = element.attributes.get(name)
        if text is None:
            if default is None:
                self.Fail(element, f"needs the attribute '{name}'")
            return default
        try:
            value = float(text.replace(" ", ""))
        except ValueError:
            self.Fail(element, f'{name}="{text}" is not a number')
        if not math.isfinite(value):
            self.Fail(element, f'{name}="{text}" is not finite')
        return value

    def Vector(
        self,
        element: _Element,
        names: tuple[str, str, str],
        default: tuple[float, float, float] = (0.0, 0.0, 0.0),
    ) -> np.ndarray:
        return np.array([self.Number(element, n, d) for n, d in zip(names, default)])

    def SolidPlacement(self, element: _Element, state: dict) -> tuple[np.ndarray, np.ndarray]:
        """A solid cylinder's or box's centre (px, py, pz from the current point) and axis
        (hx, hy, hz: z when none is given, missing components zero)."""
        if self.Flag(element, "field"):
            self.Fail(element, "field volumes are supported for spheres only")
        centre = state["point"] + self.Vector(element, ("px", "py", "pz"))
        names = ("hx", "hy", "hz")
        axis = (
            self.Vector(element, names)
            if any(n in element.attributes for n in names)
            else np.array([0.0, 0.0, 1.0])
        )
        if not np.any(axis):
            self.Fail(element, "its axis (hx, hy, hz) is zero")
        return centre, axis

    def Flag(self, element: _Element, name: str) -> bool:
        text = element.attributes.get(name, "false").strip().lower()
        if text not in ("true", "false", "1", "0"):
            self.Fail(element, f'{name}="{text}" is not a boolean (true or false)')
        return text in ("true", "1")

    def Direction(self, element: _Element) -> tuple[np.ndarray, np.ndarray]:
        """The element's vector (scaled to its ``length``, if given) and its unit direction."""
        v = self.Vector(element, ("x", "y", "z"))
        norm = float(np.linalg.norm(v))
        if norm == 0.0:
            self.Fail(element, "its vector (x, y, z) is zero")
        length = self.Number(element, "length", norm)
        return v / norm * length, v / norm

    def Radius(self, element: _Element, name: str = "radius") -> float:
        value = self.Number(element, name, 0.0)
        if value < 0:
            self.Fail(element, f"{name} must be >= 0, got {value}")
        return value

    def Margin(self, element: _Element, radius: float) -> float | None:
        """The field margin of a link or joint whose field radius is ``field``."""
        if "field" not in element.attributes:
            return None
        field = self.Number(element, "field")
        if field < radius:
            self.Fail(element, f"field {field} is smaller than radius {radius}")
        return field - radius

    # ---- the tree ---------------------------------------------------------------------------
    def Read(self, root: _Element) -> None:
        if root.tag != "ZeroPositionKinematicTree":
            self.Fail(root, "the root element must be <ZeroPositionKinematicTree>")
        self.CheckAttributes(root)
        parts = set()
        for child in root.children:
            if child.tag != "bodypart":
                self.Fail(child, "only <bodypart> may sit at the top level")
            self.CheckAttributes(child)
            name = child.attributes.get("name", "").strip()
            if not name or name in parts:
                self.Fail(child, f"every bodypart needs a unique name, got '{name}'")
            parts.add(name)
            state = dict(
                part=name,
                point=np.zeros(3),
                body=ROOT_BODY,
                direction=np.zeros(3),
                motor=None,
                counters={"joint": 0, "motor": 0},
                part_motors=[],
                lists=[],
            )
            self.Children(child, state)
            motors = sorted(state["part_motors"], key=lambda m: m.index)  # document order
            self.motors.extend(motors)
            for element in state["lists"]:
                self.Constraints(element, motors)

    def CheckAttributes(self, element: _Element) -> None:
        if element.tag not in _ATTRIBUTES:
            self.Fail(
                element,
                "unknown element; MoBeE's elements are: "
                + ", ".join(f"<{t}>" for t in _ATTRIBUTES),
            )
        unknown = sorted(set(element.attributes) - _ATTRIBUTES[element.tag])
        if unknown:
            self.Fail(
                element,
                f"unknown attribute(s) {unknown}; <{element.tag}> takes: "
                + (", ".join(sorted(_ATTRIBUTES[element.tag])) or "none"),
            )

    def Children(self, element: _Element, state: dict) -> None:
        for child in element.children:
            self.CheckAttributes(child)
            handler = getattr(self, f"_{child.tag}", None)
            if handler is None or child.tag in ("ZeroPositionKinematicTree", "bodypart"):
                self.Fail(child, f"<{child.tag}> cannot sit inside <{element.tag}>")
            handler(child, dict(state))

    def _link(self, element: _Element, state: dict) -> None:
        b, u = self.Direction(element)
        start = state["point"]
        radius = self.Radius(element)
        if radius > 0:
            self.AddPrimitive(
                element,
                state["body"],
                Capsule(start=start.tolist(), end=(start + b).tolist(), radius=radius),
                self.Margin(element, radius),
            )
        state.update(point=start + b, direction=u)
        self.Children(element, state)

    def _motor(self, element: _Element, state: dict) -> None:
        if state["motor"] is not None:
            self.Fail(element, "a motor cannot sit inside another motor")
        low, high = self.Number(element, "minPos"), self.Number(element, "maxPos")
        if low >= high:
            self.Fail(element, f"minPos {low} must be smaller than maxPos {high}")
        home = self.Number(element, "home", (low + high) / 2)
        if not low <= home <= high:
            self.Fail(element, f"home {home} is outside [{low}, {high}]")
        index = state["counters"]["motor"]
        state["counters"]["motor"] += 1
        state["motor"] = dict(element=element, joints=[], ranges=[])
        self.Children(element, state)
        motor = state["motor"]
        if not motor["joints"]:
            self.Fail(element, "a motor must drive at least one joint")
        name = element.attributes.get("name", f"{state['part']}_motor_{index}")
        state["part_motors"].append(
            Motor(
                name=name,
                bodypart=state["part"],
                index=index,
                joints=tuple(motor["joints"]),
                motor_range=(low, high),
                joint_ranges=tuple(motor["ranges"]),
                home=home,
            )
        )

    def _joint(self, element: _Element, state: dict) -> None:
        if state["motor"] is None:
            self.Fail(element, "a joint must sit inside the motor that drives it")
        _, axis = self.Direction(element)
        low, high = self.Number(element, "minPos"), self.Number(element, "maxPos")
        if low >= high:
            self.Fail(element, f"minPos {low} must be smaller than maxPos {high}")
        name = element.attributes.get("name", f"{state['part']}_{state['counters']['joint']}")
        state["counters"]["joint"] += 1
        if name in self.joints:
            self.Fail(element, f"a second joint named '{name}'")
        self.joints.append(name)
        state["motor"]["joints"].append(name)
        state["motor"]["ranges"].append((low, high))
        point, parent = state["point"], state["body"]
        body = f"{name}_link"
        self.joint_points[body] = point
        self.parents[body] = parent
        self.joints_sdf.append(
            f'<joint name="{name}" type="revolute"><parent>{parent}</parent>'
            f"<child>{body}</child><axis><xyz>{_Xyz(axis)}</xyz><limit>"
            f"<lower>{math.radians(low)!r}</lower><upper>{math.radians(high)!r}</upper>"
            "<effort>0</effort></limit></axis></joint>"
        )  # no actuator: FreezeJoints adds them
        radius = self.Radius(element)
        if radius > 0 and "length" in element.attributes:
            half = axis * self.Number(element, "length") / 2
            self.AddPrimitive(
                element,
                body,
                Capsule(start=(point - half).tolist(), end=(point + half).tolist(), radius=radius),
                self.Margin(element, radius),
            )
        state.update(body=body, motor=None)
        self.Children(element, state)

    def _marker(self, element: _Element, state: dict) -> None:
        name = element.attributes.get("name", "").strip()
        if not name or any(m.name == name for m in self.markers):
            self.Fail(element, f"every marker needs a unique name, got '{name}'")
        direction = state["direction"] if np.any(state["direction"]) else np.array([0, 0, 1.0])
        self.markers.append(
            Marker(
                name=name,
                link=state["body"],
                position=state["point"].tolist(),
                direction=direction.tolist(),
            )
        )
        self.Children(element, state)

    def _sphere(self, element: _Element, state: dict) -> None:
        centre = state["point"] + self.Vector(element, ("px", "py", "pz"))
        radius = self.Number(element, "radius")
        if radius <= 0:
            self.Fail(element, f"radius must be > 0, got {radius}")
        if self.Flag(element, "field"):
            self.AddPrimitive(
                element,
                state["body"],
                Sphere(center=centre.tolist(), radius=FIELD_SPHERE_CORE),
                max(radius - FIELD_SPHERE_CORE, 0.0),
            )
        else:
            self.AddPrimitive(
                element, state["body"], Sphere(center=centre.tolist(), radius=radius), None
            )
        self.Children(element, state)

    def _cylinder(self, element: _Element, state: dict) -> None:
        centre, axis = self.SolidPlacement(element, state)
        radius, height = self.Number(element, "radius"), self.Number(element, "height")
        if radius <= 0 or height <= 0:
            self.Fail(element, f"radius and height must be > 0, got {radius}, {height}")
        # A capsule as long as the cylinder (our overlay's round-ended cylinder).
        half = axis / np.linalg.norm(axis) * max(height / 2 - radius, 1e-4)
        self.AddPrimitive(
            element,
            state["body"],
            Capsule(start=(centre - half).tolist(), end=(centre + half).tolist(), radius=radius),
            None,
        )
        self.Children(element, state)

    def _box(self, element: _Element, state: dict) -> None:
        centre, axis = self.SolidPlacement(element, state)
        size = [
            self.Number(element, "width"),
            self.Number(element, "depth"),
            self.Number(element, "height"),
        ]
        if min(size) <= 0:
            self.Fail(element, f"width, depth and height must be > 0, got {size}")
        rotation = _ShortestRotation(axis) @ RotationMatrix.MakeZRotation(
            math.radians(self.Number(element, "angle", 0.0))
        )
        rpy = np.degrees(RollPitchYaw(rotation).vector())
        self.AddPrimitive(
            element,
            state["body"],
            Box(center=centre.tolist(), size=size, rpy_deg=rpy.tolist()),
            None,
        )
        self.Children(element, state)

    def _constraintList(self, element: _Element, state: dict) -> None:
        state["lists"].append(element)  # read once the bodypart's motors are all known

    def _constraint(self, element: _Element, state: dict) -> None:
        self.Fail(element, "a constraint must sit inside a <constraintList>")

    def Constraints(self, element: _Element, motors: list[Motor]) -> None:
        literals = []
        for child in element.children:
            self.CheckAttributes(child)
            if child.tag != "constraint":
                self.Fail(child, "only <constraint> may sit inside a <constraintList>")
            a = self.Numbers(child, "a", float)
            q = self.Numbers(child, "q", int)
            if len(a) != len(q) or not a:
                self.Fail(child, f"a has {len(a)} values and q {len(q)}; they must match")
            b = self.Number(child, "b")
            coefficients: dict[str, float] = {}
            offset = b
            for a_i, index in zip(a, q):
                if not 0 <= index < len(motors):
                    self.Fail(
                        child,
                        f"q names motor {index}, but this bodypart has "
                        f"{len(motors)} motors (0..{len(motors) - 1})",
                    )
                motor = motors[index]
                # a . m < b with m = m_low + (joint - j_low) * (m_high - m_low) / (j_high - j_low)
                (m_low, m_high), (j_low, j_high) = motor.motor_range, motor.joint_ranges[0]
                scale = (m_high - m_low) / (j_high - j_low)
                joint = motor.joints[0]
                coefficients[joint] = coefficients.get(joint, 0.0) - a_i * scale
                offset -= a_i * (m_low - j_low * scale)
            literals.append(Literal(coefficients=coefficients, offset=offset))
        if not literals:
            self.Fail(element, "a constraintList needs at least one constraint")
        self.clauses.append(Clause(name=f"line {element.line}", literals=literals))

    def Numbers(self, element: _Element, name: str, kind) -> list:
        text = element.attributes.get(name)
        if text is None:
            self.Fail(element, f"needs the attribute '{name}'")
        try:
            return [kind(v) for v in text.replace(",", " ").split()]
        except ValueError:
            self.Fail(
                element,
                f'{name}="{text}" is not a list of {"integers" if kind is int else "numbers"}',
            )

    def LinkSdf(self, body: str) -> str:
        """A body as an SDFormat <link>: its pose at zero (parallel to its parent's, at its
        joint's point), a small inertia (a massless body cannot be simulated dynamically) and its
        primitives drawn as visuals."""
        origin = self.joint_points[body]
        visuals = "".join(_Visual(p, origin) for p in self.primitives if p.link == body)
        if body == ROOT_BODY:
            return f'<link name="{body}">{visuals}</link>'
        parent = self.parents[body]
        return (
            f'<link name="{body}"><pose relative_to="{parent}">'
            f"{_Xyz(origin - self.joint_points[parent])} 0 0 0</pose>{visuals}"
            "<inertial><mass>0.1</mass><inertia><ixx>1e-4</ixx><iyy>1e-4</iyy>"
            "<izz>1e-4</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial></link>"
        )

    def Exclusions(self) -> list[list[str]]:
        """Per body, its primitives with those of its parent and grandparent (see the module)."""
        on_body: dict[str, list[str]] = {}
        for primitive in self.primitives:
            on_body.setdefault(primitive.link, []).append(primitive.name)
        groups = []
        for body, parent in self.parents.items():
            chain = [body, parent, self.parents.get(parent)]
            group = [name for b in chain if b for name in on_body.get(b, [])]
            if len(group) >= 2:
                groups.append(group)
        return groups

    def AddPrimitive(self, element: _Element, body: str, shape, margin: float | None) -> None:
        name = f"{element.tag}_line{element.line}"
        self.primitives.append(Primitive(name=name, link=body, shape=shape, field=margin))


VISUAL_COLOR = "1.0 0.55 0.1 1"


def _Visual(primitive: Primitive, body_origin: np.ndarray) -> str:
    """An SDFormat <visual> of a primitive, on a body whose frame sits at ``body_origin`` and is
    parallel to the root's at zero."""
    shape = primitive.shape
    if isinstance(shape, Sphere):
        X = RigidTransform(np.asarray(shape.center) - body_origin)
        geometry = f"<sphere><radius>{shape.radius!r}</radius></sphere>"
    elif isinstance(shape, Capsule):
        start, end = np.asarray(shape.start), np.asarray(shape.end)
        X = RigidTransform(
            RotationMatrix.MakeFromOneVector(end - start, 2), (start + end) / 2 - body_origin
        )
        geometry = (
            f"<capsule><radius>{shape.radius!r}</radius>"
            f"<length>{float(np.linalg.norm(end - start))!r}</length></capsule>"
        )
    else:
        X = RigidTransform(
            RollPitchYaw(np.radians(shape.rpy_deg)), np.asarray(shape.center) - body_origin
        )
        geometry = f"<box><size>{_Xyz(np.asarray(shape.size))}</size></box>"
    rpy = RollPitchYaw(X.rotation()).vector()
    return (
        f'<visual name="{primitive.name}"><pose>{_Xyz(X.translation())} {_Xyz(rpy)}</pose>'
        f"<geometry>{geometry}</geometry><material><diffuse>{VISUAL_COLOR}</diffuse>"
        "</material></visual>"
    )


def _Xyz(v: np.ndarray) -> str:
    return " ".join(repr(float(c)) for c in v)


def _ShortestRotation(axis: np.ndarray) -> RotationMatrix:
    """The rotation by the smallest angle that carries z onto ``axis``."""
    z, a = np.array([0.0, 0.0, 1.0]), axis / np.linalg.norm(axis)
    cross, cosine = np.cross(z, a), float(z @ a)
    if np.linalg.norm(cross) < 1e-12:
        return RotationMatrix() if cosine > 0 else RotationMatrix.MakeXRotation(math.pi)
    angle = math.atan2(float(np.linalg.norm(cross)), cosine)
    return RotationMatrix(AngleAxis(angle, cross / np.linalg.norm(cross)))


def LoadZeroPositionTree(filename: str | pathlib.Path) -> ZeroPositionRobot:
    """Reads a ``ZeroPositionKinematicTree`` file.

    Raises:
        ZeroPositionError: naming the file, the line and the element, for malformed XML, unknown
            elements or attributes, bad numbers, limits with min >= max, or a constraint naming a
            motor that does not exist.
    """
    source = str(filename)
    try:
        text = pathlib.Path(filename).read_text()
    except OSError as error:
        raise ZeroPositionError(f"{source}: cannot read: {error.strerror}") from None
    root = _ParseXml(text, source)
    reader = _Reader(source)
    reader.Read(root)
    name = root.attributes.get("robotName", pathlib.Path(source).stem)
    overlay = Overlay(
        reference_link=ROOT_BODY,
        primitives=reader.primitives,
        exclude=reader.Exclusions(),
        markers=reader.markers,
        clauses=reader.clauses,
    )
    ValidateOverlay(overlay, source)
    sdf = (
        f'<?xml version="1.0"?><sdf version="1.9"><model name="{name}">'
        + "".join(reader.LinkSdf(body) for body in reader.joint_points)
        + "".join(reader.joints_sdf)
        + "</model></sdf>"
    )
    return ZeroPositionRobot(
        name=name,
        source=source,
        sdf=sdf,
        overlay=overlay,
        motors=tuple(reader.motors),
        joints=tuple(reader.joints),
    )


def AddZeroPositionRobot(
    plant,
    scene_graph,
    robot: ZeroPositionRobot,
    *,
    controlled_joints: list[str] | None = None,
    X_WRoot: RigidTransform | None = None,
    model_name: str | None = None,
):
    """Adds ``robot`` with its overlay to an unfinalized ``plant``, its root body welded at
    ``X_WRoot``; joints not in ``controlled_joints`` (all, by default) are welded at home."""
    name = model_name or robot.name
    return AddModelWithOverlay(
        plant,
        scene_graph,
        add_model=lambda p: Parser(p, name).AddModelsFromString(robot.sdf, "sdf")[0],
        overlay=robot.overlay,
        controlled_joints=robot.joints if controlled_joints is None else controlled_joints,
        home=robot.home,
        X_WRoot=X_WRoot,
        model_source=robot.source,
        overlay_source=robot.source,
    )


@dc.dataclass
class ZeroPositionConfig:
    """A robot of a scenario read from a MoBeE XML file (e.g. ``katana.xml``)."""

    # The file: package://mobee_drake/..., a path, or a shipped model's name.
    file: str = "katana.xml"
    # The controlled joints; empty: every joint of a motor that drives one joint. (Motors that
    # drive several joints, like the Katana's gripper, are held at home: MoBeE 2.0 here controls
    # joints, not motors.)
    controlled_joints: list[str] = dc.field(default_factory=list)

    def Load(self) -> ZeroPositionRobot:
        return LoadZeroPositionTree(ResolveModelFile(self.file))

    def Joints(self, robot: ZeroPositionRobot) -> list[str]:
        return list(self.controlled_joints) or [
            m.joints[0] for m in robot.motors if len(m.joints) == 1
        ]
