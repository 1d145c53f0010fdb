"""The robot's world: objects that can be added, moved, removed and switched between roles live.

MoBeE's world changes while the robot moves (ch. 2.3.2, ch. 4.3.2): vision adds objects, a ball
turns from a ghost into an obstacle. Drake cannot add frames or bodies to a built diagram, but
SceneGraph lets the geometry itself change *in the Context* ("model versus context"): geometry can
be registered and removed and its roles assigned and removed. We use exactly that:

- every object is a geometry fixed to the world frame, registered by the robot's plant (so the
  dynamic robot's contact solver knows it);
- its *role* decides what the rest of the system sees: an **obstacle** has the proximity role (MoBeE
  repels the robot from it and the dynamic robot collides with it) and is drawn solid; a **target**
  and a **ghost** have no proximity role (MoBeE ignores them, the palm may touch a target), the
  target drawn green, the ghost translucent;
- :class:`LiveWorld` changes them through the diagram's Context, between simulation steps, from a
  script, from scenario events, or on a supervisor's request (an abstract output port named
  ``world_events`` listing every :class:`~mobee_drake.simulation.scenario.WorldEvent` the
  supervisor has issued, in order; the runner applies the new ones after each step it takes):
  roles are assigned and removed, objects registered and removed; a move re-registers the object
  at its new pose (SceneGraph does not update the pose of a
  world-fixed geometry whose shape is changed in a Context). Changes made in the Context are not
  in the SceneGraph model, so a Meshcat *recording* shows the objects as they were at the start
  (the live view is updated).
"""

import numpy as np
from pydrake.geometry import (
    AddContactMaterial,
    Box,
    Cylinder,
    GeometryId,
    GeometryInstance,
    IllustrationProperties,
    MakePhongIllustrationProperties,
    ProximityProperties,
    Role,
    RoleAssign,
    SceneGraph,
    Shape,
    Sphere,
)
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.plant import CoulombFriction, MultibodyPlant

from mobee_drake.simulation import scenario as schema

ROLE_COLORS = {
    "obstacle": np.array([0.55, 0.40, 0.25, 1.0]),
    "target": np.array([0.20, 0.75, 0.30, 0.9]),
    "ghost": np.array([0.60, 0.60, 0.90, 0.25]),
}


def MakeShape(shape) -> Shape:
    """The Drake shape of a scenario shape."""
    if isinstance(shape, schema.Box):
        return Box(*shape.size)
    if isinstance(shape, schema.Sphere):
        return Sphere(shape.radius)
    return Cylinder(shape.radius, shape.length)


def ObjectPose(position, rpy_deg) -> RigidTransform:
    return RigidTransform(RollPitchYaw(np.radians(rpy_deg)), np.asarray(position, dtype=float))


def _ProximityProperties() -> ProximityProperties:
    properties = ProximityProperties()
    AddContactMaterial(friction=CoulombFriction(0.5, 0.5), properties=properties)
    return properties


def _IllustrationProperties(role: str) -> IllustrationProperties:
    return MakePhongIllustrationProperties(ROLE_COLORS[role])


