"""The station: the robot, its world, MoBeE, what moves the robot, companions and the viewer, in
one Diagram that knows no client (clients connect through :mod:`mobee_drake.station.parts`).

What moves the robot (``StationConfig.mover``):

- **kinematic**: MoBeE's virtual dynamics (eq. 5.7) are the robot. :class:`VirtualDynamics`
  integrates them every ``time_step`` and its positions pose the robot's geometry through
  ``MultibodyPositionToGeometryPose``; the plant only supplies kinematics and geometry and is not
  simulated.
- **reflex**: the same kinematic robot, moved by MoBeE 1.0's position moves and reflex; the
  attractor is the move command.
- **dynamic**: the MultibodyPlant is simulated with contact (its ``plant_config``), and follows
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

The diagram exports ``robot_state`` ((q, v) of MoBeE's joints, whichever robot moves),
``attractor`` (MoBeE's q*), MoBeE's ``marker_positions`` and ``field_pairs``, and takes,
unless the client sets them, ``attractor``, ``config_force`` and ``marker_forces`` as inputs.
"""

import dataclasses as dc

import numpy as np
from pydrake.geometry import Meshcat, MeshcatVisualizer, SceneGraph
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlant
from pydrake.systems.controllers import InverseDynamics, InverseDynamicsController
from pydrake.systems.framework import Diagram, DiagramBuilder, LeafSystem, OutputPort
from pydrake.systems.primitives import (
    Adder,
    MatrixGain,
    PassThrough,
    SharedPointerSystem,
    ZeroOrderHold,
)
from pydrake.systems.rendering import MultibodyPositionToGeometryPose

from mobee_drake.mobee.barrier import JointTracking, StepModel
from mobee_drake.mobee.params import MobeeParams
from mobee_drake.mobee.reflex import ReflexController
from mobee_drake.mobee.system import Mobee
from mobee_drake.robots.couplings import LinearMapSystem
from mobee_drake.robots.overlay import RobotOverlay
from mobee_drake.robots.scenario_robot import AddScenarioRobot
from mobee_drake.station.config import (
    Dynamic,
    Kinematic,
    Mover,
    Reflex,
    StationConfig,
    Visualization,
)
from mobee_drake.station.data_log import AddDataLog, DataLogger
from mobee_drake.station.parts import (
    CheckClientPorts,
    ClientPorts,
    Declared,
    StationParts,
    WarnOfUndeclaredHooks,
)
from mobee_drake.station.safety import SafetyMonitor
from mobee_drake.station.viewer import AddViewer
from mobee_drake.station.virtual_dynamics import VirtualDynamics
from mobee_drake.station.world_events import WorldEventLedger
from mobee_drake.world.live_world import LiveWorld, ObjectPose
from mobee_drake.world.objects import WorldEvent

# Gains of the dynamic robot's joint controller, per unit of (mass-normalised) acceleration:
# critically damped at 20 rad/s, which tracks MoBeE's virtual trajectory (time constants around
# one second) closely.
POSITION_GAIN, VELOCITY_GAIN = 400.0, 40.0


@dc.dataclass
class Station:
    """A built station and typed handles to its parts."""

    config: StationConfig
    diagram: Diagram
    plant: MultibodyPlant
    scene_graph: SceneGraph
    robot: RobotOverlay
    mobee: Mobee
    # What moves the robot: its virtual dynamics, or MoBeE 1.0's reflex controller.
    mover: VirtualDynamics | ReflexController
    world: LiveWorld
    monitor: SafetyMonitor
    # The diagram's outputs: the robot's (q, v) in MoBeE's joint order, whichever robot moves,
    # and MoBeE's attractor.
    robot_state: OutputPort
    attractor: OutputPort
    # The world events: the scripted ones by time, the clients' request ports, and the ledger
    # of those applied (see :mod:`mobee_drake.station.world_events`).
    scripted_events: list[WorldEvent]
    request_ports: list[OutputPort]
    event_ledger: WorldEventLedger
    # What the robot's client declared it offers (None: the attractor is an input of the
    # diagram), and each companion's client's.
    client_ports: ClientPorts | None = None
    companion_ports: list[ClientPorts] = dc.field(default_factory=list)
    meshcat: Meshcat | None = None
    visualizer: MeshcatVisualizer | None = None
    # The run's data log (None: the scenario turned it off).
    data_log: DataLogger | None = None

    @property
    def client(self) -> LeafSystem | None:
        """The robot's client's system (None without a client)."""
        return self.client_ports.system if self.client_ports is not None else None

    def Hooks(self, hook: str) -> list:
        """Every client's systems (or ports) declared for ``hook``, a hook field of
        :class:`~mobee_drake.station.parts.ClientPorts`: the robot's client's, then the
        companions'."""
        return [
            system
            for ports in [self.client_ports, *self.companion_ports]
            if ports is not None
            for system in Declared(ports, hook)
        ]


