"""The robot's world, live: objects added, moved, removed and switched between roles while the
robot moves, kept in SceneGraph's Context and nowhere else.

MoBeE's world changes while the robot moves (ch. 2.3.2, ch. 4.3.2): vision adds objects, a ball
turns from a ghost into an obstacle. Drake cannot add bodies to a built diagram, but SceneGraph
lets geometry change *in the Context* ("model versus context"): geometry can be registered,
removed and reshaped and its roles assigned and removed. We use exactly that:

- every object is a geometry registered by the robot's plant: on the world body for the
  kinematic robot, on a body welded to the world (``world_objects``) for the dynamic one. A move
  registers the object anew at its new pose (a new GeometryId) on the kinematic robot; on the
  dynamic robot it reshapes the geometry in place (same GeometryId, so the contact solver keeps
  knowing it; SceneGraph 1.51 does not move a world-body geometry that is reshaped), and the new
  pose takes effect at the robot's next step (SceneGraph recomputes a body geometry's pose when
  its body moves, not when the geometry is reshaped);
- its *role* decides what the rest of the system sees: an **obstacle** has the proximity role
  (MoBeE repels the robot from it and the dynamic robot collides with it) and is drawn solid; a
  **target** and a **ghost** have no proximity role (MoBeE ignores them, the palm may touch a
  target), the target drawn green, the ghost translucent. The role and its colour are written
  into the object's *perception* properties (group ``mobee_world``), so that they can be read
  back. Perception, not illustration: no renderer is registered, and the station's viewer draws
  the objects itself, each world it has seen at its own path (see
  :class:`~mobee_drake.station.viewer.WorldDrawer`), so that a recording shows every world event
  at its time (Drake's illustration visualizer replaces a changed geometry for the whole
  recording);
- :class:`LiveWorld` holds no state: names, ids, roles, shapes and poses are read from the
  Context's SceneGraph inspector, so two contexts of one diagram hold two worlds, a cloned Context
  clones its world, and a checkpoint saves :meth:`LiveWorld.Snapshot`.

An obstacle *added* while the dynamic robot runs would be a geometry its plant never registered,
which Drake's contact solver rejects; :meth:`LiveWorld.Add` refuses that with a clear error
(targets and ghosts are fine, and objects known when the station is built can always move).
"""

import numpy as np
from pydrake.geometry import (
    AddContactMaterial,
    Box,
    Convex,
    Cylinder,
    GeometryId,
    GeometryInstance,
    PerceptionProperties,
    ProximityProperties,
    Rgba,
    Role,
    SceneGraph,
    Shape,
    Sphere,
)
from pydrake.math import RigidTransform, RollPitchYaw
from pydrake.multibody.plant import CoulombFriction, MultibodyPlant
from pydrake.multibody.tree import SpatialInertia, default_model_instance

from mobee_drake.resources import ResolveModelPath
from mobee_drake.world import objects as schema

ROLE_COLORS = {
    "obstacle": np.array([0.55, 0.40, 0.25, 1.0]),
    "target": np.array([0.20, 0.75, 0.30, 0.9]),
    "ghost": np.array([0.60, 0.60, 0.90, 0.25]),
}
# The perception property that names a world object's role.
_ROLE_GROUP, _ROLE_PROPERTY = "mobee_world", "role"


def MakeShape(shape) -> Shape:
    """The Drake shape of a scenario shape (a mesh's file resolved, see
    :func:`~mobee_drake.resources.ResolveModelPath`)."""
    if isinstance(shape, schema.Box):
        return Box(*shape.size)
    if isinstance(shape, schema.Sphere):
        return Sphere(shape.radius)
    if isinstance(shape, schema.Mesh):
        return Convex(str(ResolveModelPath(shape.file)), shape.scale)
    return Cylinder(shape.radius, shape.length)


def _ShapeToJson(shape: Shape) -> dict:
    if isinstance(shape, Sphere):
        return {"sphere": shape.radius()}
    if isinstance(shape, Box):
        return {"box": list(shape.size())}
    if isinstance(shape, Convex):
        return {"convex": [str(shape.source().path()), shape.scale()]}
    return {"cylinder": [shape.radius(), shape.length()]}


def _ShapeFromJson(data: dict) -> Shape:
    if "sphere" in data:
        return Sphere(data["sphere"])
    if "box" in data:
        return Box(*data["box"])
    if "convex" in data:
        return Convex(*data["convex"])
    return Cylinder(*data["cylinder"])


def ObjectPose(position, rpy_deg) -> RigidTransform:
    return RigidTransform(RollPitchYaw(np.radians(rpy_deg)), np.asarray(position, dtype=float))


def _ProximityProperties() -> ProximityProperties:
    properties = ProximityProperties()
    AddContactMaterial(friction=CoulombFriction(0.5, 0.5), properties=properties)
    return properties


