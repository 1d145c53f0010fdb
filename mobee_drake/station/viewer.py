"""Meshcat: the robot and its world, the attractor as a translucent robot, the trail of a marker,
and MoBeE's workspace forces: field forces at witness points, client forces at markers."""

import gc
import logging
import math

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
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.perception import PointCloud
from pydrake.systems.framework import DiagramBuilder, LeafSystem, OutputPort
from pydrake.systems.primitives import SharedPointerSystem
from pydrake.systems.rendering import MultibodyPositionToGeometryPose

from mobee_drake.mobee.system import Mobee
from mobee_drake.robots.assembly import FreezeJoints
from mobee_drake.robots.couplings import CoupledPositions, LinearMapSystem
from mobee_drake.robots.scenario_robot import AddGhostRobot
from mobee_drake.station.config import StationConfig, Visualization
from mobee_drake.world.live_world import ROLE_COLORS, LiveWorld

ATTRACTOR_ALPHA = 0.25
TRAIL_COLOR = Rgba(0.9, 0.2, 0.2, 1.0)
TRAIL_WIDTH = 0.004  # m (the trail's points are kept 2 mm apart)
CONTACT_FORCE_COLOR = Rgba(1.0, 0.55, 0.0, 1.0)
MARKER_FORCE_COLOR = Rgba(0.85, 0.0, 0.85, 1.0)
MARKER_ARROW_LENGTH_PER_FORCE = 0.01
# Length of a drawn contact force per metre of field penetration (a full 3 cm field: 15 cm).
ARROW_LENGTH_PER_PENETRATION = 5.0
# The framed camera (see CameraFramer) looks from in front of the iCub (which faces -x), a little
# to its right and above; Meshcat's camera sees 75 degrees vertically. It frames a sphere of at
# least FRAMED_RADIUS (m) with a margin.
CAMERA_DIRECTION = np.array([-1.0, -0.25, 0.45]) / np.linalg.norm([-1.0, -0.25, 0.45])
CAMERA_FIELD_OF_VIEW = math.radians(75.0)
FRAMED_RADIUS = 0.15
# The objects framed are those whose centre lies this close to a framed marker (m).
FRAMED_REACH = 0.15
FRAMING_MARGIN = 1.3
# MoBeE's primitives (the "collision" layer, hidden by default) move every this many frames.
COLLISION_LAYER_FRAMES = 4
# The smallest motion of a body the viewer sends (m, or in its rotation matrix's entries, about
# 0.006 degrees): far below a pixel (see PoseStreamer).
POSE_TOLERANCE = 1e-4


def ReleaseMeshcats() -> None:
    """Destroys now, on this thread, the Meshcats that only reference cycles still hold (a
    model built with one holds it so). Drake ends the process when a Meshcat is destroyed on
    another thread than the one that made it, as Python's cycle collector would do from
    whichever thread next sets it off (a battery's worker pool, say): call this on the
    Meshcat's thread once a function's Meshcat and what was built with it are dropped."""
    gc.collect()


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


