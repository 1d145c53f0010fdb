"""The controllers of the reactive benchmark (:mod:`mobee_drake.experiments.bench_reactive`): MoBeE
with a preset of its parameters, and Drake's differential inverse kinematics; each runs a task for
a horizon from its start and returns the trajectory."""

from collections.abc import Callable
import contextlib
import dataclasses as dc
import logging
import os
import sys
import time

import numpy as np
from pydrake.common import Parallelism
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.inverse_kinematics import DifferentialInverseKinematicsSystem
from pydrake.multibody.math import SpatialVelocity
from pydrake.multibody.tree import FixedOffsetFrame
from pydrake.planning import DofMask, JointLimits, RobotDiagramBuilder, SceneGraphCollisionChecker
from pydrake.systems.framework import BusValue

from mobee_drake.experiments.reactive_tasks import PALM, PERIOD, ReachTask
from mobee_drake.mobee.flow import FlowParams
from mobee_drake.mobee.params import Dissertation, MobeeParams
from mobee_drake.resources import ResolveModelFile
from mobee_drake.robots.controlled_robot import ControlledRobot
from mobee_drake.robots.icub import (
    IcubConfig,
)
from mobee_drake.robots.overlay import LoadOverlay
from mobee_drake.robots.scenario_robot import AddScenarioRobot
from mobee_drake.scenario import BuildScenario, Scenario
from mobee_drake.station.attractors import FixedAttractor, MarkerGoal
from mobee_drake.station.config import DataLog, Kinematic
from mobee_drake.station.world_events import MakeSimulator
from mobee_drake.world.live_world import LiveWorld

# DiffIK's joint speed limit (rad/s).
SPEED_LIMIT = 0.4
# DiffIK's clamp on the palm's desired speed (m/s per axis) at SPEED_LIMIT.
PALM_SPEED = 0.3
# The gain of MoBeE's palm goal (a MarkerGoal), when it is given the palm's target.
PALM_GOAL_GAIN = 200.0
# MoBeE's speed cap with its default constants (spring maximum / damping, rad/s), at which DiffIK
# runs too for a comparison at equal speed.
MOBEE_SPEED_CAP = MobeeParams().spring_squash.m / MobeeParams().damping
# DiffIK's collision constraint ignores pairs farther apart than this (m).
INFLUENCE_DISTANCE = 0.10


@dc.dataclass
class Trajectory:
    """The joint positions every period from the start (steps + 1 rows, MoBeE's order), the wall
    time (s) of each control step of the controller alone, and the periods in which the
    controller gave up (DiffIK: its QP failed and it commanded zero velocity)."""

    q: np.ndarray
    step_seconds: np.ndarray
    failed_steps: int = 0


@dc.dataclass
class ReactiveController:
    """A controller under benchmark: its label and ``run(task, horizon) -> Trajectory``."""

    label: str
    run: Callable[[ReachTask, float], Trajectory]


# MoBeE's parameter sets under benchmark, by name (later presets join here).
MOBEE_PRESETS: dict[str, Callable[[], MobeeParams]] = {
    "defaults": MobeeParams,
    "dissertation": Dissertation,
    # The defaults without the obstacle-aware flow (what the flow adds).
    "defaults_no_flow": lambda: MobeeParams(flow=FlowParams(enabled=False)),
}


def MobeeController(
    params: MobeeParams, label: str = "MoBeE", palm_goal_gain: float = 0.0
) -> ReactiveController:
    """MoBeE with ``params``, moving the kinematic robot of the task's station (its virtual
    dynamics, eq. 5.7, integrated every period) towards the goal posture as its attractor, and
    with ``palm_goal_gain`` > 0 also pulling the palm to the goal's palm position (a
    :class:`MarkerGoal`, eq. 5.10: the target DiffIK is given).

    A step's cost is the evaluation of MoBeE's total force (forward kinematics, SceneGraph's
    signed-distance query, every term and the safety barrier), which the station's integration
    then reads from the cache; the integration itself (a few us) is not counted.
    """

    def Run(task: ReachTask, horizon: float) -> Trajectory:
        scenario = Scenario(
            robot=task.Robot(),
            objects=list(task.objects),
            mobee=params,
            mover=Kinematic(),
            time_step=PERIOD,
            attractor=FixedAttractor(
                joints_deg=task.GoalDegrees(),
                marker_goals=[
                    MarkerGoal(marker="r_palm", position=list(task.goal_palm), gain=palm_goal_gain)
                ]
                if palm_goal_gain > 0
                else [],
            ),
            duration=horizon,
            data_log=DataLog(enabled=False),
        )
        station = BuildScenario(scenario)
        simulator = MakeSimulator(station)
        simulator.Initialize()
        context = simulator.get_mutable_context()
        total = station.mobee.GetOutputPort("total")
        mobee_context = station.mobee.GetMyContextFromRoot(context)
        n, steps = len(task.joints), round(horizon / PERIOD)
        q, seconds = np.empty((steps + 1, n)), np.empty(steps)
        q[0] = station.robot_state.Eval(context)[:n]
        for k in range(steps):
            begin = time.perf_counter()
            total.Eval(mobee_context)
            seconds[k] = time.perf_counter() - begin
            simulator.AdvanceTo((k + 1) * PERIOD)
            q[k + 1] = station.robot_state.Eval(context)[:n]
        return Trajectory(q, seconds)

    return ReactiveController(label, Run)


