"""Meshcat: the robot and its world, the attractor as a translucent robot, the trail of a marker,
and MoBeE's workspace forces: field forces at witness points, client forces at markers."""

import logging

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import (
    Meshcat,
    MeshcatParams,
    MeshcatVisualizer,
    MeshcatVisualizerParams,
    QueryObject,
    Rgba,
    Role,
    SceneGraph,
)
from pydrake.math import RigidTransform
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import BasicVector, DiagramBuilder, LeafSystem, OutputPort
from pydrake.systems.primitives import SharedPointerSystem
from pydrake.systems.rendering import MultibodyPositionToGeometryPose

from mobee_drake.mobee.system import Mobee
from mobee_drake.robots.assembly import FreezeJoints
from mobee_drake.robots.couplings import CoupledPositions, LinearMapSystem
from mobee_drake.robots.scenario_robot import RobotModelText
from mobee_drake.station.config import StationConfig
from mobee_drake.world.live_world import ROLE_COLORS, LiveWorld

ATTRACTOR_ALPHA = 0.25
TRAIL_COLOR = Rgba(0.9, 0.2, 0.2, 1.0)
CONTACT_FORCE_COLOR = Rgba(1.0, 0.55, 0.0, 1.0)
MARKER_FORCE_COLOR = Rgba(0.85, 0.0, 0.85, 1.0)
MARKER_ARROW_LENGTH_PER_FORCE = 0.01
# Length of a drawn contact force per metre of field penetration (a full 3 cm field: 15 cm).
ARROW_LENGTH_PER_PENETRATION = 5.0


def RecordingMeshcat() -> Meshcat:
    """A Meshcat only to record in: Drake's Meshcat records through its server, so it listens,
    but on this machine's loopback only, and says nothing of it (no one is to connect)."""
    drake_logger = logging.getLogger("drake")
    level = drake_logger.level
    drake_logger.setLevel(logging.WARNING)
    try:
        return Meshcat(MeshcatParams(host="localhost"))
    finally:
        drake_logger.setLevel(level)


class ForceDrawer(LeafSystem):
    """Draws MoBeE's workspace forces as segments (publish only: it keeps no state).

    - Field forces: from each witness point on the robot along the force (the separating
      direction), the length proportional to the field penetration (orange, ``/field_forces``).
    - Client forces on markers (``marker_forces``, when given): from each loaded marker along its
      force, 1 cm per unit of force (magenta, ``/marker_forces``).
    """

    def __init__(self, *, meshcat: Meshcat, num_markers: int, period: float):
        super().__init__()
        self._meshcat = meshcat
        self._contacts_port = self.DeclareAbstractInputPort(
            "field_contacts", AbstractValue.Make([])
        )
        self._positions_port = self.DeclareVectorInputPort("marker_positions", 3 * num_markers)
        self._forces_port = self.DeclareVectorInputPort("marker_forces", 3 * num_markers)
        self.DeclarePeriodicPublishEvent(period_sec=period, offset_sec=0.0, publish=self._Draw)
        self.DeclareForcedPublishEvent(self._Draw)

    def _Segments(self, path: str, starts: list, ends: list, color: Rgba) -> None:
        if starts:
            self._meshcat.SetLineSegments(path, np.array(starts).T, np.array(ends).T, 4.0, color)
        else:
            self._meshcat.Delete(path)

    def _Draw(self, context) -> None:
        contacts = self._contacts_port.Eval(context)
        self._Segments(
            "/field_forces",
            [c.p_WCa for c in contacts],
            [
                c.p_WCa + ARROW_LENGTH_PER_PENETRATION * c.penetration * c.nhat_BA_W
                for c in contacts
            ],
            CONTACT_FORCE_COLOR,
        )
        starts, ends = [], []
        if self._forces_port.HasValue(context):
            points = self._positions_port.Eval(context).reshape(-1, 3)
            forces = self._forces_port.Eval(context).reshape(-1, 3)
            for p, f in zip(points, forces):
                if np.any(f != 0):
                    starts.append(p)
                    ends.append(p + MARKER_ARROW_LENGTH_PER_FORCE * f)
        self._Segments("/marker_forces", starts, ends, MARKER_FORCE_COLOR)