class PoseStreamer(LeafSystem):
    """Keeps Meshcat's bodies where they are, sending only what moved.

    Drake's ``MeshcatVisualizer`` draws the geometry of ``role`` under ``/drake/{prefix}`` and
    sends every frame's pose at every publish, also for bodies that stand still (the legs, the
    resting arm). Its visualizer is added here to draw only when the simulation starts; this
    system then sends, every ``period``, the pose of each frame that moved more than
    ``POSE_TOLERANCE`` since the pose last sent. In a recording a frame that starts moving after
    standing still first gets its still pose at the previous period, so the animation does not
    spread the motion over the time it stood. Which frames there are and what was sent is
    Meshcat's bookkeeping (as in MeshcatVisualizer): drawing changes nothing in the simulation.
    """

    def __init__(self, *, meshcat: Meshcat, role: Role, prefix: str, period: float):
        super().__init__()
        self._meshcat, self._role, self._prefix, self._period = meshcat, role, prefix, period
        self._query_port = self.DeclareAbstractInputPort(
            "geometry_query", AbstractValue.Make(QueryObject())
        )
        self._paths: dict | None = None  # frame -> its Meshcat path (on the first publish)
        self._sent: dict = {}  # frame -> (the pose sent, its time)
        self.DeclarePeriodicPublishEvent(period_sec=period, offset_sec=0.0, publish=self._Send)
        self.DeclareForcedPublishEvent(self._Send)

    def _Paths(self, inspector) -> dict:
        return {
            frame: f"/drake/{self._prefix}/" + inspector.GetName(frame).replace("::", "/")
            for frame in inspector.GetAllFrameIds()
            if frame != inspector.world_frame_id()
            and inspector.NumGeometriesForFrameWithRole(frame, self._role) > 0
        }

    def _Send(self, context) -> None:
        query = self._query_port.Eval(context)
        if self._paths is None:
            self._paths = self._Paths(query.inspector())
        time = context.get_time()
        for frame, path in self._paths.items():
            X = RigidTransform(query.GetPoseInWorld(frame))  # (A copy: the query's is live.)
            sent = self._sent.get(frame)
            if sent is not None:
                if _Near(sent[0], X):
                    continue
                if sent[1] < time - 1.5 * self._period:  # It stood still until now.
                    self._meshcat.SetTransform(path, sent[0], time - self._period)
            self._meshcat.SetTransform(path, X, time)
            self._sent[frame] = (X, time)


def _Near(X: RigidTransform, Y: RigidTransform) -> bool:
    """Whether two poses differ by at most POSE_TOLERANCE (m, or in a rotation's entries)."""
    return bool(
        np.abs(X.translation() - Y.translation()).max() <= POSE_TOLERANCE
        and np.abs(X.rotation().matrix() - Y.rotation().matrix()).max() <= POSE_TOLERANCE
    )


def _AddGeometryLayer(
    builder: DiagramBuilder,
    scene_graph: SceneGraph,
    meshcat: Meshcat,
    params: MeshcatVisualizerParams,
    period: float,
) -> MeshcatVisualizer:
    """Drake's visualizer of ``params`` (drawing when the simulation starts) and a
    :class:`PoseStreamer` that moves what it drew."""
    name = f"{params.prefix}_poses"
    params.publish_period = math.inf
    visualizer = MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat, params)
    streamer = builder.AddNamedSystem(
        name, PoseStreamer(meshcat=meshcat, role=params.role, prefix=params.prefix, period=period)
    )
    builder.Connect(scene_graph.get_query_output_port(), streamer.get_input_port())
    return visualizer


class _Arrows:
    """A pool of arrows drawn at Meshcat paths ``{root}/{i}`` that sends only what changed.

    Each arrow is a unit segment along its own z axis, placed by its transform and stretched by
    its ``scale`` property: a frame with forces sends a transform and a scale per changed arrow,
    never geometry. Arrows are created when more are needed than ever before, hidden in a
    recording until they are first used, and hidden (not deleted) when not needed. The pool is
    Meshcat's bookkeeping, as MeshcatVisualizer keeps its own: drawing changes nothing in the
    simulation.
    """

    def __init__(self, meshcat: Meshcat, root: str, color: Rgba):
        self._meshcat, self._root, self._color = meshcat, root, color
        self._drawn: list[tuple | None] = []  # Per arrow: (start, vector) shown, or None.

    def Draw(self, arrows: list[tuple[np.ndarray, np.ndarray]], time: float) -> None:
        """Shows ``arrows`` (start, vector: world, m) at ``time`` and hides the rest."""
        meshcat = self._meshcat
        for i, (start, vector) in enumerate(arrows):
            path = f"{self._root}/{i}"
            if i == len(self._drawn):
                meshcat.SetLineSegments(
                    path, np.zeros((3, 1)), np.array([[0.0], [0.0], [1.0]]), 4.0, self._color
                )
                meshcat.SetProperty(path, "visible", False, 0.0)
                self._drawn.append(None)
            key = (tuple(start), tuple(vector))
            if self._drawn[i] == key:
                continue
            length = float(np.linalg.norm(vector))
            X = RigidTransform(RotationMatrix.MakeFromOneVector(vector / length, 2), start)
            meshcat.SetTransform(path, X, time)
            meshcat.SetProperty(path, "scale", [1.0, 1.0, length], time)
            if self._drawn[i] is None:
                meshcat.SetProperty(path, "visible", True, time)
            self._drawn[i] = key
        for i in range(len(arrows), len(self._drawn)):
            if self._drawn[i] is not None:
                meshcat.SetProperty(f"{self._root}/{i}", "visible", False, time)
                self._drawn[i] = None