def _JointTracking(control: str) -> JointTracking:
    """The gains of the dynamic robot's joint controller in the position or velocity mode."""
    return JointTracking(POSITION_GAIN if control == "position" else 0.0, VELOCITY_GAIN)


def _StepModel(mover_config: Kinematic | Dynamic, time_step: float) -> StepModel:
    """How the next period moves the robot under MoBeE's total, for its safety barrier."""
    if not isinstance(mover_config, Dynamic):
        return StepModel(period=time_step)
    if mover_config.control == "force":
        return StepModel(period=time_step, implicit_damping=False)
    return StepModel(period=time_step, tracking=_JointTracking(mover_config.control))


def _AddMobee(
    builder: DiagramBuilder,
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    robot: RobotOverlay,
    joints: list[str],
    params: MobeeParams,
    time_step: float,
    mover_config: Mover,
    prefix: str = "",
):
    """One robot's MoBeE, what moves it (its virtual dynamics, eq. 5.7, or MoBeE 1.0's reflex
    controller, whose command input the caller connects) and the map of its state into the
    plant's (``x_plant = S [q; v] + s0``, followers of coupled joints included); returns MoBeE,
    the mover, S and the map's system."""
    # How the next period integrates MoBeE's total, for its safety barrier (MoBeE 1.0's reflex
    # moves the robot by itself, without MoBeE 2.0's total).
    step = None
    if not isinstance(mover_config, Reflex):
        step = _StepModel(mover_config, time_step)
    mobee = Mobee.AddToBuilder(
        builder,
        plant=plant,
        scene_graph=scene_graph,
        robot=robot,
        joints=joints,
        params=params,
        step=step,
        name=f"{prefix}mobee",
        # The dynamic robot's MoBeE sees the plant's measured state; the kinematic one's is its
        # virtual dynamics' (connected by the caller).
        measured_state=isinstance(mover_config, Dynamic),
    )
    if isinstance(mover_config, Reflex):
        mover = builder.AddNamedSystem(
            f"{prefix}reflex",
            ReflexController(
                initial_positions=mobee.home,
                period=time_step,
                params=mover_config,
                clauses=mobee.clauses,
            ),
        )
        builder.Connect(mobee.GetOutputPort("field_pairs"), mover.GetInputPort("field_pairs"))
    else:
        mover = builder.AddNamedSystem(
            f"{prefix}virtual_dynamics",
            VirtualDynamics(
                mass=mobee.mass,
                damping=mobee.damping,
                period=time_step,
                initial_positions=mobee.home,
                # The dynamic robot's MoBeE sees the plant's measured velocity.
                measured_damping=isinstance(mover_config, Dynamic),
            ),
        )
        builder.Connect(mobee.GetOutputPort("forces"), mover.GetInputPort("forces"))
    S, s0 = mobee.PlantStateMap()
    to_plant = builder.AddNamedSystem(f"{prefix}to_plant_state", LinearMapSystem(S, s0))
    builder.Connect(mover.GetOutputPort("state"), to_plant.get_input_port())
    return mobee, mover, S, to_plant


def _AddJointController(
    builder: DiagramBuilder,
    plant: MultibodyPlant,
    mobee: Mobee,
    state_map: np.ndarray,
    to_plant: LeafSystem,
    dynamic: Dynamic,
    time_step: float,
) -> None:
    """The dynamic robot's joint torques, by its control modality (see the module)."""
    n = plant.num_velocities()
    if dynamic.control == "force":
        held = builder.AddNamedSystem("total_hold", ZeroOrderHold(time_step, len(mobee.joints)))
        builder.Connect(mobee.GetOutputPort("total"), held.get_input_port())
        # q'' = total / M in MoBeE's order, then to the plant's velocity order.
        to_acceleration = state_map[plant.num_positions() :, len(mobee.joints) :]
        acceleration = builder.AddNamedSystem(
            "acceleration", MatrixGain(to_acceleration @ np.diag(1.0 / mobee.mass))
        )
        builder.Connect(held.get_output_port(), acceleration.get_input_port())
        controller = builder.AddNamedSystem("inverse_dynamics", InverseDynamics(plant))
        builder.Connect(
            acceleration.get_output_port(), controller.get_input_port_desired_acceleration()
        )
    else:
        gains = _JointTracking(dynamic.control)
        controller = builder.AddNamedSystem(
            "joint_controller",
            InverseDynamicsController(
                plant,
                np.full(n, gains.position_gain),
                np.zeros(n),
                np.full(n, gains.velocity_gain),
                False,
            ),
        )
        builder.Connect(to_plant.get_output_port(), controller.get_input_port_desired_state())
    builder.Connect(plant.get_state_output_port(), controller.get_input_port_estimated_state())
    builder.Connect(
        controller.get_output_port_generalized_force(),
        plant.get_applied_generalized_force_input_port(),
    )


