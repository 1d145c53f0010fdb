"""What the station is made of, as typed dataclasses for Drake's YAML loader.

The station is the robot (the iCub or a MoBeE XML robot), its world, MoBeE, what moves the
robot, companions with their own MoBeE and the viewer. What moves the robot is one of three
tagged choices, so that no illegal combination can be written:

- ``!Kinematic {}`` (the default, for learning runs): MoBeE's virtual dynamics (eq. 5.7) are the
  robot; the plant gives kinematics and geometry and is not simulated.
- ``!Dynamic {control: position | velocity | force, plant_config: {...}}``: the MultibodyPlant
  (Drake's :class:`MultibodyPlantConfig`: time step, contact model) is simulated and follows MoBeE
  through one modality of ch. 5.2.
- ``!Reflex {speed_deg: ..., history: ..., tolerance_deg: ...}``: MoBeE 1.0's position moves with
  the rewinding reflex (ch. 4.1) move the kinematic robot.
"""

import copy
import dataclasses as dc
import math

from pydrake.multibody.plant import (
    ApplyMultibodyPlantConfig,
    MultibodyPlant,
    MultibodyPlantConfig,
)

from mobee_drake.mobee.params import Dissertation, MobeeParams
from mobee_drake.mobee.reflex import ReflexParams
from mobee_drake.resources import ResolveModelPath
from mobee_drake.robots.icub import IcubConfig
from mobee_drake.robots.model_cache import MESH_RESOLUTIONS
from mobee_drake.robots.model_file import ModelFileConfig
from mobee_drake.robots.zero_position import ZeroPositionConfig
from mobee_drake.station.attractors import FixedAttractor, RandomAttractors
from mobee_drake.world.objects import (
    OBJECT_ROLES,
    Box,
    Cylinder,
    Mesh,
    SceneObject,
    Sphere,
    WorldEvent,
)

CONTROL_MODALITIES = ("position", "velocity", "force")
# The longest period MoBeE may run at (s; our choice: the original ran at 20 ms, and at 0.1 s a
# hand at 1 m/s already moves 10 cm, more than MoBeE's fields, between two reactions).
MAX_TIME_STEP = 0.1
# The shortest periods (s): MoBeE's, and the simulated plant's (shorter ones only make a run take
# days without a line of output: 1e-9 s is 10^9 periods a simulated second).
MIN_TIME_STEP = 1e-4
MIN_PLANT_TIME_STEP = 1e-5
# How far from the world's origin an object may be (m): a robot's workspace, with room to spare
# (an object at 1e300 m breaks SceneGraph's arithmetic without a word).
MAX_WORLD_EXTENT = 1000.0
# The most objects a scenario may list: SceneGraph's collision filter grows with the square of
# the geometries, in memory and in time (docs/benchmarks.md, `mobee-drake bench objects`).
MAX_OBJECTS = 2000


def _Finite(values) -> bool:
    return all(math.isfinite(v) for v in values)


def _ShapeErrors(name: str, shape) -> list[str]:
    if isinstance(shape, Mesh):
        try:
            ResolveModelPath(shape.file)
        except ValueError as e:
            return [f"object '{name}': mesh file {e}"]
    sizes = {
        Box: lambda s: list(s.size),
        Sphere: lambda s: [s.radius],
        Cylinder: lambda s: [s.radius, s.length],
        Mesh: lambda s: [s.scale],
    }[type(shape)](shape)
    if isinstance(shape, Box) and len(sizes) != 3:
        return [f"object '{name}': a box's size needs three numbers, got {sizes}"]
    if not (_Finite(sizes) and min(sizes) > 0):
        return [f"object '{name}': its shape's sizes must be finite and > 0, got {sizes}"]
    return []


def _Zeros3() -> list[float]:
    return [0.0, 0.0, 0.0]


@dc.dataclass
class Kinematic:
    """MoBeE's virtual dynamics (eq. 5.7) move the robot, every ``time_step``."""