class ForceDrawer(LeafSystem):
    """Draws MoBeE's workspace forces as arrows (publish only: it keeps no state).

    - Field forces: from each witness point on the robot along the force (the separating
      direction), the length proportional to the field penetration (orange, ``/field_forces``).
    - Client forces on markers (``marker_forces``, when given): from each loaded marker along its
      force, 1 cm per unit of force (magenta, ``/marker_forces``).

    Arrows are updated in place (see :class:`_Arrows`), so a recording shows them over time.
    """

    def __init__(self, *, meshcat: Meshcat, num_markers: int, period: float):
        super().__init__()
        self._fields = _Arrows(meshcat, "/field_forces", CONTACT_FORCE_COLOR)
        self._markers = _Arrows(meshcat, "/marker_forces", MARKER_FORCE_COLOR)
        self._contacts_port = self.DeclareAbstractInputPort(
            "field_contacts", AbstractValue.Make([])
        )
        self._positions_port = self.DeclareVectorInputPort("marker_positions", 3 * num_markers)
        self._forces_port = self.DeclareVectorInputPort("marker_forces", 3 * num_markers)
        self.DeclarePeriodicPublishEvent(period_sec=period, offset_sec=0.0, publish=self._Draw)
        self.DeclareForcedPublishEvent(self._Draw)

    def _Draw(self, context) -> None:
        time = context.get_time()
        fields = [
            (c.p_WCa, ARROW_LENGTH_PER_PENETRATION * c.penetration * c.nhat_BA_W)
            for c in self._contacts_port.Eval(context)
            if c.penetration > 0
        ]
        self._fields.Draw(fields, time)
        markers = []
        if self._forces_port.HasValue(context):
            points = self._positions_port.Eval(context).reshape(-1, 3)
            forces = self._forces_port.Eval(context).reshape(-1, 3)
            markers = [
                (p, MARKER_ARROW_LENGTH_PER_FORCE * f)
                for p, f in zip(points, forces)
                if np.any(f != 0)
            ]
        self._markers.Draw(markers, time)


