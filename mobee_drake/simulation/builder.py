"""Builds the Diagram of a scenario: the robot (the iCub or a MoBeE XML robot), its world,
MoBeE, the robot model and the viewer.

Two robots, chosen by ``Scenario.robot_model``:

- **kinematic** (the default, for learning runs): MoBeE's virtual dynamics (eq. 5.7) are the
  robot. :class:`VirtualDynamics` integrates them every ``time_step`` and its positions pose the
  robot's geometry through ``MultibodyPositionToGeometryPose``; the plant only supplies
  kinematics and geometry and is not simulated.
- **dynamic**: the MultibodyPlant is simulated with ``plant_time_step`` and contact, and follows
  MoBeE, which sees the plant's measured state, through one of the modalities of ch. 5.2:

  - ``position``: MoBeE's virtual trajectory (q, v integrated by :class:`VirtualDynamics` from the
    forces at the measured state, as the real iCub's MoBeE sent commands every period) is the
    desired state of a joint-space inverse-dynamics PD controller (gravity and inertia
    compensated, as the iCub's position control);
  - ``velocity``: the same controller tracking the virtual velocity only (no position gain);
  - ``force``: the robot is torque-controlled so that it accelerates as eq. 5.7 asks: the joint
    torques are the inverse dynamics of ``q'' = total / M`` (so gravity, inertia and Coriolis
    forces are compensated and MoBeE's virtual mass is honoured). MoBeE's total is sampled every
    ``time_step`` and held in between.
"""

import dataclasses as dc

import numpy as np
from pydrake.geometry import (
    Meshcat,
    MeshcatVisualizer,
    SceneGraph,
)
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, MultibodyPlant
from pydrake.systems.controllers import (
    InverseDynamics,
    InverseDynamicsController,
)
from pydrake.systems.framework import Diagram, DiagramBuilder, OutputPort
from pydrake.systems.primitives import (
    Adder,
    ConstantVectorSource,
    MatrixGain,
    SharedPointerSystem,
    ZeroOrderHold,
)
from pydrake.systems.rendering import MultibodyPositionToGeometryPose

from mobee_drake.mobee.system import Mobee
from mobee_drake.planning.explorers import LoadAgentModel
from mobee_drake.planning.state_space import FromGraph, Lattice, StateActionSpace
from mobee_drake.planning.supervisor import Agent, ExplorationSupervisor
from mobee_drake.reaching.executor import StateActionExecutor
from mobee_drake.reflex.controller import ReflexController, ReflexParams
from mobee_drake.robots.assembly import JointStateSelector
from mobee_drake.robots.overlay import RobotOverlay
from mobee_drake.robots.scenario_robot import AddScenarioRobot
from mobee_drake.simulation.attractors import RandomAttractorSource, SliderAttractorSource
from mobee_drake.simulation.safety import SafetyMonitor
from mobee_drake.simulation.scenario import (
    ExploreAttractor,
    FixedAttractor,
    Scenario,
    SliderAttractor,
    StateActionAttractor,
)
from mobee_drake.simulation.virtual_dynamics import VirtualDynamics
from mobee_drake.simulation.world import LiveWorld, ObjectPose

# Gains of the dynamic robot's joint controller, per unit of (mass-normalised) acceleration:
# critically damped at 20 rad/s, which tracks MoBeE's virtual trajectory (time constants around
# one second) closely.
POSITION_GAIN, VELOCITY_GAIN = 400.0, 40.0
# How often the attractor sliders are read (s).
SLIDER_PERIOD = 0.05


@dc.dataclass
class Simulation:
    """A built scenario and handles to the parts a runner or a test needs."""

    scenario: Scenario
    diagram: Diagram
    plant: MultibodyPlant
    scene_graph: SceneGraph
    robot: RobotOverlay
    mobee: Mobee
    world: LiveWorld
    monitor: SafetyMonitor
    # The diagram's outputs: the robot's (q, v) in MoBeE's joint order, whichever robot model
    # runs, and MoBeE's attractor.
    robot_state: OutputPort
    attractor: OutputPort
    visualizer: MeshcatVisualizer | None = None
    # How many of each supervisor's world events the runner has applied (runner bookkeeping:
    # the events themselves are in the supervisors' state, the world in SceneGraph's Context).
    applied_requests: dict = dc.field(default_factory=dict)