@dc.dataclass
class Dynamic:
    """The MultibodyPlant is simulated, with contact, and follows MoBeE (ch. 5.2)."""

    # "position" (tracks MoBeE's virtual trajectory), "velocity" (its velocity only) or "force"
    # (the joint torques that accelerate the robot as eq. 5.7 asks).
    control: str = "position"
    plant_config: MultibodyPlantConfig = dc.field(
        default_factory=lambda: MultibodyPlantConfig(time_step=0.001)
    )


@dc.dataclass
class Reflex(ReflexParams):
    """MoBeE 1.0: position moves with the reflex that rewinds to the last waypoint (ch. 4.1)."""


Mover = Kinematic | Dynamic | Reflex


@dc.dataclass
class Companion:
    """Another robot in the same world with its own MoBeE (dissertation ch. 4.1.2, Fig. 4.5).

    Kinematic runs only. Each robot's MoBeE keeps its own body out of the other's way: to it, the
    other robot is an obstacle.
    """

    name: str = "katana"
    robot: ZeroPositionConfig | IcubConfig | ModelFileConfig = dc.field(
        default_factory=ZeroPositionConfig
    )
    # Pose of the companion's root in world: metres, degrees.
    position: list[float] = dc.field(default_factory=_Zeros3)
    rpy_deg: list[float] = dc.field(default_factory=_Zeros3)
    # MoBeE's constants: the defaults, or ``!Dissertation {}`` (mobee_drake/mobee/params.py).
    mobee: MobeeParams | Dissertation = dc.field(default_factory=MobeeParams)
    attractor: RandomAttractors | FixedAttractor = dc.field(default_factory=RandomAttractors)


@dc.dataclass
class Visualization:
    """What the viewer draws when the station has Meshcat."""

    # The marker whose path is drawn as a trail ("" for none).
    trail_marker: str = "r_palm"
    # Draw the attractor as a translucent second robot.
    show_attractor: bool = True
    # Frames per second of the viewer and of a recording (film's rate: with the robot moving,
    # the live stream stays within about 100 kB/s; see `mobee-drake bench viewer`), and the most
    # frames a recording keeps (a longer run is recorded at a lower rate), which bounds its size.
    frame_rate: float = 24.0
    max_recorded_frames: int = 3600
    # The camera (world, m), both given or both empty; empty: framed on the task when the run
    # starts (the trail's marker and the world's objects, seen from in front of the iCub, which
    # faces -x, a little to its right and above).
    camera_position: list[float] = dc.field(default_factory=list)
    camera_target: list[float] = dc.field(default_factory=list)
    # The robot's visual meshes: "light" (decimated, a tenth of the triangles, for viewers and
    # recordings) or "full" (icub-models' own).
    meshes: str = "light"


@dc.dataclass
class DataLog:
    """What the run's data log keeps (see :mod:`mobee_drake.station.data_log`)."""

    enabled: bool = True
    # Seconds between rows (0: every control period).
    period: float = 0.0
    # Each force term of eq. 5.7 per joint (True), or only its norm (False).
    full_forces: bool = False
    # The most rows a run's log keeps in memory (about 5 kB each for the iCub at the peak, with
    # Drake's sink's spare capacity and the written table): a longer run is logged at a longer
    # period (see mobee_drake.scenario.BuildScenario). 30,000: a 10-minute run at 20 ms.
    max_rows: int = 30_000