class TrailDrawer(LeafSystem):
    """Draws the recent path of one marker as a line in Meshcat.

    The last ``capacity`` positions, sampled every ``period``, are kept in the discrete state (a
    ring buffer and its count); a periodic publish sends them to Meshcat.
    """

    def __init__(
        self,
        *,
        meshcat: Meshcat,
        marker_index: int,
        num_markers: int,
        period: float,
        capacity: int = 600,
        path: str = "/trail",
    ):
        super().__init__()
        self._meshcat, self._path, self._capacity = meshcat, path, capacity
        self._marker_index = marker_index
        self._positions_port = self.DeclareVectorInputPort("marker_positions", 3 * num_markers)
        self._state = self.DeclareDiscreteState(BasicVector(np.zeros(3 * capacity + 1)))
        self.DeclarePeriodicDiscreteUpdateEvent(
            period_sec=period, offset_sec=0.0, update=self._Append
        )
        self.DeclarePeriodicPublishEvent(period_sec=period, offset_sec=0.0, publish=self._Draw)

    def _Append(self, context, discrete_state) -> None:
        x = context.get_discrete_state(self._state).value().copy()
        count = int(x[-1])
        i = 3 * self._marker_index
        p = self._positions_port.Eval(context)[i : i + 3]
        slot = count % self._capacity
        x[3 * slot : 3 * slot + 3] = p
        x[-1] = count + 1
        discrete_state.get_mutable_vector(self._state).SetFromVector(x)

    def _Draw(self, context) -> None:
        x = context.get_discrete_state(self._state).value()
        count = int(x[-1])
        if count < 2:
            return
        points = x[:-1].reshape(self._capacity, 3)
        if count > self._capacity:  # Oldest first.
            start = count % self._capacity
            points = np.vstack([points[start:], points[:start]])
        else:
            points = points[:count]
        self._meshcat.SetLine(self._path, points.T, 3.0, TRAIL_COLOR)


class WorldDrawer(LeafSystem):
    """Draws the world's objects in Meshcat, under ``/drake/world``: each state an object is seen in
    (its role, shape and pose) at a path of its own, shown while the object is in that state.

    So a recording shows every world event at its time: a ball made a ghost at 6 s is solid
    until 6 s, then translucent (Drake's illustration visualizer replaces a changed geometry, so
    its recording shows the last state all along; the objects carry their role in perception
    properties, which it does not draw). Which paths exist and which is shown is Meshcat's
    bookkeeping, kept here as MeshcatVisualizer keeps its own: drawing changes nothing in the
    simulation.
    """

    def __init__(self, *, meshcat: Meshcat, world: LiveWorld, period: float):
        super().__init__()
        self._meshcat, self._world = meshcat, world
        self._query_port = self.DeclareAbstractInputPort(
            "geometry_query", AbstractValue.Make(QueryObject())
        )
        self._paths: dict[tuple, str] = {}  # (name, role, shape, pose) -> its path
        self._shown: dict[str, bool] = {}  # path -> whether it is shown
        self.DeclareInitializationPublishEvent(self._Draw)
        self.DeclarePeriodicPublishEvent(period_sec=period, offset_sec=0.0, publish=self._Draw)
        self.DeclareForcedPublishEvent(self._Draw)

    def _Draw(self, context) -> None:
        objects = self._world.ObjectsSeenBy(self._query_port.Eval(context).inspector())
        now, time = set(), context.get_time()
        for name, (_, role, shape, X_WO) in objects.items():
            key = (name, role, repr(shape), X_WO.GetAsMatrix34().tobytes())
            path = self._paths.get(key)
            if path is None:
                path = f"world/{name}/{sum(k[0] == name for k in self._paths)}"
                self._paths[key] = path
                self._meshcat.SetObject(path, shape, Rgba(*ROLE_COLORS[role]))
                self._meshcat.SetTransform(path, X_WO)
                # Hidden in a recording until now (a recording without a frame at its start
                # would show its first keyframe's value all along).
                self._meshcat.SetProperty(path, "visible", False, 0.0)
                self._shown[path] = False
            now.add(path)
        for path, shown in self._shown.items():
            if (path in now) != shown:
                self._meshcat.SetProperty(path, "visible", path in now, time)
                self._shown[path] = path in now