def RoadmapStateSpace(folder: str, mobee: Mobee, joints: list[str]) -> StateActionSpace:
    """The state-action space of a saved task-relevant roadmap over an agent's ``joints``."""
    from mobee_drake.trm.roadmap import TaskRelevantRoadmap

    roadmap = TaskRelevantRoadmap.Load(folder)
    missing = [j for j in joints if j not in roadmap.joints]
    if missing:
        raise ValueError(f"{folder}: the roadmap has no joint(s) {', '.join(missing)}")
    lower, upper = mobee.position_limits
    mine = [mobee.joint_index(j) for j in joints]
    theirs = [roadmap.joints.index(j) for j in joints]
    centres = (roadmap.q[:, theirs] - lower[mine]) / (upper[mine] - lower[mine])
    return FromGraph(centres, roadmap.edges)


def _AttractorSource(
    builder: DiagramBuilder,
    program,
    seed: int,
    mobee: Mobee,
    robot_state: OutputPort,
    meshcat: Meshcat | None,
    name: str = "attractor",
) -> tuple[OutputPort, OutputPort | None]:
    """The system that sets ``mobee``'s attractor according to ``program``: its attractor port
    and, if it also sets the client's marker forces, their port."""
    lower, upper = mobee.position_limits
    if isinstance(program, StateActionAttractor):
        executor = builder.AddNamedSystem(
            name,
            StateActionExecutor(
                num_joints=len(mobee.joints),
                marker_index=mobee.marker_index(program.forcing.marker),
                num_markers=len(mobee.marker_names),
                initial_attractor=mobee.home,
                forcing=program.forcing,
                timing=program.timing,
            ),
        )
        builder.Connect(robot_state, executor.GetInputPort("robot_state"))
        builder.Connect(
            mobee.GetOutputPort("marker_positions"), executor.GetInputPort("marker_positions")
        )
        builder.Connect(mobee.GetOutputPort("field_pairs"), executor.GetInputPort("field_pairs"))
        return executor.GetOutputPort("attractor"), executor.GetOutputPort("marker_forces")
    if isinstance(program, ExploreAttractor):
        agents = [
            Agent(
                name=a.name,
                joints=a.joints,
                space=(
                    RoadmapStateSpace(a.roadmap, mobee, a.joints)
                    if a.roadmap
                    else Lattice(a.levels, len(a.joints), k=a.nearest or None)
                ),
                explorer=a.explorer,
                model=LoadAgentModel(a.model, a.name, a.explorer) if a.model else None,
            )
            for a in program.agents
        ]
        supervisor = builder.AddNamedSystem(
            name,
            ExplorationSupervisor(
                agents=agents,
                joints=mobee.joints,
                lower=lower,
                upper=upper,
                home=mobee.home,
                timing=program.timing,
            ),
        )
        builder.Connect(robot_state, supervisor.GetInputPort("robot_state"))
        return supervisor.get_output_port(), None
    if isinstance(program, SliderAttractor):
        if meshcat is None:
            raise ValueError("the slider attractor needs Meshcat (run with --meshcat)")
        return builder.AddNamedSystem(
            name,
            SliderAttractorSource(
                meshcat=meshcat,
                joints=mobee.joints,
                lower=lower,
                upper=upper,
                home=mobee.home,
                period=SLIDER_PERIOD,
            ),
        ).get_output_port(), None
    if isinstance(program, FixedAttractor):
        q_star = mobee.home
        for joint, value in program.joints_deg.items():
            q_star[mobee.joint_index(joint)] = np.radians(value)
        mobee.CheckAttractor(q_star)
        return builder.AddNamedSystem(name, ConstantVectorSource(q_star)).get_output_port(), None
    babbling = np.ones(len(mobee.joints), dtype=bool)
    if program.joints:
        babbling[:] = False
        for joint in program.joints:
            babbling[mobee.joint_index(joint)] = True
    return builder.AddNamedSystem(
        name,
        RandomAttractorSource(
            lower=lower,
            upper=upper,
            home=mobee.home,
            babbling=babbling,
            range_fraction=program.range_fraction,
            period=program.period,
            seed=seed,
        ),
    ).get_output_port(), None