@dc.dataclass
class StationConfig:
    """The robot, its world and what moves it (see ``diagrams/`` for examples)."""

    # The iCub, ``!ZeroPositionConfig {file: katana.xml}`` for a robot from a MoBeE XML file, or
    # ``!ModelFileConfig {file: arm.urdf, overlay: arm_overlay.yaml}`` for a URDF or SDFormat
    # robot with its MoBeE overlay.
    robot: IcubConfig | ZeroPositionConfig | ModelFileConfig = dc.field(default_factory=IcubConfig)
    objects: list[SceneObject] = dc.field(default_factory=list)
    # Other robots in the same world, each with its own MoBeE (not with the !Dynamic mover).
    companions: list[Companion] = dc.field(default_factory=list)
    # MoBeE's constants: the defaults, or ``!Dissertation {}`` (mobee_drake/mobee/params.py).
    mobee: MobeeParams | Dissertation = dc.field(default_factory=MobeeParams)
    # What moves the robot (see the module).
    mover: Mover = dc.field(default_factory=Kinematic)
    # MoBeE's period (s): the kinematic robot's integration step, the dynamic robot's control rate.
    time_step: float = 0.01
    # Scripted changes of the world.
    world_events: list[WorldEvent] = dc.field(default_factory=list)
    visualization: Visualization = dc.field(default_factory=Visualization)
    data_log: DataLog = dc.field(default_factory=DataLog)
    # Seeds every generator of a run: random attractors, exploring agents, companions.
    random_seed: int = 0


def StationConfigErrors(config: StationConfig) -> list[str]:
    """What is wrong with ``config`` that its types cannot say (empty: nothing)."""
    names = [obj.name for obj in config.objects]
    return (
        _MoverErrors(config)
        + _TimingAndViewErrors(config)
        + _ObjectErrors(config.objects)
        + _WorldEventErrors(config.world_events, set(names))
        + _CompanionErrors(config, set(names))
    )


def _MoverErrors(config: StationConfig) -> list[str]:
    """The dynamic robot's control and plant, MoBeE 1.0's reflex."""
    errors = []
    mover = config.mover
    if isinstance(mover, Dynamic):
        if mover.control not in CONTROL_MODALITIES:
            errors.append(
                f"mover control must be one of {CONTROL_MODALITIES}, got '{mover.control}'"
            )
        step = mover.plant_config.time_step
        try:  # Drake's own check of its strings (contact model, approximation, solver)
            probe = copy.deepcopy(mover.plant_config)
            probe.time_step = 1e-3  # (the step is checked below)
            ApplyMultibodyPlantConfig(probe, MultibodyPlant(probe.time_step))
        except (RuntimeError, ValueError) as error:
            errors.append(f"plant_config: {error}")
        if not (math.isfinite(step) and MIN_PLANT_TIME_STEP <= step <= config.time_step):
            errors.append(
                f"plant_config time_step must be >= {MIN_PLANT_TIME_STEP:g} s and <= time_step, "
                f"got {step}"
            )
    if isinstance(mover, Reflex) and not (
        _Finite([mover.speed_deg, mover.tolerance_deg])
        and mover.speed_deg > 0
        and mover.history >= 2
        and mover.tolerance_deg > 0
    ):
        errors.append("reflex: speed_deg and tolerance_deg must be finite and > 0, history >= 2")
    return errors


def _TimingAndViewErrors(config: StationConfig) -> list[str]:
    """The robot's joints, MoBeE's period, the viewer and the data log."""
    errors = []
    if isinstance(config.robot, IcubConfig) and not config.robot.controlled_joints:
        errors.append("robot controlled_joints must name at least one joint")
    for robot in [config.robot] + [c.robot for c in config.companions]:
        if isinstance(robot, ModelFileConfig):
            for key in ("file", "overlay"):
                try:
                    ResolveModelPath(getattr(robot, key))
                except ValueError as e:
                    errors.append(f"robot {key}: {e}")
    if not (math.isfinite(config.time_step) and MIN_TIME_STEP <= config.time_step <= MAX_TIME_STEP):
        errors.append(
            f"time_step must be >= {MIN_TIME_STEP:g} and <= {MAX_TIME_STEP} s, "
            f"got {config.time_step}"
        )
    shown, log = config.visualization, config.data_log
    if not (math.isfinite(shown.frame_rate) and shown.frame_rate > 0):
        errors.append(f"visualization frame_rate must be > 0, got {shown.frame_rate}")
    camera = shown.camera_position + shown.camera_target
    if camera and not (
        len(shown.camera_position) == len(shown.camera_target) == 3 and _Finite(camera)
    ):
        errors.append(
            "visualization camera_position and camera_target need three finite numbers each "
            "(or leave both out: the camera is then framed on the task)"
        )
    if shown.meshes not in MESH_RESOLUTIONS:
        errors.append(
            f"visualization meshes must be one of {', '.join(MESH_RESOLUTIONS)}, "
            f"got '{shown.meshes}'"
        )
    if shown.max_recorded_frames < 1:
        errors.append(
            f"visualization max_recorded_frames must be >= 1, got {shown.max_recorded_frames}"
        )
    if log.max_rows < 1:
        errors.append(f"data_log max_rows must be >= 1, got {log.max_rows}")
    if not (math.isfinite(log.period) and log.period >= 0):
        errors.append(f"data_log period must be >= 0 s (0: every control period), got {log.period}")
    return errors


