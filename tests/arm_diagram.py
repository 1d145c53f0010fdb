"""A three-link planar arm with MoBeE, for tests (see models/three_link_arm.urdf)."""

import pathlib

import numpy as np
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import DiagramBuilder

from mobee_drake.mobee.params import MobeeParams
from mobee_drake.mobee.system import Mobee
from mobee_drake.robots.assembly import AddRobotWithOverlay
from mobee_drake.world.live_world import LiveWorld
from mobee_drake.world.objects import Box, SceneObject

MODELS = pathlib.Path(__file__).resolve().parents[1] / "models"
JOINTS = ["joint1", "joint2", "joint3"]


class ArmDiagram:
    """The arm, optional fixed boxes and MoBeE, with the plant's positions set by the test."""

    def __init__(
        self, boxes=(), params=None, joints=JOINTS, couplings=(), step=None, boxes_first=False
    ):
        """``boxes_first`` registers the boxes before the robot (lower GeometryIds: SceneGraph
        then reports each box-robot pair with the box as its A)."""
        builder = DiagramBuilder()
        self.plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
        world = LiveWorld(self.plant, scene_graph)
        if boxes_first:
            self._Register(world, boxes)
        self.robot = AddRobotWithOverlay(
            self.plant,
            scene_graph,
            model_file=MODELS / "three_link_arm.urdf",
            overlay_file=MODELS / "three_link_arm_overlay.yaml",
            controlled_joints=joints,
            couplings=couplings,
        )
        if not boxes_first:
            self._Register(world, boxes)
        self.plant.Finalize()
        self.params = params or MobeeParams()
        self.dut = Mobee.AddToBuilder(
            builder,
            plant=self.plant,
            scene_graph=scene_graph,
            robot=self.robot,
            joints=list(joints),
            params=self.params,
            step=step,
        )
        self.diagram = builder.Build()
        self.root_context = self.diagram.CreateDefaultContext()
        self.context = self.dut.GetMyMutableContextFromRoot(self.root_context)
        self.plant_context = self.plant.GetMyMutableContextFromRoot(self.root_context)

    @staticmethod
    def _Register(world, boxes):
        for i, (size, center) in enumerate(boxes):
            world.Register(
                SceneObject(name=f"box{i}", shape=Box(size=list(size)), position=list(center))
            )

    def Set(self, q, v=(0.0, 0.0, 0.0)):
        self.plant.SetPositions(self.plant_context, np.asarray(q, dtype=float))
        self.plant.SetVelocities(self.plant_context, np.asarray(v, dtype=float))

    def Out(self, name):
        return self.dut.GetOutputPort(name).Eval(self.context)

    def Jacobian(self, body_name, p_WP):
        """The translational Jacobian of the world point p_WP moving with body_name."""
        body = self.plant.GetBodyByName(body_name)
        X_BW = body.EvalPoseInWorld(self.plant_context).inverse()
        world = self.plant.world_frame()
        return self.plant.CalcJacobianTranslationalVelocity(
            self.plant_context, JacobianWrtVariable.kV, body.body_frame(), X_BW @ p_WP, world, world
        )