def _AddAttractorRobot(
    builder: DiagramBuilder,
    config: StationConfig,
    scene_graph: SceneGraph,
    mobee: Mobee,
    attractor: OutputPort,
) -> None:
    """A second, translucent robot (illustration only) posed at the attractor."""
    text, extension, root, home = RobotModelText(config.robot, ATTRACTOR_ALPHA)
    ghost = MultibodyPlant(0.0)
    ghost.RegisterAsSourceForSceneGraph(scene_graph)
    parser = Parser(ghost, "attractor")
    (instance,) = parser.AddModelsFromString(text, extension)
    ghost.RenameModelInstance(instance, "attractor")
    ghost.WeldFrames(ghost.world_frame(), ghost.GetFrameByName(root, instance), RigidTransform())
    followers = list(mobee.followers)
    moved = list(mobee.joints) + [c.follower for c in followers]
    FreezeJoints(ghost, instance, keep=moved, home=home, source="attractor robot")
    ghost.Finalize()
    builder.AddNamedSystem("attractor_robot_owner", SharedPointerSystem(ghost))
    coupled = CoupledPositions.Of(ghost, instance, list(mobee.joints), followers)
    P, p0 = coupled.PositionMap(ghost.num_positions())
    to_ghost = builder.AddNamedSystem("attractor_to_robot", LinearMapSystem(P, p0))
    to_pose = builder.AddNamedSystem("attractor_pose", MultibodyPositionToGeometryPose(ghost))
    builder.Connect(attractor, to_ghost.get_input_port())
    builder.Connect(to_ghost.get_output_port(), to_pose.get_input_port())
    builder.Connect(
        to_pose.get_output_port(), scene_graph.get_source_pose_port(ghost.get_source_id())
    )


def AddViewer(
    builder: DiagramBuilder,
    *,
    config: StationConfig,
    meshcat: Meshcat,
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    mobee: Mobee,
    world: LiveWorld,
    attractor: OutputPort,
    marker_forces: OutputPort | str | None = None,
) -> MeshcatVisualizer:
    """Adds the Meshcat viewer of a scenario; returns the illustration visualizer.

    ``marker_forces`` is the port, or names the diagram input, that carries the client's marker
    forces, if any.
    """
    settings = config.visualization
    if settings.show_attractor:
        _AddAttractorRobot(builder, config, scene_graph, mobee, attractor)
    period = 1.0 / settings.frame_rate
    visualizer = MeshcatVisualizer.AddToBuilder(
        builder,
        scene_graph,
        meshcat,
        MeshcatVisualizerParams(
            publish_period=period, role=Role.kIllustration, prefix="illustration"
        ),
    )
    world_drawer = builder.AddNamedSystem(
        "world_drawer", WorldDrawer(meshcat=meshcat, world=world, period=period)
    )
    builder.Connect(scene_graph.get_query_output_port(), world_drawer.get_input_port())
    meshcat.SetCameraPose(settings.camera_position, settings.camera_target)
    # MoBeE's primitives, hidden by default (toggle "collision" in Meshcat's controls).
    MeshcatVisualizer.AddToBuilder(
        builder,
        scene_graph,
        meshcat,
        MeshcatVisualizerParams(
            publish_period=period,
            role=Role.kProximity,
            prefix="collision",
            default_color=Rgba(0.2, 0.5, 0.9, 0.4),
            visible_by_default=False,
        ),
    )
    forces = builder.AddNamedSystem(
        "force_drawer",
        ForceDrawer(
            meshcat=meshcat,
            num_markers=len(mobee.marker_names),
            period=max(config.time_step, 1 / 30),
        ),
    )
    builder.Connect(mobee.GetOutputPort("field_contacts"), forces.GetInputPort("field_contacts"))
    builder.Connect(
        mobee.GetOutputPort("marker_positions"), forces.GetInputPort("marker_positions")
    )
    if isinstance(marker_forces, str):
        builder.ConnectInput(marker_forces, forces.GetInputPort("marker_forces"))
    elif marker_forces is not None:
        builder.Connect(marker_forces, forces.GetInputPort("marker_forces"))
    if settings.trail_marker:
        trail = builder.AddNamedSystem(
            "trail",
            TrailDrawer(
                meshcat=meshcat,
                marker_index=mobee.marker_index(settings.trail_marker),
                num_markers=len(mobee.marker_names),
                period=max(config.time_step, 0.02),
            ),
        )
        builder.Connect(mobee.GetOutputPort("marker_positions"), trail.get_input_port())
    return visualizer