@contextlib.contextmanager
def _Quiet():
    """Drake's log at errors only (DiffIK warns at every period its QP fails, with the QP's
    violated constraints) and the process's standard output closed to C code (OSQP prints
    "Polishing not needed" at some solves)."""
    logger = logging.getLogger("drake")
    level = logger.level
    logger.setLevel(logging.ERROR)
    sys.stdout.flush()
    saved, devnull = os.dup(1), os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    try:
        yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)
        logger.setLevel(level)


def DiffIkController(
    safety_distance: float, label: str, speed_limit: float = SPEED_LIMIT
) -> ReactiveController:
    """Drake's ``DifferentialInverseKinematicsSystem``, all 20 joints active.

    Its ``SceneGraphCollisionChecker`` sees the task's robot and objects in a ``RobotDiagram``
    built as the station builds them (the same overlay primitives, filters and objects). The
    recipe:

    - ``LeastSquaresCost`` on the palm's translation (rotation masked out; weight 100, as Drake
      advises over the centering cost), the goal's palm position as the desired pose and
      ``K_VX`` = 1, the desired palm speed clamped to 0.3 m/s per axis;
    - ``JointCenteringCost`` (gain 1/s) towards the goal posture (the nominal posture);
    - ``CollisionConstraint`` at ``safety_distance`` (pairs within ``INFLUENCE_DISTANCE``);
    - ``JointVelocityLimitConstraint`` at ``speed_limit`` (rad/s; Drake's default margins), the
      palm's speed clamp scaled with it (0.3 m/s at ``SPEED_LIMIT``).

    The commanded velocity is integrated every period (explicit Euler) and the positions fed
    back. A step's cost is the evaluation of the commanded velocity (the checker's distances,
    Jacobians and the QP).
    """

    def Run(task: ReachTask, horizon: float) -> Trajectory:
        builder = RobotDiagramBuilder(time_step=0.0)
        plant, scene_graph = builder.plant(), builder.scene_graph()
        overlay, joints = AddScenarioRobot(plant, scene_graph, task.Robot())
        world = LiveWorld(plant, scene_graph)
        for obj in task.objects:
            world.Register(obj)
        (marker,) = [m for m in overlay.markers if m.name == PALM]
        palm = plant.AddFrame(
            FixedOffsetFrame(
                f"{PALM}_marker",
                plant.GetBodyByName(marker.body_name, overlay.instance).body_frame(),
                RigidTransform(marker.p_BM),
            )
        )
        plant.Finalize()
        robot = ControlledRobot.Of(plant, overlay, joints, "DiffIK")
        diagram = builder.Build()
        with _Quiet():
            checker = SceneGraphCollisionChecker(
                model=diagram,
                robot_model_instances=[overlay.instance],
                edge_step_size=0.05,
                env_collision_padding=0.0,
                self_collision_padding=0.0,
                implicit_context_parallelism=Parallelism(1),
            )
        system = _DiffIkSystem(
            plant, checker, palm.scoped_name().to_string(), safety_distance, speed_limit
        )
        context = system.CreateDefaultContext()
        positions = plant.GetPositions(plant.CreateDefaultContext())
        goal_positions = robot.PlantPositions(task.goal, positions.copy())
        plant_context = plant.CreateDefaultContext()
        plant.SetPositions(plant_context, goal_positions)
        desired = BusValue()
        desired.Set(palm.scoped_name().to_string(), AbstractValue.Make(palm.CalcPoseInWorld(
            plant_context
        )))  # fmt: skip
        system.get_input_port_desired_cartesian_poses().FixValue(context, desired)
        system.get_input_port_nominal_posture().FixValue(context, goal_positions)
        position_port = system.get_input_port_position()
        command = system.get_output_port_commanded_velocity()
        n, steps = len(task.joints), round(horizon / PERIOD)
        q, seconds = np.empty((steps + 1, n)), np.empty(steps)
        q[0] = task.start
        failed = 0
        with _Quiet():
            for k in range(steps):
                position_port.FixValue(context, robot.PlantPositions(q[k], positions))
                begin = time.perf_counter()
                v = command.Eval(context)
                seconds[k] = time.perf_counter() - begin
                failed += not v.any()
                q[k + 1] = q[k] + PERIOD * v[robot.v_index]
        return Trajectory(q, seconds, failed)

    return ReactiveController(label, Run)