def _AddCompanions(
    builder: DiagramBuilder,
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    world: LiveWorld,
    config: StationConfig,
    robots: list[tuple[RobotOverlay, list[str]]],
) -> tuple[list[OutputPort], list[ClientPorts]]:
    """Each companion's MoBeE, virtual dynamics and attractor program; returns the ports of
    their states in the plant's state vector and what their clients declared."""
    positions, declared = [], []
    for i, (companion, (overlay, joints)) in enumerate(zip(config.companions, robots)):
        prefix = f"{companion.name}_"
        mobee, mover, _, to_plant = _AddMobee(
            builder,
            plant,
            scene_graph,
            overlay,
            joints,
            companion.mobee,
            config.time_step,
            Kinematic(),
            prefix=prefix,
        )
        builder.Connect(mover.GetOutputPort("state"), mobee.GetInputPort("state"))
        parts = StationParts(
            builder=builder,
            plant=plant,
            scene_graph=scene_graph,
            mobee=mobee,
            world=world,
            robot_state=mover.GetOutputPort("state"),
            meshcat=None,
            random_seed=config.random_seed + 1 + i,  # its own draws
            period=config.time_step,
            prefix=prefix,
        )
        ports = companion.attractor.AddToBuilder(parts)
        CheckClientPorts(ports)
        builder.Connect(ports.attractor, mobee.GetInputPort("attractor"))
        positions.append(to_plant.get_output_port())
        declared.append(ports)
    return positions, declared


def _PoseKinematicRobots(
    builder: DiagramBuilder,
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    state_ports: list[OutputPort],
) -> None:
    """Poses the geometry of the kinematic robots (each port fills its own robot's entries of
    the plant's state); the plant is not simulated, only kept alive by the diagram."""
    builder.AddNamedSystem("plant_owner", SharedPointerSystem(plant))
    to_pose = builder.AddNamedSystem(
        "to_geometry_pose", MultibodyPositionToGeometryPose(plant, input_multibody_state=True)
    )
    plant_state = state_ports[0]
    if len(state_ports) > 1:
        adder = builder.AddNamedSystem(
            "all_robots_state", Adder(len(state_ports), plant.num_multibody_states())
        )
        for i, port in enumerate(state_ports):
            builder.Connect(port, adder.get_input_port(i))
        plant_state = adder.get_output_port()
    builder.Connect(plant_state, to_pose.get_input_port())
    builder.Connect(
        to_pose.get_output_port(), scene_graph.get_source_pose_port(plant.get_source_id())
    )


def _ConnectClient(
    builder: DiagramBuilder, client: ClientPorts | None, mobee: Mobee, mover, reflex: bool
) -> tuple[OutputPort, OutputPort | str]:
    """Checks what the client declares and wires its ports into MoBeE (and MoBeE 1.0's mover);
    without a client, the attractor and the client's forces are inputs of the diagram. Returns
    the attractor's port and the marker forces' port or diagram input name."""
    if client is None:
        attractor_input = builder.AddNamedSystem("attractor_input", PassThrough(len(mobee.joints)))
        builder.ExportInput(attractor_input.get_input_port(), "attractor")
        attractor = attractor_input.get_output_port()
    else:
        CheckClientPorts(client)
        attractor = client.attractor
    builder.Connect(attractor, mobee.GetInputPort("attractor"))
    if reflex:  # MoBeE 1.0: the attractor is the position move command.
        builder.Connect(attractor, mover.GetInputPort("command"))
    if client is None or client.config_force is None:
        builder.ExportInput(mobee.GetInputPort("config_force"), "config_force")
    else:
        builder.Connect(client.config_force, mobee.GetInputPort("config_force"))
    if client is None or client.marker_forces is None:
        builder.ExportInput(mobee.GetInputPort("marker_forces"), "marker_forces")
        return attractor, "marker_forces"
    builder.Connect(client.marker_forces, mobee.GetInputPort("marker_forces"))
    return attractor, client.marker_forces