class TrailDrawer(LeafSystem):
    """Draws the whole path of one marker in Meshcat, as a line in pieces under ``path``.

    Every ``period`` the marker's position is kept if it lies ``resolution`` or more from the
    last kept one (a still marker adds nothing). Kept points go into the open piece (the discrete
    state: its points, their count, its start time and its number), which is closed after
    ``piece_points`` points or ``piece_seconds`` seconds; the next piece starts at its last point.
    A closed piece is never sent again, so the stream carries only the open piece, and only when
    it grew; a long run's path is never cut to a tail. The path is drawn as points of
    ``TRAIL_WIDTH`` (browsers draw lines one pixel wide whatever their width, which hides the
    path behind the hand), closer than their width, so they read as a line. In a recording each
    piece is hidden until its start, so the path grows as it was travelled (a piece at a time).
    """

    def __init__(
        self,
        *,
        meshcat: Meshcat,
        marker_index: int,
        num_markers: int,
        period: float,
        resolution: float = 0.002,
        piece_points: int = 100,
        piece_seconds: float = 0.5,
        path: str = "/trail",
    ):
        super().__init__()
        self._meshcat, self._path, self._resolution = meshcat, path, resolution
        self._capacity, self._piece_seconds = piece_points, piece_seconds
        self._marker_index = marker_index
        self._positions_port = self.DeclareVectorInputPort("marker_positions", 3 * num_markers)
        self._points = self.DeclareDiscreteState(3 * piece_points)
        # The open piece: [its point count, its start time, its number].
        self._piece = self.DeclareDiscreteState(3)
        self._drawn: tuple[int, int] | None = None  # (piece, count) last sent to Meshcat.
        self.DeclarePeriodicDiscreteUpdateEvent(
            period_sec=period, offset_sec=0.0, update=self._Append
        )
        self.DeclarePeriodicPublishEvent(period_sec=period, offset_sec=0.0, publish=self._Draw)

    def _Append(self, context, discrete_state) -> None:
        points = context.get_discrete_state(self._points).value().reshape(-1, 3).copy()
        count, start, piece = context.get_discrete_state(self._piece).value()
        count, piece, time = int(count), int(piece), context.get_time()
        i = 3 * self._marker_index
        p = self._positions_port.Eval(context)[i : i + 3]
        if count and np.linalg.norm(p - points[count - 1]) < self._resolution:
            return
        if count == self._capacity or (count > 1 and time - start >= self._piece_seconds):
            points[0], count, piece = points[count - 1], 1, piece + 1  # The next piece.
            start = time
        if count == 0:
            start = time
        points[count] = p
        discrete_state.get_mutable_vector(self._points).SetFromVector(points.ravel())
        discrete_state.get_mutable_vector(self._piece).SetFromVector([count + 1, start, piece])

    def _Draw(self, context) -> None:
        count, start, piece = context.get_discrete_state(self._piece).value()
        count, piece = int(count), int(piece)
        if count < 2 or self._drawn == (piece, count):
            return
        cloud = PointCloud(count)
        cloud.mutable_xyzs()[:] = (
            context.get_discrete_state(self._points).value()[: 3 * count].reshape(-1, 3).T
        )
        path = f"{self._path}/{piece}"
        self._meshcat.SetObject(path, cloud, TRAIL_WIDTH, TRAIL_COLOR)
        if self._drawn is None or self._drawn[0] != piece:
            self._meshcat.SetProperty(path, "visible", False, 0.0)
            self._meshcat.SetProperty(path, "visible", True, start)
        self._drawn = (piece, count)