def _AddMobee(
    builder: DiagramBuilder,
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    robot: RobotOverlay,
    joints: list[str],
    params,
    time_step: float,
    prefix: str = "",
    reflex: ReflexParams | None = None,
):
    """One robot's MoBeE, what moves the robot (its virtual dynamics, eq. 5.7, or with ``reflex``
    MoBeE 1.0's reflex controller, whose command input the caller connects) and the map of its
    state into the plant's; returns MoBeE, the mover, the selector matrix and its gain system."""
    mobee = builder.AddNamedSystem(
        f"{prefix}mobee", Mobee(plant, robot, joints=joints, params=params)
    )
    builder.Connect(scene_graph.get_query_output_port(), mobee.GetInputPort("geometry_query"))
    if reflex is None:
        _, damping, _ = params.PerJoint(joints)
        mover = builder.AddNamedSystem(
            f"{prefix}virtual_dynamics",
            VirtualDynamics(
                mass=mobee.mass,
                damping=np.array(damping),
                period=time_step,
                initial_positions=mobee.home,
            ),
        )
        builder.Connect(mobee.GetOutputPort("total"), mover.GetInputPort("total"))
        builder.Connect(mobee.GetOutputPort("damping"), mover.GetInputPort("damping"))
    else:
        mover = builder.AddNamedSystem(
            f"{prefix}reflex",
            ReflexController(
                initial_positions=mobee.home, period=time_step, params=reflex, clauses=mobee.clauses
            ),
        )
        builder.Connect(mobee.GetOutputPort("field_pairs"), mover.GetInputPort("field_pairs"))
    selector = JointStateSelector(plant, mobee.joints, robot.instance)
    to_plant = builder.AddNamedSystem(f"{prefix}to_plant_state", MatrixGain(selector))
    builder.Connect(mover.GetOutputPort("state"), to_plant.get_input_port())
    return mobee, mover, selector, to_plant


@dc.dataclass
class Parts:
    """What a prebuild callback may connect to: the systems and ports of the simulation."""

    builder: DiagramBuilder
    plant: MultibodyPlant
    scene_graph: SceneGraph
    mobee: Mobee
    world: LiveWorld
    # (q, v) of MoBeE's joints, and MoBeE's attractor.
    robot_state: OutputPort
    attractor: OutputPort


