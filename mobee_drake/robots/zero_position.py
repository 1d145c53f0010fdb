"""MoBeE's robot format: the ``ZeroPositionKinematicTree`` XML (dissertation ch. 2.3.1, App. B).

In zero reference position (ZP) notation every vector is written in the global frame with every
joint at zero: a ``<link>`` is a displacement ``b`` from the current point, a ``<joint>`` an axis
``u`` through the current point, and the nesting of the elements is the kinematic tree. This
module reads such a file into a Drake model (an SDFormat string: one body per joint, its frame at
the joint's point and parallel to the world's at zero) and our own overlay
(:class:`~mobee_drake.robots.overlay.Overlay`: primitives, markers, constraint clauses in the
root's coordinates at zero), so a MoBeE robot file runs under MoBeE 2.0 like any other robot.

The original MoBeE's reader (``zphandler.cpp``, ``kintreenode.cpp``, ``transformable.cpp`` of
its ``LibKinematicModel``) settles most readings; ``docs/zero_position.md`` lists each with its
source. In short:

- Like the original, an element inside a ``<link>`` or ``<joint>`` is placed in that *node's*
  frame, whose origin is where the node starts: ``px, py, pz`` of a ``<sphere>``, ``<cylinder>``
  or ``<box>`` and a ``<marker>``'s point are relative to the **start** of the enclosing link
  (the joint's point directly inside a joint); a link's own capsule runs from its start to its
  end. An element directly inside a joint does not turn with that joint (the original draws it
  before the joint's rotation): it belongs to the joint's parent body. (The joint's own capsule,
  the same solid at every angle, stays on the joint's body, for the collision filters below.)
  Primitives and markers outside every link and joint are refused, as by the original.
- A box's ``width, height, depth`` run along its own x, y, z; its height axis ``(hx, hy, hz)``
  defaults to y, and the box is turned as the original's ``setSpecialEulerOrientation`` turns it
  (:func:`PrimitiveRotation`); a cylinder's height runs along the same axis.
- ``length`` absent or 0 means the vector as given; a positive ``length`` rescales the vector;
  a joint with ``radius > 0`` has a capsule of that length along its axis, centred on it.
- ``version`` absent, empty or "1.0"; anything else is refused.
- Numbers: decimal literals only (``-0.2``, ``.5``, ``1e-3``; blanks around and between a sign
  and its digits allowed, so App. B's ``z="- .2"`` is -0.2). Blanks or ``_`` inside digits,
  ``nan``, ``inf`` and magnitudes above 1e6 (m, deg or a constraint's coefficient) are refused.
- Names of bodyparts, joints, motors, markers and the robot: letters, digits, ``_``, ``-``,
  ``.``; unique; a joint's name never that of a body (``base``, ``<joint>_link``).
- Files are read as bytes and decoded by expat per their XML declaration (UTF-8 by default);
  entity declarations, text inside elements and nesting deeper than :data:`MAX_DEPTH` are
  refused.
- ``field`` of a link or joint is the radius of its force-field volume, so the field margin is
  ``field - radius``; absent, the overlay's default margin (3 cm). The boolean ``field`` makes a
  sphere a pure field volume (a 1 mm solid with the rest as field margin); field boxes and
  cylinders are refused.
- A marker's direction is the enclosing link's.
- A body's primitives do not interact with its parent's (Drake filters those), its
  grandparent's (ZP models put consecutive joints at one point, a wrist, where the links on
  either side always touch) nor its siblings' (the original's ``ignoreAdjacentPairs``: a node and
  its siblings are never checked, e.g. a gripper's two fingers). (Drake 1.51 also never returns
  from the signed distance of two capsules whose axes meet exactly at an end, as they do there.)
- A ``<motor>`` maps its interval ``[minPos, maxPos]`` affinely onto each of its joints' intervals;
  its ``home`` (motor degrees) defaults to the middle of its interval. Motors are numbered from 0
  in document order within their ``<bodypart>``, which is what a ``<constraint>``'s ``q`` indexes.
- A ``<constraintList>`` is one clause of the CNF (satisfied while any of its constraints holds);
  the robot's constraint set is the conjunction of all lists. A ``<constraint a q b>`` is
  ``a . m < b`` over motor angles in degrees, turned into a literal over the motors' (first)
  joints.
- Joints are named ``<bodypart>_<k>`` (``k`` counting the bodypart's joints in document order)
  unless they carry a ``name``; bodies ``<joint name>_link``; the root body is ``base``;
  primitives ``<tag>_line<N>`` (``_2``, ``_3``, ... for more on one line).
"""