def _DiffIkSystem(plant, checker, frame: str, safety_distance: float, speed_limit: float):
    """Drake's DiffIK with the recipe of :func:`DiffIkController`."""
    System = DifferentialInverseKinematicsSystem
    translation = {frame: np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])}
    recipe = System.Recipe()
    recipe.AddIngredient(
        System.LeastSquaresCost(
            System.LeastSquaresCost.Config(
                cartesian_qp_weight=100.0, cartesian_axis_masks=translation
            )
        )
    )
    recipe.AddIngredient(
        System.JointCenteringCost(
            System.JointCenteringCost.Config(posture_gain=1.0, cartesian_axis_masks=translation)
        )
    )
    recipe.AddIngredient(
        System.CollisionConstraint(
            System.CollisionConstraint.Config(
                safety_distance=safety_distance, influence_distance=INFLUENCE_DISTANCE
            )
        )
    )
    limits = JointLimits(plant)
    n = plant.num_velocities()
    recipe.AddIngredient(
        System.JointVelocityLimitConstraint(
            System.JointVelocityLimitConstraint.Config(),
            JointLimits(
                limits.position_lower(),
                limits.position_upper(),
                np.full(n, -speed_limit),
                np.full(n, speed_limit),
                limits.acceleration_lower(),
                limits.acceleration_upper(),
            ),
        )
    )
    return System(
        recipe=recipe,
        task_frame="world",
        collision_checker=checker,
        active_dof=DofMask(n, True),
        time_step=PERIOD,
        K_VX=1.0,
        Vd_TG_limit=SpatialVelocity(
            w=np.full(3, 1.0), v=np.full(3, PALM_SPEED * speed_limit / SPEED_LIMIT)
        ),
    )


def FieldMargin() -> float:
    """MoBeE's default field margin of the iCub's overlay (m): DiffIK's safety distance at
    equal clearance (the forearms' and the head's fields are 1 cm wider)."""
    return LoadOverlay(ResolveModelFile(IcubConfig().overlay)).default_field


CONTROLLERS = [
    "mobee",
    "mobee_posture",
    "mobee_dissertation",
    "diffik_1cm",
    "diffik_field",
    "diffik_fast",
]


def Controllers(preset: str = "defaults") -> dict[str, ReactiveController]:
    """The controllers under benchmark, by name: MoBeE with the named preset, given the goal
    posture and the palm's target (what DiffIK is given) or the posture only; MoBeE with the
    dissertation's constants; DiffIK at a 1 cm safety distance and at MoBeE's field margin, and
    at 1 cm with MoBeE's speed cap."""
    field = FieldMargin()
    params = MOBEE_PRESETS[preset]
    return {
        "mobee": MobeeController(params(), f"MoBeE ({preset}), palm goal", PALM_GOAL_GAIN),
        "mobee_posture": MobeeController(params(), f"MoBeE ({preset}), posture only"),
        "mobee_dissertation": MobeeController(Dissertation(), "MoBeE (dissertation)"),
        "diffik_1cm": DiffIkController(0.01, "DiffIK, 1 cm"),
        "diffik_field": DiffIkController(field, f"DiffIK, {100 * field:g} cm (MoBeE's field)"),
        "diffik_fast": DiffIkController(
            0.01, f"DiffIK, 1 cm, {MOBEE_SPEED_CAP:g} rad/s", speed_limit=MOBEE_SPEED_CAP
        ),
    }