def BuildSimulation(
    scenario: Scenario, meshcat: Meshcat | None = None, *, prebuild=None
) -> Simulation:
    """Builds the scenario's diagram; with ``meshcat``, also the viewer.

    ``prebuild(parts: Parts)``, if given, is called before the diagram is built, to add a user's
    own systems (a supervisor, a logger). A system with an abstract output port named
    ``world_events`` edits the live world (see :mod:`mobee_drake.simulation.world`).
    """
    builder = DiagramBuilder()
    kinematic = scenario.robot_model == "kinematic"
    if kinematic:
        scene_graph = builder.AddNamedSystem("scene_graph", SceneGraph())
        plant = MultibodyPlant(0.0)
        plant.RegisterAsSourceForSceneGraph(scene_graph)
    else:
        plant, scene_graph = AddMultibodyPlantSceneGraph(builder, scenario.plant_time_step)
    robot, joints = AddScenarioRobot(plant, scene_graph, scenario.robot)
    companions = [
        AddScenarioRobot(
            plant,
            scene_graph,
            c.robot,
            model_name=c.name,
            X_WRoot=ObjectPose(c.position, c.rpy_deg),
        )
        for c in scenario.companions
    ]
    world = LiveWorld(plant, scene_graph)
    for obj in scenario.objects:
        world.Register(obj)
    plant.Finalize()

    reflex = scenario.reflex if scenario.controller == "reflex" else None
    mobee, mover, selector, to_plant = _AddMobee(
        builder,
        plant,
        scene_graph,
        robot,
        joints,
        scenario.mobee,
        scenario.time_step,
        reflex=reflex,
    )
    # The client's forces (eq. 5.9-5.10) are inputs of the diagram, for scripts and supervisors
    # (unfixed, they are zero), unless the attractor program sets the marker forces.
    builder.ExportInput(mobee.GetInputPort("config_force"), "config_force")
    companion_positions = []
    for i, (companion, (overlay, companion_joints)) in enumerate(
        zip(scenario.companions, companions)
    ):
        other, other_mover, _, other_to_plant = _AddMobee(
            builder,
            plant,
            scene_graph,
            overlay,
            companion_joints,
            companion.mobee,
            scenario.time_step,
            prefix=f"{companion.name}_",
        )
        builder.Connect(other_mover.GetOutputPort("state"), other.GetInputPort("state"))
        builder.Connect(
            _AttractorSource(
                builder,
                companion.attractor,
                scenario.random_seed + 1 + i,  # its own draws
                other,
                other_mover.GetOutputPort("state"),
                None,
                name=f"{companion.name}_attractor",
            )[0],
            other.GetInputPort("attractor"),
        )
        companion_positions.append(other_to_plant.get_output_port())

    if kinematic:
        # The plant lives as long as the diagram; it is not a system of it.
        builder.AddNamedSystem("plant_owner", SharedPointerSystem(plant))
        to_pose = builder.AddNamedSystem(
            "to_geometry_pose", MultibodyPositionToGeometryPose(plant, input_multibody_state=True)
        )
        plant_state = to_plant.get_output_port()
        if companion_positions:  # Each robot's joints fill their own entries of the state.
            adder = builder.AddNamedSystem(
                "all_robots_state",
                Adder(1 + len(companion_positions), plant.num_multibody_states()),
            )
            for i, port in enumerate([plant_state] + companion_positions):
                builder.Connect(port, adder.get_input_port(i))
            plant_state = adder.get_output_port()
        builder.Connect(plant_state, to_pose.get_input_port())
        builder.Connect(
            to_pose.get_output_port(), scene_graph.get_source_pose_port(plant.get_source_id())
        )
        builder.Connect(mover.GetOutputPort("state"), mobee.GetInputPort("state"))
        robot_state = mover.GetOutputPort("state")
    else:
        from_plant = builder.AddNamedSystem("from_plant_state", MatrixGain(selector.T))
        builder.Connect(plant.get_state_output_port(), from_plant.get_input_port())
        builder.Connect(from_plant.get_output_port(), mobee.GetInputPort("state"))
        robot_state = from_plant.get_output_port()
        n = plant.num_velocities()
        if scenario.control == "force":
            held = builder.AddNamedSystem(
                "total_hold", ZeroOrderHold(scenario.time_step, len(joints))
            )
            builder.Connect(mobee.GetOutputPort("total"), held.get_input_port())
            # q'' = total / M in MoBeE's order, then to the plant's velocity order.
            to_acceleration = selector[plant.num_positions() :, len(joints) :]
            acceleration = builder.AddNamedSystem(
                "acceleration", MatrixGain(to_acceleration @ np.diag(1.0 / mobee.mass))
            )
            builder.Connect(held.get_output_port(), acceleration.get_input_port())
            controller = builder.AddNamedSystem("inverse_dynamics", InverseDynamics(plant))
            builder.Connect(
                plant.get_state_output_port(), controller.get_input_port_estimated_state()
            )
            builder.Connect(
                acceleration.get_output_port(), controller.get_input_port_desired_acceleration()
            )
        else:
            kp = np.full(n, POSITION_GAIN if scenario.control == "position" else 0.0)
            controller = builder.AddNamedSystem(
                "joint_controller",
                InverseDynamicsController(plant, kp, np.zeros(n), np.full(n, VELOCITY_GAIN), False),
            )
            builder.Connect(
                plant.get_state_output_port(), controller.get_input_port_estimated_state()
            )
            builder.Connect(to_plant.get_output_port(), controller.get_input_port_desired_state())
        builder.Connect(
            controller.get_output_port_generalized_force(),
            plant.get_applied_generalized_force_input_port(),
        )

    attractor, marker_forces = _AttractorSource(
        builder, scenario.attractor, scenario.random_seed, mobee, robot_state, meshcat
    )
    builder.Connect(attractor, mobee.GetInputPort("attractor"))
    if reflex is not None:  # MoBeE 1.0: the attractor is the position move command
        builder.Connect(attractor, mover.GetInputPort("command"))
    if marker_forces is None:
        builder.ExportInput(mobee.GetInputPort("marker_forces"), "marker_forces")
    else:
        builder.Connect(marker_forces, mobee.GetInputPort("marker_forces"))

    monitor = builder.AddNamedSystem(
        "safety_monitor", SafetyMonitor(names=world.names, period=scenario.time_step)
    )
    builder.Connect(mobee.GetOutputPort("field_pairs"), monitor.GetInputPort("field_pairs"))
    builder.Connect(scene_graph.get_query_output_port(), monitor.GetInputPort("geometry_query"))

    visualizer = None
    if meshcat is not None:
        from mobee_drake.simulation.viewer import AddViewer

        visualizer = AddViewer(
            builder,
            scenario=scenario,
            meshcat=meshcat,
            plant=plant,
            scene_graph=scene_graph,
            mobee=mobee,
            attractor=attractor,
            marker_forces=marker_forces or "marker_forces",
        )

    if prebuild is not None:
        prebuild(
            Parts(
                builder=builder,
                plant=plant,
                scene_graph=scene_graph,
                mobee=mobee,
                world=world,
                robot_state=robot_state,
                attractor=attractor,
            )
        )
    builder.ExportOutput(robot_state, "robot_state")
    builder.ExportOutput(attractor, "attractor")
    diagram = builder.Build()
    diagram.set_name("mobee_simulation")
    return Simulation(
        scenario=scenario,
        diagram=diagram,
        plant=plant,
        scene_graph=scene_graph,
        robot=robot,
        mobee=mobee,
        world=world,
        monitor=monitor,
        robot_state=diagram.GetOutputPort("robot_state"),
        attractor=diagram.GetOutputPort("attractor"),
        visualizer=visualizer,
    )