import dataclasses as dc
import math
import pathlib
import re
import xml.parsers.expat
from xml.sax.saxutils import escape, quoteattr

import numpy as np
from pydrake.common.eigen_geometry import AngleAxis
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from mobee_drake.resources import ResolveModelFile
from mobee_drake.robots.assembly import AddModelWithOverlay
from mobee_drake.robots.couplings import JointCoupling
from mobee_drake.robots.overlay import (
    MAX_MAGNITUDE,
    Box,
    Capsule,
    Clause,
    Literal,
    Marker,
    NameProblem,
    Overlay,
    Primitive,
    Sphere,
    ValidateOverlay,
)

ROOT_BODY = "base"
# The solid core of a field sphere (m).
FIELD_SPHERE_CORE = 0.001
# Elements may nest this deep (the Katana nests 21; a chain of link, motor and joint takes three
# levels a joint).
MAX_DEPTH = 200
# A link's or joint's vector shorter than this (m) gives no direction.
MIN_VECTOR = 1e-9
# Attributes in degrees, and a constraint's coefficients and motor indices (no unit); every other
# number is a length (m) or a component of a direction.
_DEGREES = {"minPos", "maxPos", "home", "angle"}
_COEFFICIENTS = {"a", "b", "q"}
# A decimal literal: digits with at most one point, an optional exponent.
_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_INTEGER = re.compile(r"\+?[0-9]+")
_BLANKS = " \t\r\n"

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
_IN_NODES = {"link", "joint", "motor", "marker", "sphere", "cylinder", "box", "constraintList"}
# What each element may hold.
_CHILDREN = {
    "ZeroPositionKinematicTree": {"bodypart"},
    "bodypart": _IN_NODES,
    "link": _IN_NODES,
    "joint": _IN_NODES,
    "motor": _IN_NODES,
    "constraintList": {"constraint"},
    "constraint": set(),
    "marker": set(),
    "sphere": set(),
    "cylinder": set(),
    "box": set(),
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
    def motor_joints(self) -> list[str]:
        """Each motor's first joint: MoBeE's degrees of freedom (the others follow)."""
        return [motor.joints[0] for motor in self.motors]

    @property
    def couplings(self) -> tuple[JointCoupling, ...]:
        """A motor that drives several joints is one degree of freedom: its first joint leads
        and the others follow (each motor's interval maps affinely onto each joint's)."""
        couplings = []
        for motor in self.motors:
            (low, high), *others = motor.joint_ranges
            for joint, (a, b) in zip(motor.joints[1:], others):
                ratio = (b - a) / (high - low)
                offset = math.radians(a - ratio * low)  # q_f = ratio q_leader + offset, rad
                couplings.append(JointCoupling(joint, motor.joints[0], ratio, offset))
        return tuple(couplings)

    @property
    def home(self) -> dict[str, float]:
        """Every joint's home angle (radians), from its motor's home."""
        return {
            joint: math.radians(angle)
            for motor in self.motors
            for joint, angle in zip(motor.joints, motor.JointAngles(motor.home))
        }


def _Shown(text: str, limit: int = 40) -> str:
    """``text`` for a one-line message: control and non-ASCII characters escaped, cut short."""
    shown = text.encode("unicode_escape").decode("ascii").replace('"', '\\"')
    return shown if len(shown) <= limit else shown[:limit] + "..."


def _DeclaredEncoding(data: bytes) -> str | None:
    match = re.match(rb"\s*<\?xml[^>]*?encoding\s*=\s*[\"']([A-Za-z0-9._-]+)[\"']", data)
    return match.group(1).decode("ascii") if match else None


def _ParseXml(data: bytes, source: str) -> _Element:
    """The element tree of ``data``, each element with the line it starts on, its elements,
    attributes and placement checked (iteratively: no nesting depth reaches Python's stack)."""
    parser = xml.parsers.expat.ParserCreate()
    stack: list[_Element] = []
    roots: list[_Element] = []

    def Fail(message: str):
        raise ZeroPositionError(f"{source}:{parser.CurrentLineNumber}: {message}")

    def Start(tag, attributes):
        element = _Element(tag, dict(attributes), parser.CurrentLineNumber)
        if tag not in _ATTRIBUTES:
            Fail(
                f"<{_Shown(tag)}>: unknown element; MoBeE's elements are: "
                + ", ".join(f"<{t}>" for t in _ATTRIBUTES)
            )
        unknown = sorted(set(element.attributes) - _ATTRIBUTES[tag])
        if unknown:
            Fail(
                f"<{tag}>: unknown attribute(s) {[_Shown(a) for a in unknown]}; <{tag}> takes: "
                + (", ".join(sorted(_ATTRIBUTES[tag])) or "none")
            )
        if not stack and tag != "ZeroPositionKinematicTree":
            Fail(f"<{tag}>: the root element must be <ZeroPositionKinematicTree>")
        if stack and tag not in _CHILDREN[stack[-1].tag]:
            allowed = _CHILDREN[stack[-1].tag]
            Fail(
                f"<{tag}>: cannot sit inside <{stack[-1].tag}>, which holds "
                + (", ".join(f"<{t}>" for t in sorted(allowed)) if allowed else "nothing")
            )
        if len(stack) >= MAX_DEPTH:
            Fail(f"<{tag}>: elements nested deeper than {MAX_DEPTH}")
        (stack[-1].children if stack else roots).append(element)
        stack.append(element)

    def Text(text):
        if text.strip(_BLANKS) and stack:
            Fail(f'<{stack[-1].tag}>: text "{_Shown(text.strip())}" is not part of the format')

    def Entity(name, *_):
        Fail(f"entity declarations are not allowed (<!ENTITY {_Shown(name)} ...>)")

    parser.StartElementHandler = Start
    parser.EndElementHandler = lambda tag: stack.pop()
    parser.CharacterDataHandler = Text
    parser.EntityDeclHandler = Entity
    try:
        parser.Parse(data, True)
    except xml.parsers.expat.ExpatError as error:
        reason = xml.parsers.expat.ErrorString(error.code)
        if error.code == xml.parsers.expat.errors.codes[
            xml.parsers.expat.errors.XML_ERROR_INVALID_TOKEN
        ] and not _DeclaredEncoding(data):
            try:
                data.decode("utf-8")
            except UnicodeDecodeError:
                reason = (
                    "not UTF-8 (declare the file's encoding, e.g. "
                    '<?xml version="1.0" encoding="ISO-8859-1"?>)'
                )
        raise ZeroPositionError(f"{source}:{error.lineno}: malformed XML: {reason}") from None
    except LookupError as error:  # an encoding Python does not know
        raise ZeroPositionError(f"{source}:1: malformed XML: {error}") from None
    return roots[0]


def _AxisAngle(axis: np.ndarray, angle: float) -> np.ndarray:
    """The right-handed rotation by ``angle`` about ``axis`` (identity for a zero axis)."""
    norm = float(np.linalg.norm(axis))
    if norm == 0.0:
        return np.eye(3)
    return RotationMatrix(AngleAxis(angle, axis / norm)).matrix()


def PrimitiveRotation(axis: np.ndarray, angle: float) -> RotationMatrix:
    """The orientation the original MoBeE gives a primitive whose height (its own y axis) runs
    along ``axis``, turned by ``angle`` (radians) about it: its ``setSpecialEulerOrientation``
    first turns about y until x points along the axis's projection on the xz plane (by the
    unsigned angle between them, skipped when the projection is zero), then carries y onto the
    axis by the shortest rotation, then turns about the axis. For an axis along -y the original
    produces a reflection; a box or cylinder centred on its origin is the same solid unturned.
    """
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    x, y = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    R = np.eye(3)
    xz = np.array([a[0], 0.0, a[2]])
    if np.linalg.norm(xz) > 1e-6:
        R = _AxisAngle(y, math.acos(np.clip(x @ xz / np.linalg.norm(xz), -1, 1))) @ R
    R = _AxisAngle(np.cross(y, a), math.acos(np.clip(a[1], -1, 1))) @ R
    R = _AxisAngle(a, angle) @ R
    return RotationMatrix(R)


class _Reader:
    """Walks the element tree, keeping the current point and body, collecting the model.

    The state handed to an element's children: ``point`` the current point (where a nested
    link or joint starts), ``origin`` the start of the innermost enclosing link or joint (where
    its own primitives and markers are placed; None outside every one), ``body`` the body a
    nested link moves with, ``frame_body`` the body the innermost node's own elements move with.
    """

    def __init__(self, source: str):
        self.source = source
        self.joints_sdf: list[str] = []
        self.joint_points: dict[str, np.ndarray] = {ROOT_BODY: np.zeros(3)}
        self.parents: dict[str, str] = {}
        self.joints: list[str] = []
        self.joint_names: set[str] = set()
        self.motors: list[Motor] = []
        self.primitives: list[Primitive] = []
        self.primitive_names: set[str] = set()
        self.markers: list[Marker] = []
        self.marker_names: set[str] = set()
        self.clauses: list[Clause] = []

    # ---- attributes -------------------------------------------------------------------------
    def Where(self, element: _Element) -> str:
        return f"{self.source}:{element.line}: <{element.tag}>"

    def Fail(self, element: _Element, message: str):
        raise ZeroPositionError(f"{self.Where(element)}: {message}")

    def Parse(self, element: _Element, name: str, text: str, pattern=_NUMBER) -> float:
        """A number written as a decimal literal (a sign may stand apart from its digits), finite
        and within the bounds of its kind."""
        compact = text.strip(_BLANKS)
        if compact[:1] in ("+", "-"):
            compact = compact[0] + compact[1:].lstrip(_BLANKS)
        if not pattern.fullmatch(compact):
            kind = "an integer" if pattern is _INTEGER else "a number (e.g. -0.2 or 1.5e-3)"
            self.Fail(element, f'{name}="{_Shown(text)}" is not {kind}')
        value = float(compact)
        unit = "deg" if name in _DEGREES else "" if name in _COEFFICIENTS else "m"
        if not (math.isfinite(value) and abs(value) <= MAX_MAGNITUDE):
            self.Fail(
                element,
                f'{name}="{_Shown(text)}" is out of range: its magnitude must be at most '
                f"{MAX_MAGNITUDE:g}{' ' + unit if unit else ''}",
            )
        return value

    def Number(self, element: _Element, name: str, default: float | None = None) -> float:
        text = element.attributes.get(name)
        if text is None:
            if default is None:
                self.Fail(element, f"needs the attribute '{name}'")
            return default
        return self.Parse(element, name, text)

    def Numbers(self, element: _Element, name: str, integers: bool = False) -> list:
        """A list of numbers separated by blanks (or commas)."""
        text = element.attributes.get(name)
        if text is None:
            self.Fail(element, f"needs the attribute '{name}'")
        items = text.replace(",", " ").split()
        if integers:
            return [int(self.Parse(element, name, item, _INTEGER)) for item in items]
        return [self.Parse(element, name, item) for item in items]

    def Vector(
        self,
        element: _Element,
        names: tuple[str, str, str],
        default: tuple[float, float, float] = (0.0, 0.0, 0.0),
    ) -> np.ndarray:
        return np.array([self.Number(element, n, d) for n, d in zip(names, default)])

    def Name(self, element: _Element, what: str, name: str) -> str:
        if problem := NameProblem(name):
            self.Fail(element, f"{what} name {problem}")
        return name

    def Flag(self, element: _Element, name: str) -> bool:
        text = element.attributes.get(name, "false").strip(_BLANKS).lower()
        if text not in ("true", "false", "1", "0"):
            self.Fail(element, f'{name}="{_Shown(text)}" is not a boolean (true or false)')
        return text in ("true", "1")

    def Direction(self, element: _Element) -> tuple[np.ndarray, float]:
        """The unit direction of the element's vector (x, y, z) and its length: ``length`` when
        given and not 0, else the vector's own (the original's reading)."""
        v = self.Vector(element, ("x", "y", "z"))
        norm = math.hypot(*v)
        if norm == 0.0:
            self.Fail(element, "its vector (x, y, z) is zero")
        if norm < MIN_VECTOR:
            self.Fail(
                element, f"its vector (x, y, z) is shorter than {MIN_VECTOR:g} m: no direction"
            )
        length = self.Number(element, "length", 0.0)
        if length < 0:
            self.Fail(element, f"length must be >= 0 (0: the vector's own length), got {length}")
        return v / norm, (length if length > 1e-12 else norm)

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

    def Placement(self, element: _Element, state: dict) -> tuple[np.ndarray, str]:
        """A primitive's centre (px, py, pz from the start of the enclosing link or joint) and
        the body it moves with."""
        if state["origin"] is None:
            self.Fail(element, f"<{element.tag}> must sit inside a <link> or <joint>")
        return state["origin"] + self.Vector(element, ("px", "py", "pz")), state["frame_body"]

    def HeightAxis(self, element: _Element) -> np.ndarray:
        """A cylinder's or box's height axis (hx, hy, hz): y when none is given or all are zero
        (the original's default)."""
        if self.Flag(element, "field"):
            self.Fail(element, "field volumes are supported for spheres only")
        axis = self.Vector(element, ("hx", "hy", "hz"))
        norm = math.hypot(*axis)
        if norm == 0.0:
            return np.array([0.0, 1.0, 0.0])
        if norm < MIN_VECTOR:
            self.Fail(
                element, f"its axis (hx, hy, hz) is shorter than {MIN_VECTOR:g}: no direction"
            )
        return axis / norm

    # ---- the tree ---------------------------------------------------------------------------
    def Read(self, root: _Element) -> None:
        version = root.attributes.get("version")
        if version not in (None, "", "1.0"):
            self.Fail(
                root,
                f'version="{_Shown(version)}" is not supported: this reader, like the '
                "original, reads version 1.0",
            )
        parts = set()
        for child in root.children:  # bodyparts only (checked while parsing)
            name = child.attributes.get("name", "")
            if not name or name in parts:
                self.Fail(child, f"every bodypart needs a unique name, got '{_Shown(name)}'")
            parts.add(self.Name(child, "the bodypart's", name))
            state = dict(
                part=name,
                point=np.zeros(3),
                origin=None,
                body=ROOT_BODY,
                frame_body=None,
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

    def Children(self, element: _Element, state: dict) -> None:
        for child in element.children:  # each allowed here (checked while parsing)
            getattr(self, f"_{child.tag}")(child, dict(state))

    def _link(self, element: _Element, state: dict) -> None:
        direction, length = self.Direction(element)
        start, end = state["point"], state["point"] + direction * length
        radius = self.Radius(element)
        if radius > 0:
            self.AddPrimitive(
                element,
                state["body"],
                Capsule(start=start.tolist(), end=end.tolist(), radius=radius),
                self.Margin(element, radius),
            )
        state.update(point=end, origin=start, frame_body=state["body"], direction=direction)
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
        name = element.attributes.get("name", f"{state['part']}_motor_{index}")
        self.Name(element, "the motor's", name)
        state["motor"] = dict(element=element, joints=[], ranges=[])
        self.Children(element, state)
        motor = state["motor"]
        if not motor["joints"]:
            self.Fail(element, "a motor must drive at least one joint")
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

    def JointName(self, element: _Element, state: dict) -> str:
        """The joint's name (given, or ``<bodypart>_<k>``), checked against every name so far:
        SDFormat keeps joints and bodies in one namespace."""
        given = "name" in element.attributes
        name = (
            element.attributes["name"] if given else f"{state['part']}_{state['counters']['joint']}"
        )
        state["counters"]["joint"] += 1
        self.Name(element, "the joint's" if given else "the generated joint", name)
        generated = "" if given else " (a joint without a name is named <bodypart>_<k>)"
        if name in self.joint_names:
            self.Fail(element, f"a second joint named '{name}'{generated}")
        if name in self.joint_points:
            self.Fail(
                element,
                f"the joint name '{name}' is a body's name (the root body is '{ROOT_BODY}', "
                f"a joint's body <joint>_link){generated}",
            )
        if f"{name}_link" in self.joint_names:
            self.Fail(element, f"this joint's body '{name}_link' would have a joint's name")
        if "_welds_to_" in name:
            self.Fail(element, f"the joint name '{name}' has the form of Drake's welds' names")
        return name

    def _joint(self, element: _Element, state: dict) -> None:
        if state["motor"] is None:
            self.Fail(element, "a joint must sit inside the motor that drives it")
        axis, length = self.Direction(element)
        low, high = self.Number(element, "minPos"), self.Number(element, "maxPos")
        if low >= high:
            self.Fail(element, f"minPos {low} must be smaller than maxPos {high}")
        name = self.JointName(element, state)
        self.joints.append(name)
        self.joint_names.add(name)
        state["motor"]["joints"].append(name)
        state["motor"]["ranges"].append((low, high))
        point, parent = state["point"], state["body"]
        body = f"{name}_link"
        self.joint_points[body] = point
        self.parents[body] = parent
        self.joints_sdf.append(
            f'<joint name={quoteattr(name)} type="revolute"><parent>{escape(parent)}</parent>'
            f"<child>{escape(body)}</child><axis><xyz>{_Xyz(axis)}</xyz><limit>"
            f"<lower>{math.radians(low)!r}</lower><upper>{math.radians(high)!r}</upper>"
            "<effort>0</effort></limit></axis></joint>"
        )  # no actuator: FreezeJoints adds them
        radius = self.Radius(element)
        if radius > 0:
            half = axis * length / 2
            self.AddPrimitive(
                element,
                body,
                Capsule(start=(point - half).tolist(), end=(point + half).tolist(), radius=radius),
                self.Margin(element, radius),
            )
        state.update(body=body, motor=None, origin=point, frame_body=parent)
        self.Children(element, state)

    def _marker(self, element: _Element, state: dict) -> None:
        if state["origin"] is None:
            self.Fail(element, "<marker> must sit inside a <link> or <joint>")
        name = element.attributes.get("name", "")
        if not name or name in self.marker_names:
            self.Fail(element, f"every marker needs a unique name, got '{_Shown(name)}'")
        self.marker_names.add(self.Name(element, "the marker's", name))
        direction = state["direction"] if np.any(state["direction"]) else np.array([0, 0, 1.0])
        self.markers.append(
            Marker(
                name=name,
                link=state["frame_body"],
                position=state["origin"].tolist(),
                direction=direction.tolist(),
            )
        )

    def _sphere(self, element: _Element, state: dict) -> None:
        centre, body = self.Placement(element, state)
        radius = self.Number(element, "radius")
        if radius <= 0:
            self.Fail(element, f"radius must be > 0, got {radius}")
        if self.Flag(element, "field"):
            self.AddPrimitive(
                element,
                body,
                Sphere(center=centre.tolist(), radius=FIELD_SPHERE_CORE),
                max(radius - FIELD_SPHERE_CORE, 0.0),
            )
        else:
            self.AddPrimitive(element, body, Sphere(center=centre.tolist(), radius=radius), None)

    def _cylinder(self, element: _Element, state: dict) -> None:
        axis = self.HeightAxis(element)
        centre, body = self.Placement(element, state)
        radius, height = self.Number(element, "radius"), self.Number(element, "height")
        if radius <= 0 or height <= 0:
            self.Fail(element, f"radius and height must be > 0, got {radius}, {height}")
        # A capsule as long as the cylinder (our overlay's round-ended cylinder).
        half = axis * max(height / 2 - radius, 1e-4)
        self.AddPrimitive(
            element,
            body,
            Capsule(start=(centre - half).tolist(), end=(centre + half).tolist(), radius=radius),
            None,
        )

    def _box(self, element: _Element, state: dict) -> None:
        axis = self.HeightAxis(element)
        centre, body = self.Placement(element, state)
        # The box's own x, y, z: width, height, depth (the original's Box(width, height, depth)).
        size = [
            self.Number(element, "width"),
            self.Number(element, "height"),
            self.Number(element, "depth"),
        ]
        if min(size) <= 0:
            self.Fail(element, f"width, height and depth must be > 0, got {size}")
        rotation = PrimitiveRotation(axis, math.radians(self.Number(element, "angle", 0.0)))
        rpy = np.degrees(RollPitchYaw(rotation).vector())
        self.AddPrimitive(
            element, body, Box(center=centre.tolist(), size=size, rpy_deg=rpy.tolist()), None
        )

    def _constraintList(self, element: _Element, state: dict) -> None:
        state["lists"].append(element)  # read once the bodypart's motors are all known

    def Constraints(self, element: _Element, motors: list[Motor]) -> None:
        literals = []
        for child in element.children:  # <constraint> only (checked while parsing)
            a = self.Numbers(child, "a")
            q = self.Numbers(child, "q", integers=True)
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

    def LinkSdf(self, body: str, visuals: str) -> str:
        """A body as an SDFormat <link>: its pose at zero (parallel to its parent's, at its
        joint's point), a small inertia (a massless body cannot be simulated dynamically) and its
        primitives drawn as ``visuals``."""
        origin = self.joint_points[body]
        if body == ROOT_BODY:
            return f"<link name={quoteattr(body)}>{visuals}</link>"
        parent = self.parents[body]
        return (
            f"<link name={quoteattr(body)}><pose relative_to={quoteattr(parent)}>"
            f"{_Xyz(origin - self.joint_points[parent])} 0 0 0</pose>{visuals}"
            "<inertial><mass>0.1</mass><inertia><ixx>1e-4</ixx><iyy>1e-4</iyy>"
            "<izz>1e-4</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial></link>"
        )

    def ModelSdf(self) -> str:
        """Every body's <link> and every joint, for the SDFormat model."""
        visuals: dict[str, list[str]] = {}
        for p in self.primitives:
            visuals.setdefault(p.link, []).append(_Visual(p, self.joint_points[p.link]))
        return "".join(
            self.LinkSdf(body, "".join(visuals.get(body, []))) for body in self.joint_points
        ) + "".join(self.joints_sdf)

    def Exclusions(self) -> list[list[str]]:
        """Per body, its primitives with those of its parent and grandparent; per parent, the
        primitives of its children (siblings; see the module)."""
        on_body: dict[str, list[str]] = {}
        for primitive in self.primitives:
            on_body.setdefault(primitive.link, []).append(primitive.name)
        children: dict[str, list[str]] = {}
        groups = []
        for body, parent in self.parents.items():
            children.setdefault(parent, []).append(body)
            chain = [body, parent, self.parents.get(parent)]
            group = [name for b in chain if b for name in on_body.get(b, [])]
            if len(group) >= 2:
                groups.append(group)
        for siblings in children.values():
            group = [name for b in siblings for name in on_body.get(b, [])]
            if len(siblings) >= 2 and len(group) >= 2:
                groups.append(group)
        return groups

    def AddPrimitive(self, element: _Element, body: str, shape, margin: float | None) -> None:
        name, k = f"{element.tag}_line{element.line}", 2
        while name in self.primitive_names:  # more than one on a line
            name, k = f"{element.tag}_line{element.line}_{k}", k + 1
        self.primitive_names.add(name)
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
        f"<visual name={quoteattr(primitive.name)}><pose>{_Xyz(X.translation())} {_Xyz(rpy)}"
        f"</pose><geometry>{geometry}</geometry><material><diffuse>{VISUAL_COLOR}</diffuse>"
        "</material></visual>"
    )


def _Xyz(v: np.ndarray) -> str:
    return " ".join(repr(float(c)) for c in v)


def LoadZeroPositionTree(filename: str | pathlib.Path) -> ZeroPositionRobot:
    """Reads a ``ZeroPositionKinematicTree`` file.

    Raises:
        ZeroPositionError: naming the file, the line and the element, for a file that cannot be
            read or decoded, malformed XML, unknown or misplaced elements, unknown attributes,
            bad numbers or names, limits with min >= max, a constraint naming a motor that does
            not exist, and the other errors listed in ``docs/zero_position.md``.
    """
    source = str(filename)
    try:
        data = pathlib.Path(filename).read_bytes()
    except OSError as error:
        raise ZeroPositionError(f"{source}: cannot read: {error.strerror}") from None
    root = _ParseXml(data, source)
    reader = _Reader(source)
    reader.Read(root)
    name = root.attributes.get("robotName")
    if not name:  # the file's name, made a valid name
        name = re.sub(r"[^A-Za-z0-9_.\-]", "_", pathlib.Path(source).stem).lstrip("_") or "robot"
    reader.Name(root, "the robot's", name)
    overlay = Overlay(
        reference_link=ROOT_BODY,
        primitives=reader.primitives,
        exclude=reader.Exclusions(),
        markers=reader.markers,
        clauses=reader.clauses,
    )
    ValidateOverlay(overlay, source)
    sdf = (
        f'<?xml version="1.0"?><sdf version="1.9"><model name={quoteattr(name)}>'
        + reader.ModelSdf()
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
    ``X_WRoot``; joints not in ``controlled_joints`` (every motor's first joint, by default) are
    welded at home, but for those that follow a controlled joint (a motor's other joints)."""
    name = model_name or robot.name
    return AddModelWithOverlay(
        plant,
        scene_graph,
        add_model=lambda p: Parser(p, name).AddModelsFromString(robot.sdf, "sdf")[0],
        overlay=robot.overlay,
        controlled_joints=(robot.motor_joints if controlled_joints is None else controlled_joints),
        home=robot.home,
        X_WRoot=X_WRoot,
        model_source=robot.source,
        overlay_source=robot.source,
        couplings=robot.couplings,
    )


@dc.dataclass
class ZeroPositionConfig:
    """A robot of a scenario read from a MoBeE XML file (e.g. ``katana.xml``)."""

    # The file: package://mobee_drake/..., a path, or a shipped model's name.
    file: str = "katana.xml"
    # The controlled joints; empty: every motor's first joint. A motor that drives several joints
    # (the Katana's gripper) is one degree of freedom: its other joints follow its first
    # (robots/couplings.py), as the original MoBeE's motors drove them.
    controlled_joints: list[str] = dc.field(default_factory=list)

    def Load(self) -> ZeroPositionRobot:
        return LoadZeroPositionTree(ResolveModelFile(self.file))

    def Joints(self, robot: ZeroPositionRobot) -> list[str]:
        joints = list(self.controlled_joints) or robot.motor_joints
        if not joints:
            raise ZeroPositionError(
                f"{robot.source}: no joint for MoBeE to control: the robot has no joints"
            )
        return joints


def BodyPoses(robot: ZeroPositionRobot, q: dict[str, float]) -> dict[str, RigidTransform]:
    """Every body's pose in the root's frame with the joints at ``q`` (radians; others zero)."""
    plant = MultibodyPlant(0.0)
    (instance,) = Parser(plant).AddModelsFromString(robot.sdf, "sdf")
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(ROOT_BODY, instance))
    plant.Finalize()
    context = plant.CreateDefaultContext()
    for joint, angle in q.items():
        plant.GetJointByName(joint, instance).set_angle(context, angle)
    bodies = [plant.get_body(i) for i in plant.GetBodyIndices(instance)]
    return {body.name(): body.EvalPoseInWorld(context) for body in bodies}
