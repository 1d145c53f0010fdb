"""The kinematic model NGIK and the roadmaps query (dissertation ch. 2, eq. 3.3).

For a robot pose ``q`` and the world's obstacles ``B`` it computes what the cost and task
functions are written in: the *marker states* ``X(q, B)`` (each marker's position and unit direction
in world) and the *collision pairs* ``K(q, B)`` (the pairs of solids that interpenetrate: the robot
against itself, where the overlay does not exclude the pair, and against obstacles).

The model is a MultibodyPlant and a SceneGraph without any system that moves them: a pose is set
in the plant's Context and the geometry queried, so one evaluation costs one forward-kinematics
pass and one signed-distance query over the overlay's primitives.
"""

import dataclasses as dc

import numpy as np
from pydrake.geometry import Meshcat, MeshcatVisualizer
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from mobee_drake.mobee.constraints import ClauseSet
from mobee_drake.mobee.fields import RobotFields
from mobee_drake.robots.controlled_robot import ControlledRobot
from mobee_drake.robots.overlay import MarkerStates
from mobee_drake.robots.scenario_robot import AddScenarioRobot, RobotConfig
from mobee_drake.world.live_world import LiveWorld
from mobee_drake.world.objects import SceneObject


@dc.dataclass(frozen=True)
class PoseEvaluation:
    """What the kinematic model reports for one pose."""

    q: np.ndarray  # (n,) the controlled joints' positions (rad)
    marker_positions: np.ndarray  # (m, 3) x_i in world
    marker_directions: np.ndarray  # (m, 3) unit u_i in world
    # The colliding pairs K(q, B), as pairs of geometry names.
    collision_pairs: tuple[tuple[str, str], ...]


class KinematicModel:
    """Forward kinematics and collision pairs of one robot among fixed objects.

    Args:
        robot: the robot, as in a scenario file.
        objects: the world's objects; only obstacles take part in collisions (targets and ghosts
            are drawn but not felt, as in the simulation).
        clearance: solids closer than this (m) count as colliding (0: only interpenetration).
        inside_fields: count the pairs inside MoBeE's fields instead (each pair closer than its
            field margin, as MoBeE 1.0's reflex sees them); ``clearance`` is then unused.
        meshcat: if given, the model is drawn there (see :meth:`Publish`).
    """

    def __init__(
        self,
        robot: RobotConfig,
        objects: list[SceneObject] = (),
        *,
        clearance: float = 0.0,
        inside_fields: bool = False,
        meshcat: Meshcat | None = None,
    ):
        builder = DiagramBuilder()
        plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
        self._overlay, self.joints = AddScenarioRobot(plant, scene_graph, robot)
        self.world = LiveWorld(plant, scene_graph)
        for obj in objects:
            self.world.Register(obj)
        plant.Finalize()
        self.visualizer = None
        if meshcat is not None:
            self.visualizer = MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat)
        self.diagram = builder.Build()
        self.plant, self.scene_graph = plant, scene_graph
        self.context = self.diagram.CreateDefaultContext()
        self._plant_context = plant.GetMyMutableContextFromRoot(self.context)
        self._scene_graph_context = scene_graph.GetMyContextFromRoot(self.context)
        self.robot = ControlledRobot.Of(plant, self._overlay, self.joints, "kinematic model")
        # Where each controlled joint's position is in the plant's positions.
        self.position_index = self.robot.q_index
        self.lower, self.upper, self.home = self.robot.lower, self.robot.upper, self.robot.home
        self.clauses = ClauseSet(
            self._overlay.overlay.clauses,
            self.joints,
            self._overlay.frozen_joints,
            followers=self.robot.followers,
        )
        self.markers, self._marker_bodies = self.robot.markers, self.robot.marker_bodies
        self.marker_names = self.robot.marker_names
        self.clearance = clearance
        self._fields = RobotFields(self._overlay.field_margins) if inside_fields else None
        inspector = scene_graph.model_inspector()
        self._names = {g: inspector.GetName(g) for g in inspector.GetAllGeometryIds()}
        self._names.update(self._overlay.geometry_names)

    def JointIndex(self, name: str) -> int:
        return self.robot.JointIndex(name)

    def MarkerIndex(self, name: str) -> int:
        return self.robot.MarkerIndex(name)

    def SetPose(self, q: np.ndarray) -> None:
        """Puts the model in pose ``q`` (the controlled joints, rad)."""
        positions = self.robot.PlantPositions(q, self.plant.GetPositions(self._plant_context))
        self.plant.SetPositions(self._plant_context, positions)

    def Evaluate(self, q: np.ndarray) -> PoseEvaluation:
        """Marker states and collision pairs of pose ``q``."""
        q = np.asarray(q, dtype=float)
        self.SetPose(q)
        positions, directions = MarkerStates(self.markers, self._marker_bodies, self._plant_context)
        return PoseEvaluation(
            q=q.copy(),
            marker_positions=positions,
            marker_directions=directions,
            collision_pairs=self._CollisionPairs(),
        )

    def _CollisionPairs(self) -> tuple[tuple[str, str], ...]:
        query = self.scene_graph.get_query_output_port().Eval(self._scene_graph_context)
        if self._fields is not None:
            fields = self._fields.FindPairs(query)
            return tuple(
                (self._names[a], self._names[b])
                for a, b in zip(fields.geometry_A, fields.geometry_B)
            )
        pairs = query.ComputeSignedDistancePairwiseClosestPoints(self.clearance)
        return tuple(
            (self._names[p.id_A], self._names[p.id_B]) for p in pairs if p.distance < self.clearance
        )

    def Publish(self, q: np.ndarray, time: float = 0.0) -> None:
        """Draws pose ``q`` in Meshcat (at ``time`` of a recording, if one is running)."""
        self.SetPose(q)
        self.context.SetTime(time)
        self.visualizer.ForcedPublish(self.visualizer.GetMyContextFromRoot(self.context))

    def IsValid(self, q: np.ndarray) -> bool:
        """Within the joint limits and every constraint clause satisfied (Alg. 4's IS_VALID)."""
        return bool(
            np.all(q >= self.lower)
            and np.all(q <= self.upper)
            and not self.clauses.ActiveClauses(q, 0.0).any()
        )