def _AddPlantAndWorld(builder: DiagramBuilder, config: StationConfig):
    """The plant (simulated for the dynamic robot; kinematics and geometry only otherwise) and
    SceneGraph, the robot and its companions in it, and the world's objects; returns (plant,
    scene_graph, (robot overlay, controlled joints), the companions' likewise, the live world)."""
    if isinstance(config.mover, Dynamic):
        plant, scene_graph = AddMultibodyPlant(config.mover.plant_config, builder)
    else:
        scene_graph = builder.AddNamedSystem("scene_graph", SceneGraph())
        plant = MultibodyPlant(0.0)
        plant.RegisterAsSourceForSceneGraph(scene_graph)
    meshes = config.visualization.meshes
    robot = AddScenarioRobot(plant, scene_graph, config.robot, meshes=meshes)
    companions = [
        AddScenarioRobot(
            plant,
            scene_graph,
            c.robot,
            model_name=c.name,
            X_WRoot=ObjectPose(c.position, c.rpy_deg),
            meshes=meshes,
        )
        for c in config.companions
    ]
    world = LiveWorld(plant, scene_graph)
    for obj in config.objects:
        world.Register(obj)
    plant.Finalize()
    return plant, scene_graph, robot, companions, world


def _ConnectRobotState(
    builder, plant, scene_graph, config, mobee, mover, state_map, to_plant, companion_positions
) -> OutputPort:
    """What MoBeE sees of the robot: the dynamic robot's plant (through MoBeE's state selector),
    with its joint controller, or the kinematic robots' virtual dynamics, which pose their
    geometry; returns the robot's (q, v) in MoBeE's joint order."""
    if isinstance(config.mover, Dynamic):
        # The controlled joints' (q, v), read from the plant (followers left out).
        robot_state = builder.GetSubsystemByName("mobee_state_selector").get_output_port()
        _AddJointController(
            builder, plant, mobee, state_map, to_plant, config.mover, config.time_step
        )
        if config.mover.control != "force":
            # The barrier predicts the plant's lag behind the virtual trajectory it tracks.
            builder.Connect(mover.GetOutputPort("state"), mobee.GetInputPort("reference_state"))
        return robot_state
    _PoseKinematicRobots(
        builder, plant, scene_graph, [to_plant.get_output_port()] + companion_positions
    )
    robot_state = mover.GetOutputPort("state")
    builder.Connect(robot_state, mobee.GetInputPort("state"))
    return robot_state


def _AddSafetyMonitor(
    builder: DiagramBuilder, scene_graph: SceneGraph, world: LiveWorld, mobee: Mobee, period: float
) -> SafetyMonitor:
    """The monitor of the robot's safety: clearances, penetrations, the barrier's periods."""
    monitor = builder.AddNamedSystem(
        "safety_monitor",
        SafetyMonitor(names=world.names, period=period, num_joints=len(mobee.joints)),
    )
    builder.Connect(mobee.GetOutputPort("f_barrier"), monitor.GetInputPort("f_barrier"))
    builder.Connect(mobee.GetOutputPort("field_pairs"), monitor.GetInputPort("field_pairs"))
    builder.Connect(scene_graph.get_query_output_port(), monitor.GetInputPort("geometry_query"))
    return monitor


def _ExportOutputs(builder: DiagramBuilder, mobee, robot_state, attractor) -> None:
    """The station's outputs for scripts and clients beyond the diagram."""
    for port, name in (
        (robot_state, "robot_state"),
        (attractor, "attractor"),
        (mobee.GetOutputPort("marker_positions"), "marker_positions"),
        (mobee.GetOutputPort("field_pairs"), "field_pairs"),
    ):
        builder.ExportOutput(port, name)


