"""The objects of the robot's world as a scenario writes them (dissertation ch. 2.3.2): their
shapes, poses and roles, and the world events that change them while the robot moves."""

import dataclasses as dc

# "obstacle": solid, MoBeE repels the robot from it; "target": shown, ignored by MoBeE, may be
# touched; "ghost": shown translucent, ignored.
OBJECT_ROLES = ("obstacle", "target", "ghost")


def _Zeros3() -> list[float]:
    return [0.0, 0.0, 0.0]


@dc.dataclass
class Box:
    size: list[float] = dc.field(default_factory=lambda: [0.1, 0.1, 0.1])


@dc.dataclass
class Sphere:
    radius: float = 0.05


@dc.dataclass
class Cylinder:
    radius: float = 0.05
    length: float = 0.1


@dc.dataclass
class Mesh:
    """A solid from a mesh file (OBJ, glTF or VTK): MoBeE and the dynamic robot's contacts see
    its convex hull (Drake's ``Convex``)."""

    # A package:// URI, an absolute path, or a path relative to the scenario's folder.
    file: str = ""
    # The factor that takes the file's units to metres.
    scale: float = 1.0


@dc.dataclass
class SceneObject:
    """An object of the robot's world: MoBeE avoids obstacles and ignores the rest."""

    name: str = ""
    shape: Box | Sphere | Cylinder | Mesh = dc.field(default_factory=Box)
    # Pose in world (the iCub's root frame unless the robot is moved): metres, degrees.
    position: list[float] = dc.field(default_factory=_Zeros3)
    rpy_deg: list[float] = dc.field(default_factory=_Zeros3)
    # One of OBJECT_ROLES.
    role: str = "obstacle"


@dc.dataclass
class WorldEvent:
    """A change of the world at a time: move an object or switch its role."""

    time: float = 0.0
    object: str = ""
    # New role, or "" to keep it.
    role: str = ""
    # New position, or empty to keep it.
    position: list[float] = dc.field(default_factory=list)