def _RoleProperties(role: str) -> PerceptionProperties:
    properties = PerceptionProperties()
    properties.AddProperty("phong", "diffuse", Rgba(*ROLE_COLORS[role]))
    properties.AddProperty(_ROLE_GROUP, _ROLE_PROPERTY, role)
    return properties


def _CheckRole(name: str, role: str) -> None:
    if role not in schema.OBJECT_ROLES:
        raise ValueError(
            f"world object '{name}': unknown role '{role}'; roles are "
            + ", ".join(schema.OBJECT_ROLES)
        )


class LiveWorld:
    """The objects of the robot's world, by name, editable in a running diagram's Context."""

    def __init__(self, plant: MultibodyPlant, scene_graph: SceneGraph):
        """The world of ``plant`` (not yet finalized; with a time step, the dynamic robot's, it
        gets the body that holds the objects)."""
        self._plant, self._scene_graph = plant, scene_graph
        self._source_id = plant.get_source_id()
        self._holder = plant.world_body()
        if plant.time_step() > 0:
            self._holder = plant.AddRigidBody(
                "world_objects",
                default_model_instance(),  # whose geometry names are not scoped
                SpatialInertia.SolidSphereWithMass(1.0, 0.01),
            )
            plant.WeldFrames(plant.world_frame(), self._holder.body_frame())

    def Register(self, obj: schema.SceneObject) -> GeometryId:
        """Adds ``obj`` to the plant before it is finalized (the scenario's initial objects)."""
        _CheckRole(obj.name, obj.role)
        instance = GeometryInstance(
            ObjectPose(obj.position, obj.rpy_deg), MakeShape(obj.shape), obj.name
        )
        instance.set_perception_properties(_RoleProperties(obj.role))
        geometry_id = self._plant.RegisterVisualGeometry(self._holder, instance)
        # The same geometry carries the proximity role while it is an obstacle.
        if obj.role == "obstacle":
            self._scene_graph.AssignRole(self._source_id, geometry_id, _ProximityProperties())
        return geometry_id

    @property
    def names(self) -> list[str]:
        """The objects the station was built with (a Context may have added or removed some)."""
        inspector = self._scene_graph.model_inspector()
        return [inspector.GetName(g) for g in self._ObjectIds(inspector)]

    def _ObjectIds(self, inspector) -> list[GeometryId]:
        """The world objects among the geometries ``inspector`` sees (they carry their role)."""
        return [
            g
            for g in inspector.GetGeometries(self._FrameId(), Role.kPerception)
            if inspector.GetPerceptionProperties(g).HasProperty(_ROLE_GROUP, _ROLE_PROPERTY)
        ]

    def _FrameId(self):
        return self._plant.GetBodyFrameIdOrThrow(self._holder.index())

    def _Inspector(self, root_context):
        scene_graph_context = self._scene_graph.GetMyContextFromRoot(root_context)
        return self._scene_graph.get_query_output_port().Eval(scene_graph_context).inspector()

    def _SceneGraphContext(self, root_context):
        return self._scene_graph.GetMyMutableContextFromRoot(root_context)

    def Objects(self, root_context) -> dict[str, tuple[GeometryId, str, Shape, RigidTransform]]:
        """Name -> (geometry id, role, shape, X_WO) of every object in ``root_context``."""
        return self.ObjectsSeenBy(self._Inspector(root_context))

    def ObjectsSeenBy(self, inspector) -> dict[str, tuple[GeometryId, str, Shape, RigidTransform]]:
        """The same, in the world of a SceneGraph ``inspector`` (a query object's)."""
        return {
            inspector.GetName(g): self._Describe(inspector, g) for g in self._ObjectIds(inspector)
        }

    @staticmethod
    def _Describe(inspector, g: GeometryId) -> tuple[GeometryId, str, Shape, RigidTransform]:
        return (
            g,
            inspector.GetPerceptionProperties(g).GetProperty(_ROLE_GROUP, _ROLE_PROPERTY),
            inspector.GetShape(g).Clone(),  # (outlives a removal)
            inspector.GetPoseInFrame(g),  # The frame is the world's.
        )

    def _Find(self, inspector, name: str) -> GeometryId | None:
        """The object named ``name`` (SceneGraph's lookup by name: no scan of the world)."""
        try:
            g = inspector.GetGeometryIdByName(self._FrameId(), Role.kPerception, name)
        except RuntimeError:  # No geometry of that name (or several: not one of our objects).
            return None
        properties = inspector.GetPerceptionProperties(g)
        return g if properties.HasProperty(_ROLE_GROUP, _ROLE_PROPERTY) else None

    def _Get(self, root_context, name: str) -> tuple:
        inspector = self._Inspector(root_context)
        return self._Describe(inspector, self._IdOf(inspector, name))

    def _IdOf(self, inspector, name: str) -> GeometryId:
        g = self._Find(inspector, name)
        if g is None:
            names = ", ".join(self.ObjectsSeenBy(inspector))
            raise ValueError(f"unknown world object '{name}'; objects are: {names}")
        return g

    def Names(self, root_context) -> list[str]:
        return list(self.Objects(root_context))

    def Role(self, root_context, name: str) -> str:
        return self._Get(root_context, name)[1]

    def GeometryIdOf(self, root_context, name: str) -> GeometryId:
        return self._IdOf(self._Inspector(root_context), name)

    def Add(self, root_context, obj: schema.SceneObject) -> None:
        """Adds an object while the simulation runs."""
        if self._Find(self._Inspector(root_context), obj.name) is not None:
            raise ValueError(f"world object '{obj.name}' exists already")
        _CheckRole(obj.name, obj.role)
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
        if role == "obstacle" and self._plant.time_step() > 0:
            raise ValueError(
                f"world object '{name}': an obstacle cannot be added while the dynamic robot "
                "runs (its contact solver knows only the objects it was built with); add it to "
                "the scenario's objects, as a ghost if it should appear later"
            )
        instance = GeometryInstance(X_WO, shape, name)
        instance.set_perception_properties(_RoleProperties(role))
        if role == "obstacle":
            instance.set_proximity_properties(_ProximityProperties())
        self._scene_graph.RegisterGeometry(
            self._SceneGraphContext(root_context), self._source_id, self._FrameId(), instance
        )

    def Remove(self, root_context, name: str) -> None:
        self._scene_graph.RemoveGeometry(
            self._SceneGraphContext(root_context),
            self._source_id,
            self.GeometryIdOf(root_context, name),
        )

    def Move(self, root_context, name: str, position, rpy_deg=(0.0, 0.0, 0.0)) -> None:
        """Moves an object (its shape and role stay; see the module for its GeometryId)."""
        self._Place(root_context, name, ObjectPose(position, rpy_deg))

    def _Place(self, root_context, name: str, X_WO: RigidTransform, shape: Shape | None = None):
        geometry_id, role, current, _ = self._Get(root_context, name)
        if self._plant.time_step() > 0:  # The dynamic robot: keep the id (see the module).
            self._scene_graph.ChangeShape(
                self._SceneGraphContext(root_context),
                self._source_id,
                geometry_id,
                shape or current,
                X_WO,
            )
        else:
            self.Remove(root_context, name)
            self._Register(root_context, name, shape or current, X_WO, role)

    def SetRole(self, root_context, name: str, role: str) -> None:
        """Switches an object between "obstacle", "target" and "ghost"."""
        _CheckRole(name, role)
        geometry_id, old, _, _ = self._Get(root_context, name)
        context = self._SceneGraphContext(root_context)
        if old == "obstacle" and role != "obstacle":
            self._scene_graph.RemoveRole(context, self._source_id, geometry_id, Role.kProximity)
        elif old != "obstacle" and role == "obstacle":
            self._scene_graph.AssignRole(
                context, self._source_id, geometry_id, _ProximityProperties()
            )
        # (SceneGraph replaces no perception properties in place: removed, then assigned.)
        self._scene_graph.RemoveRole(context, self._source_id, geometry_id, Role.kPerception)
        self._scene_graph.AssignRole(context, self._source_id, geometry_id, _RoleProperties(role))

    def Apply(self, root_context, event: schema.WorldEvent) -> None:
        """Applies a world event."""
        if event.position:
            self.Move(root_context, event.object, event.position)
        if event.role:
            self.SetRole(root_context, event.object, event.role)

    def Snapshot(self, root_context) -> list[dict]:
        """The world of ``root_context`` as JSON-able data, exact to the bit (for checkpoints)."""
        return [
            {
                "name": name,
                "role": role,
                "shape": _ShapeToJson(shape),
                "X_WO": X_WO.GetAsMatrix4().tolist(),
            }
            for name, (_, role, shape, X_WO) in self.Objects(root_context).items()
        ]

    def Restore(self, root_context, snapshot: list[dict]) -> None:
        """Makes the world of ``root_context`` the one of a :meth:`Snapshot`."""
        current = self.Objects(root_context)
        for name in set(current) - {o["name"] for o in snapshot}:
            self.Remove(root_context, name)
        for saved in snapshot:
            X_WO, shape = RigidTransform(np.array(saved["X_WO"])), _ShapeFromJson(saved["shape"])
            if saved["name"] not in current:
                self._Register(root_context, saved["name"], shape, X_WO, saved["role"])
                continue
            self._Place(root_context, saved["name"], X_WO, shape)
            if current[saved["name"]][1] != saved["role"]:
                self.SetRole(root_context, saved["name"], saved["role"])