def _ObjectErrors(objects: list[SceneObject]) -> list[str]:
    """Their number, names, roles, poses and shapes."""
    errors = []
    names = set()
    if len(objects) > MAX_OBJECTS:
        errors.append(
            f"objects: at most {MAX_OBJECTS} (SceneGraph's collision filter grows with their "
            f"square), got {len(objects)}"
        )
    for obj in objects:
        if not obj.name or obj.name in names:
            errors.append(f"every object needs a unique name, got '{obj.name}'")
        names.add(obj.name)
        if obj.role not in OBJECT_ROLES:
            errors.append(
                f"object '{obj.name}': role must be one of {OBJECT_ROLES}, got '{obj.role}'"
            )
        if not (len(obj.position) == 3 and len(obj.rpy_deg) == 3):
            errors.append(f"object '{obj.name}': position and rpy_deg need three numbers")
        elif not _Finite(obj.position + obj.rpy_deg):
            errors.append(f"object '{obj.name}': position and rpy_deg must be finite")
        elif max(map(abs, obj.position)) > MAX_WORLD_EXTENT:
            errors.append(
                f"object '{obj.name}': position must lie within {MAX_WORLD_EXTENT:g} m of the "
                f"world's origin, got {obj.position}"
            )
        errors += _ShapeErrors(obj.name, obj.shape)
    return errors


def _WorldEventErrors(events: list[WorldEvent], names: set[str]) -> list[str]:
    """Each scripted event's object, role, position and time."""
    errors = []
    for event in events:
        where = f"world event at {event.time} s"
        if event.object not in names:
            errors.append(f"{where} names unknown object '{event.object}'")
        if event.role not in OBJECT_ROLES + ("",):
            errors.append(f"{where}: role must be one of {OBJECT_ROLES}, got '{event.role}'")
        if len(event.position) not in (0, 3):
            errors.append(f"{where}: position needs three numbers")
        if not (_Finite([event.time, *event.position]) and event.time >= 0):
            errors.append(f"{where}: its time must be >= 0 and its numbers finite")
        elif event.position and max(map(abs, event.position)) > MAX_WORLD_EXTENT:
            errors.append(f"{where}: position must lie within {MAX_WORLD_EXTENT:g} m of the origin")
    return errors


def _CompanionErrors(config: StationConfig, names: set[str]) -> list[str]:
    """Each companion's mover, name (not an object's), pose and attractor."""
    errors, mover = [], config.mover
    for companion in config.companions:
        if isinstance(mover, Dynamic):
            errors.append(
                f"companion '{companion.name}': other robots run with the kinematic robot only "
                "(!Kinematic or !Reflex)"
            )
        if not companion.name or companion.name in names:
            errors.append(
                f"every companion needs a unique name, not an object's, got '{companion.name}'"
            )
        names.add(companion.name)
        if not (len(companion.position) == 3 and len(companion.rpy_deg) == 3):
            errors.append(f"companion '{companion.name}': position and rpy_deg need three numbers")
        elif not _Finite(companion.position + companion.rpy_deg):
            errors.append(f"companion '{companion.name}': position and rpy_deg must be finite")
        try:
            companion.attractor.Validate()
        except ValueError as e:
            errors.append(f"companion '{companion.name}': {e}")
    return errors