class LiveWorld:
    """The objects of the robot's world, by name, editable while a simulation runs."""

    def __init__(self, plant: MultibodyPlant, scene_graph: SceneGraph):
        self._plant, self._scene_graph = plant, scene_graph
        self._source_id = plant.get_source_id()
        self._frame_id = scene_graph.world_frame_id()
        # name -> [geometry id, shape, pose, role]
        self._objects: dict[str, list] = {}

    def Register(self, obj: schema.SceneObject) -> GeometryId:
        """Adds ``obj`` to the plant before it is finalized (the scenario's initial objects)."""
        shape, X_WO = MakeShape(obj.shape), ObjectPose(obj.position, obj.rpy_deg)
        world = self._plant.world_body()
        geometry_id = self._plant.RegisterVisualGeometry(
            world, X_WO, shape, obj.name, ROLE_COLORS[obj.role]
        )
        # The same geometry carries the proximity role while it is an obstacle.
        if obj.role == "obstacle":
            self._scene_graph.AssignRole(self._source_id, geometry_id, _ProximityProperties())
        self._objects[obj.name] = [geometry_id, shape, X_WO, obj.role]
        return geometry_id

    @property
    def names(self) -> list[str]:
        return list(self._objects)

    def role(self, name: str) -> str:
        return self._Get(name)[3]

    def geometry_id(self, name: str) -> GeometryId:
        return self._Get(name)[0]

    def _Get(self, name: str) -> list:
        if name not in self._objects:
            raise ValueError(
                f"unknown world object '{name}'; objects are: " + ", ".join(self._objects)
            )
        return self._objects[name]

    def _SceneGraphContext(self, root_context):
        return self._scene_graph.GetMyMutableContextFromRoot(root_context)

    def Add(self, root_context, obj: schema.SceneObject) -> None:
        """Adds an object while the simulation runs."""
        if obj.name in self._objects:
            raise ValueError(f"world object '{obj.name}' exists already")
        if obj.role not in schema.OBJECT_ROLES:
            raise ValueError(f"world object '{obj.name}': unknown role '{obj.role}'")
        self._Register(
            root_context,
            obj.name,
            MakeShape(obj.shape),
            ObjectPose(obj.position, obj.rpy_deg),
            obj.role,
        )

    def _Register(
        self, root_context, name: str, shape: Shape, X_WO: RigidTransform, role: str
    ) -> None:
        instance = GeometryInstance(X_WO, shape, name)
        instance.set_illustration_properties(_IllustrationProperties(role))
        if role == "obstacle":
            instance.set_proximity_properties(_ProximityProperties())
        geometry_id = self._scene_graph.RegisterGeometry(
            self._SceneGraphContext(root_context), self._source_id, self._frame_id, instance
        )
        self._objects[name] = [geometry_id, shape, X_WO, role]

    def Remove(self, root_context, name: str) -> None:
        geometry_id = self._Get(name)[0]
        self._scene_graph.RemoveGeometry(
            self._SceneGraphContext(root_context), self._source_id, geometry_id
        )
        del self._objects[name]

    def Move(self, root_context, name: str, position, rpy_deg=(0.0, 0.0, 0.0)) -> None:
        """Moves an object. SceneGraph 1.51 does not update the pose of a world-fixed geometry
        changed with ``ChangeShape`` in a Context, so the object is registered anew (its
        GeometryId changes; its name, shape and role stay)."""
        _, shape, _, role = self._Get(name)
        self.Remove(root_context, name)
        self._Register(root_context, name, shape, ObjectPose(position, rpy_deg), role)

    def SetRole(self, root_context, name: str, role: str) -> None:
        """Switches an object between "obstacle", "target" and "ghost"."""
        if role not in schema.OBJECT_ROLES:
            raise ValueError(
                f"world object '{name}': unknown role '{role}'; roles are "
                + ", ".join(schema.OBJECT_ROLES)
            )
        entry = self._Get(name)
        context = self._SceneGraphContext(root_context)
        geometry_id, old = entry[0], entry[3]
        if old == "obstacle" and role != "obstacle":
            self._scene_graph.RemoveRole(context, self._source_id, geometry_id, Role.kProximity)
        elif old != "obstacle" and role == "obstacle":
            self._scene_graph.AssignRole(
                context, self._source_id, geometry_id, _ProximityProperties()
            )
        self._scene_graph.AssignRole(
            context,
            self._source_id,
            geometry_id,
            _IllustrationProperties(role),
            RoleAssign.kReplace,
        )
        entry[3] = role

    def Apply(self, root_context, event: schema.WorldEvent) -> None:
        """Applies a scenario's world event."""
        if event.position:
            self.Move(root_context, event.object, event.position)
        if event.role:
            self.SetRole(root_context, event.object, event.role)


WORLD_EVENTS_PORT = "world_events"


def SupervisorEventPorts(diagram) -> list:
    """The ``world_events`` output ports of the diagram's systems (see the module)."""
    return [
        system.GetOutputPort(WORLD_EVENTS_PORT)
        for system in diagram.GetSystems()
        if system.HasOutputPort(WORLD_EVENTS_PORT)
    ]