def _AddRecords(builder, config, mobee, robot_state, attractor, client, companion_ports):
    """What records the run: the world-event ledger of the clients' requests and the scripted
    events, and the data log (when enabled). Returns the request ports, the ledger, the scripted
    events in time order and the data log (or None)."""
    # (The companions' first: they were built first, and the ledger counts in this order.)
    request_ports = [
        port for ports in [*companion_ports, client] if ports for port in ports.world_events
    ]
    event_ledger = builder.AddNamedSystem(
        "world_event_ledger", WorldEventLedger(num_request_ports=len(request_ports))
    )
    scripted_events = sorted(config.world_events, key=lambda e: e.time)
    data_log = None
    if config.data_log.enabled:
        data_log = AddDataLog(
            builder,
            config=config.data_log,
            time_step=config.time_step,
            mobee=mobee,
            robot_state=robot_state,
            attractor=attractor,
            event_counts=event_ledger.GetOutputPort("counts"),
            scripted_events=scripted_events,
            request_ports=request_ports,
            clients=Declared(client, "data_log") if client is not None else [],
        )
    return request_ports, event_ledger, scripted_events, data_log


def _CheckTrailMarker(visualization: Visualization, mobee: Mobee) -> None:
    """Fails with a clear message when the trail's marker is not one of the robot's."""
    if not visualization.trail_marker:
        return
    try:
        mobee.marker_index(visualization.trail_marker)
    except ValueError as e:
        raise ValueError(
            f"visualization trail_marker: {e} (the default, "
            f"{Visualization.trail_marker}, is the iCub's; '' draws no trail)"
        ) from None


def MakeMobeeStation(
    config: StationConfig, meshcat: Meshcat | None = None, *, prebuild_callback=None
) -> Station:
    """Builds the station of ``config``; with ``meshcat``, also the viewer.

    ``prebuild_callback(parts: StationParts) -> ClientPorts | None``, if given, adds the client
    (see :mod:`mobee_drake.station.parts`) and any other systems of the user's (a logger, a
    supervisor). What the client offers, its world-event requests among it, is what its
    :class:`~mobee_drake.station.parts.ClientPorts` declares, checked here; simulate the station
    with :func:`~mobee_drake.station.world_events.MakeSimulator`, which applies the requests.
    """
    builder = DiagramBuilder()
    mover_config = config.mover
    plant, scene_graph, (robot, joints), companions, world = _AddPlantAndWorld(builder, config)
    mobee, mover, state_map, to_plant = _AddMobee(
        builder, plant, scene_graph, robot, joints, config.mobee, config.time_step, mover_config
    )
    # The client's forces (eq. 5.9-5.10) are inputs of the diagram, for scripts and supervisors
    # (unfixed, they are zero), unless the client sets them (see _ConnectClient).
    companion_positions, companion_ports = _AddCompanions(
        builder, plant, scene_graph, world, config, companions
    )
    robot_state = _ConnectRobotState(
        builder, plant, scene_graph, config, mobee, mover, state_map, to_plant, companion_positions
    )
    monitor = _AddSafetyMonitor(builder, scene_graph, world, mobee, config.time_step)

    parts = StationParts(
        builder=builder,
        plant=plant,
        scene_graph=scene_graph,
        mobee=mobee,
        world=world,
        robot_state=robot_state,
        meshcat=meshcat,
        random_seed=config.random_seed,
        period=config.time_step,
    )
    client = prebuild_callback(parts) if prebuild_callback else None
    attractor, marker_forces = _ConnectClient(
        builder, client, mobee, mover, isinstance(mover_config, Reflex)
    )
    _CheckTrailMarker(config.visualization, mobee)  # With or without a viewer.
    visualizer = None
    if meshcat is not None:
        visualizer = AddViewer(
            builder,
            config=config,
            meshcat=meshcat,
            plant=plant,
            scene_graph=scene_graph,
            mobee=mobee,
            world=world,
            attractor=attractor,
            marker_forces=marker_forces,
        )
    request_ports, event_ledger, scripted_events, data_log = _AddRecords(
        builder, config, mobee, robot_state, attractor, client, companion_ports
    )
    _ExportOutputs(builder, mobee, robot_state, attractor)
    WarnOfUndeclaredHooks(builder.GetSystems(), [client, *companion_ports])
    diagram = builder.Build()
    diagram.set_name("mobee_station")
    return Station(
        config=config,
        diagram=diagram,
        plant=plant,
        scene_graph=scene_graph,
        robot=robot,
        mobee=mobee,
        mover=mover,
        world=world,
        monitor=monitor,
        robot_state=diagram.GetOutputPort("robot_state"),
        attractor=diagram.GetOutputPort("attractor"),
        scripted_events=scripted_events,
        request_ports=request_ports,
        event_ledger=event_ledger,
        client_ports=client,
        companion_ports=companion_ports,
        meshcat=meshcat,
        visualizer=visualizer,
        data_log=data_log,
    )