class CameraFramer(LeafSystem):
    """Frames Meshcat's camera on the task when the simulation starts (an initialization
    publish): the sphere around the trail's marker (every marker without a trail) and the
    world's objects within ``FRAMED_REACH`` of it, seen from ``CAMERA_DIRECTION`` at the distance
    that fits the sphere in the view."""

    def __init__(
        self, *, meshcat: Meshcat, world: LiveWorld, marker_index: int | None, num_markers: int
    ):
        super().__init__()
        self._meshcat, self._world, self._marker_index = meshcat, world, marker_index
        self._positions_port = self.DeclareVectorInputPort("marker_positions", 3 * num_markers)
        self._query_port = self.DeclareAbstractInputPort(
            "geometry_query", AbstractValue.Make(QueryObject())
        )
        self.DeclareInitializationPublishEvent(self._Frame)

    def _Frame(self, context) -> None:
        markers = self._positions_port.Eval(context).reshape(-1, 3)
        if self._marker_index is not None:
            markers = markers[self._marker_index : self._marker_index + 1]
        objects = self._world.ObjectsSeenBy(self._query_port.Eval(context).inspector())
        centres = [X_WO.translation() for *_, X_WO in objects.values()]
        near = [c for c in centres if np.linalg.norm(markers - c, axis=1).min() <= FRAMED_REACH]
        points = np.vstack([markers, *near])
        low, high = points.min(axis=0), points.max(axis=0)
        target = (low + high) / 2
        radius = max(FRAMED_RADIUS, float(np.linalg.norm(high - low)) / 2) * FRAMING_MARGIN
        distance = radius / math.sin(CAMERA_FIELD_OF_VIEW / 2)
        self._meshcat.SetCameraPose(target + distance * CAMERA_DIRECTION, target)


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
    """A second, translucent robot (illustration only) posed at the attractor: the bodies that
    MoBeE's joints move."""
    ghost = MultibodyPlant(0.0)
    ghost.RegisterAsSourceForSceneGraph(scene_graph)
    instance, home = AddGhostRobot(
        ghost, scene_graph, config.robot, ATTRACTOR_ALPHA, config.visualization.meshes
    )
    followers = list(mobee.followers)
    moved = list(mobee.joints) + [c.follower for c in followers]
    FreezeJoints(ghost, instance, keep=moved, home=home, source="attractor robot")
    ghost.Finalize()
    # Only the bodies MoBeE's joints move are drawn: the rest would hide in the robot itself.
    moving = set(
        ghost.GetBodiesKinematicallyAffectedBy(
            [ghost.GetJointByName(name, instance).index() for name in moved]
        )
    )
    for index in ghost.GetBodyIndices(instance):
        if index not in moving:
            for geometry in ghost.GetVisualGeometriesForBody(ghost.get_body(index)):
                scene_graph.RemoveGeometry(ghost.get_source_id(), geometry)
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
    visualizer = _AddGeometryLayer(
        builder,
        scene_graph,
        meshcat,
        MeshcatVisualizerParams(role=Role.kIllustration, prefix="illustration"),
        period,
    )
    world_drawer = builder.AddNamedSystem(
        "world_drawer", WorldDrawer(meshcat=meshcat, world=world, period=period)
    )
    builder.Connect(scene_graph.get_query_output_port(), world_drawer.get_input_port())
    _AddCamera(builder, settings, meshcat, scene_graph, mobee, world)
    # MoBeE's primitives, hidden by default (toggle "collision" in Meshcat's controls).
    _AddGeometryLayer(
        builder,
        scene_graph,
        meshcat,
        MeshcatVisualizerParams(
            role=Role.kProximity,
            prefix="collision",
            default_color=Rgba(0.2, 0.5, 0.9, 0.4),
            visible_by_default=False,
        ),
        COLLISION_LAYER_FRAMES * period,
    )
    _AddForceDrawer(builder, meshcat, mobee, config.time_step, marker_forces)
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


def _AddCamera(
    builder: DiagramBuilder,
    settings: Visualization,
    meshcat: Meshcat,
    scene_graph: SceneGraph,
    mobee: Mobee,
    world: LiveWorld,
) -> None:
    """Places the camera where the scenario says, or adds the framer that follows the arm."""
    if settings.camera_position:
        meshcat.SetCameraPose(settings.camera_position, settings.camera_target)
        return
    framer = builder.AddNamedSystem(
        "camera_framer",
        CameraFramer(
            meshcat=meshcat,
            world=world,
            marker_index=(
                mobee.marker_index(settings.trail_marker) if settings.trail_marker else None
            ),
            num_markers=len(mobee.marker_names),
        ),
    )
    builder.Connect(
        mobee.GetOutputPort("marker_positions"), framer.GetInputPort("marker_positions")
    )
    builder.Connect(scene_graph.get_query_output_port(), framer.GetInputPort("geometry_query"))


def _AddForceDrawer(
    builder: DiagramBuilder,
    meshcat: Meshcat,
    mobee: Mobee,
    time_step: float,
    marker_forces: OutputPort | str | None,
) -> None:
    """Adds the arrows of MoBeE's field forces and of the client's marker forces, if any."""
    forces = builder.AddNamedSystem(
        "force_drawer",
        ForceDrawer(
            meshcat=meshcat,
            num_markers=len(mobee.marker_names),
            period=max(time_step, 1 / 30),
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
