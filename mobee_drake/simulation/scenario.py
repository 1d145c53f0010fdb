"""Scenario files: what to simulate, as typed dataclasses loaded with Drake's YAML loader.

A scenario (``diagrams/*.yaml``) names the robot, the objects of its world, MoBeE's parameters,
the robot model and control modality, the attractor program, the time step and duration, what
to show, and the random seed. :func:`LoadScenario` reads one; errors name the file, the key and,
where YAML gives it, the line.
"""

import dataclasses as dc
import pathlib

from mobee_drake.mobee.params import MobeeParams
from mobee_drake.planning.explorers import ExplorerConfig
from mobee_drake.planning.supervisor import ActionTiming
from mobee_drake.reaching.executor import ReachForcing
from mobee_drake.reflex.controller import ReflexParams
from mobee_drake.robots.icub import IcubConfig
from mobee_drake.robots.zero_position import ZeroPositionConfig
from mobee_drake.yaml_io import LoadYamlFile, YamlFileError

ROBOT_MODELS = ("kinematic", "dynamic")
# "mobee2": MoBeE's forces move the robot (ch. 5); "reflex": MoBeE 1.0's position moves with the
# rewinding reflex (ch. 4.1).
CONTROLLERS = ("mobee2", "reflex")
CONTROL_MODALITIES = ("position", "velocity", "force")
OBJECT_ROLES = ("obstacle", "target", "ghost")


def _Zeros3() -> list[float]:
    return [0.0, 0.0, 0.0]


@dc.dataclass
class Box:
    size: list[float] = dc.field(default_factory=lambda: [0.1, 0.1, 0.1])


@dc.dataclass
class Sphere:
    radius: float = 0.05


@dc.dataclass
class Cylinder:
    radius: float = 0.05
    length: float = 0.1


@dc.dataclass
class SceneObject:
    """An object of the robot's world (ch. 2.3.2): MoBeE avoids obstacles and ignores the rest."""

    name: str = ""
    shape: Box | Sphere | Cylinder = dc.field(default_factory=Box)
    # Pose in world (the iCub's root frame unless the robot is moved): metres, degrees.
    position: list[float] = dc.field(default_factory=_Zeros3)
    rpy_deg: list[float] = dc.field(default_factory=_Zeros3)
    # "obstacle" (solid, repels the robot), "target" (shown, ignored by MoBeE, may be touched) or
    # "ghost" (shown translucent, ignored).
    role: str = "obstacle"


@dc.dataclass
class FixedAttractor:
    """One attractor for the whole run: the home posture with the given joints changed."""

    joints_deg: dict[str, float] = dc.field(default_factory=dict)


@dc.dataclass
class RandomAttractors:
    """Motor babbling (ch. 4.1.1): a new attractor drawn uniformly inside the joint limits."""

    # Seconds between two attractors.
    period: float = 5.0
    # The joints that babble (empty: every controlled joint); the others stay at home.
    joints: list[str] = dc.field(default_factory=list)
    # Draw from this fraction of each joint's range, centred in the range (1: the whole range).
    range_fraction: float = 0.8


@dc.dataclass
class SliderAttractor:
    """Interactive: one Meshcat slider per controlled joint moves the attractor (needs Meshcat)."""


@dc.dataclass
class ExploringAgent:
    """A curious agent on some joints (dissertation ch. 6-7), its states a hyper-lattice."""

    name: str = "agent"
    joints: list[str] = dc.field(default_factory=list)
    # The lattice's levels, in fractions of each joint's range (e.g. [0.25, 0.75]: a hypercube).
    levels: list[float] = dc.field(default_factory=lambda: [0.25, 0.75])
    # Instead of the lattice: a task-relevant roadmap saved by ``mobee-drake experiment trm`` (its
    # folder); its vertices become the states and its edges the actions (ch. 9.4.5).
    roadmap: str = ""
    # Actions to the k nearest states; 0: to the nearest equidistant ones.
    nearest: int = 0
    explorer: ExplorerConfig = dc.field(default_factory=ExplorerConfig)
    # Start from a model learned before: a checkpoint folder holding ``<name>.npz/json``.
    model: str = ""


@dc.dataclass
class ExploreAttractor:
    """The attractor is set by exploring agents (Alg. 8), each on its own joints."""

    agents: list[ExploringAgent] = dc.field(default_factory=list)
    timing: ActionTiming = dc.field(default_factory=ActionTiming)


@dc.dataclass
class StateActionAttractor:
    """The attractor and a marker's force are set by a client's state-actions, one at a time:
    transitions and dynamic reaches (ch. 8; see :mod:`mobee_drake.reaching.executor`)."""

    forcing: ReachForcing = dc.field(default_factory=ReachForcing)
    timing: ActionTiming = dc.field(default_factory=ActionTiming)


@dc.dataclass
class Companion:
    """Another robot in the same world with its own MoBeE (dissertation ch. 4.1.2, Fig. 4.5).

    Kinematic runs only. Each robot's MoBeE keeps its own body out of the other's way: to it, the
    other robot is an obstacle.
    """

    name: str = "katana"
    robot: ZeroPositionConfig | IcubConfig = dc.field(default_factory=ZeroPositionConfig)
    # Pose of the companion's root in world: metres, degrees.
    position: list[float] = dc.field(default_factory=_Zeros3)
    rpy_deg: list[float] = dc.field(default_factory=_Zeros3)
    mobee: MobeeParams = dc.field(default_factory=MobeeParams)
    attractor: RandomAttractors | FixedAttractor = dc.field(default_factory=RandomAttractors)


@dc.dataclass
class WorldEvent:
    """A scripted change of the world at a time: move an object or switch its role."""

    time: float = 0.0
    object: str = ""
    # New role, or "" to keep it.
    role: str = ""
    # New position, or empty to keep it.
    position: list[float] = dc.field(default_factory=list)


@dc.dataclass
class Visualization:
    # Show the run in Meshcat (a browser at the printed address).
    meshcat: bool = True
    # Save a replayable recording to this HTML file ("" for none).
    record: str = ""
    # The marker whose path is drawn as a trail ("" for none).
    trail_marker: str = "r_palm"
    # Draw the attractor as a translucent second robot.
    show_attractor: bool = True


@dc.dataclass
class Scenario:
    """Everything a run needs (see ``diagrams/`` for examples)."""

    # The iCub, or ``!ZeroPositionConfig {file: katana.xml}`` for a robot from a MoBeE XML file.
    robot: IcubConfig | ZeroPositionConfig = dc.field(default_factory=IcubConfig)
    objects: list[SceneObject] = dc.field(default_factory=list)
    # Other robots in the same world, each with its own MoBeE (kinematic runs only).
    companions: list[Companion] = dc.field(default_factory=list)
    mobee: MobeeParams = dc.field(default_factory=MobeeParams)
    # "kinematic": MoBeE's virtual dynamics (eq. 5.7) move the robot, no plant dynamics;
    # "dynamic": the MultibodyPlant is simulated and follows MoBeE through ``control``.
    robot_model: str = "kinematic"
    # With the dynamic robot: "position", "velocity" or "force" (ch. 5.2).
    control: str = "position"
    # What moves the (kinematic) robot: MoBeE 2.0's forces or MoBeE 1.0's reflex (CONTROLLERS).
    controller: str = "mobee2"
    reflex: ReflexParams = dc.field(default_factory=ReflexParams)
    # MoBeE's period (s): the kinematic robot's integration step, the dynamic robot's control rate.
    time_step: float = 0.01
    # The dynamic robot's plant step (s).
    plant_time_step: float = 0.001
    duration: float = 10.0
    attractor: (
        FixedAttractor
        | RandomAttractors
        | SliderAttractor
        | ExploreAttractor
        | StateActionAttractor
    ) = dc.field(default_factory=FixedAttractor)
    world_events: list[WorldEvent] = dc.field(default_factory=list)
    visualization: Visualization = dc.field(default_factory=Visualization)
    random_seed: int = 0


def _Check(condition: bool, source: str, message: str) -> None:
    if not condition:
        raise YamlFileError(f"{source}: {message}")


def ValidateScenario(scenario: Scenario, source: str = "scenario") -> None:
    """Checks the choices and numbers that the schema's types cannot."""
    _Check(
        scenario.robot_model in ROBOT_MODELS,
        source,
        f"robot_model must be one of {ROBOT_MODELS}, got '{scenario.robot_model}'",
    )
    _Check(
        scenario.controller in CONTROLLERS,
        source,
        f"controller must be one of {CONTROLLERS}, got '{scenario.controller}'",
    )
    _Check(
        scenario.controller == "mobee2" or scenario.robot_model == "kinematic",
        source,
        "the reflex controller (MoBeE 1.0) moves the kinematic robot only",
    )
    _Check(
        scenario.reflex.speed_deg > 0
        and scenario.reflex.history >= 2
        and scenario.reflex.tolerance_deg > 0,
        source,
        "reflex: speed_deg and tolerance_deg must be > 0 and history >= 2",
    )
    _Check(
        scenario.control in CONTROL_MODALITIES,
        source,
        f"control must be one of {CONTROL_MODALITIES}, got '{scenario.control}'",
    )
    for key in ("time_step", "plant_time_step", "duration"):
        value = getattr(scenario, key)
        _Check(value > 0, source, f"{key} must be > 0, got {value}")
    names = set()
    for obj in scenario.objects:
        _Check(
            bool(obj.name) and obj.name not in names,
            source,
            f"every object needs a unique name, got '{obj.name}'",
        )
        names.add(obj.name)
        _Check(
            obj.role in OBJECT_ROLES,
            source,
            f"object '{obj.name}': role must be one of {OBJECT_ROLES}, got '{obj.role}'",
        )
        _Check(
            len(obj.position) == 3 and len(obj.rpy_deg) == 3,
            source,
            f"object '{obj.name}': position and rpy_deg need three numbers",
        )
    for event in scenario.world_events:
        _Check(
            event.object in names,
            source,
            f"world event at {event.time} s names unknown object '{event.object}'",
        )
        _Check(
            event.role in OBJECT_ROLES + ("",),
            source,
            f"world event at {event.time} s: role must be one of {OBJECT_ROLES}, "
            f"got '{event.role}'",
        )
        _Check(
            len(event.position) in (0, 3),
            source,
            f"world event at {event.time} s: position needs three numbers",
        )
    for companion in scenario.companions:
        _Check(
            scenario.robot_model == "kinematic",
            source,
            f"companion '{companion.name}': other robots run in kinematic scenarios only",
        )
        _Check(
            bool(companion.name) and companion.name not in names,
            source,
            f"every companion needs a unique name, not an object's, got '{companion.name}'",
        )
        names.add(companion.name)
        _Check(
            len(companion.position) == 3 and len(companion.rpy_deg) == 3,
            source,
            f"companion '{companion.name}': position and rpy_deg need three numbers",
        )
    if isinstance(scenario.attractor, RandomAttractors):
        _Check(scenario.attractor.period > 0, source, "attractor period must be > 0")
        _Check(
            0 < scenario.attractor.range_fraction <= 1,
            source,
            "attractor range_fraction must be in (0, 1]",
        )


def LoadScenario(filename: str | pathlib.Path, overrides: str | None = None) -> Scenario:
    """Loads a scenario file, then applies ``overrides`` (YAML text with the same keys)."""
    scenario = LoadYamlFile(schema=Scenario, filename=filename)
    if overrides:
        from pydrake.common.yaml import yaml_load_typed

        try:
            scenario = yaml_load_typed(schema=Scenario, data=overrides, defaults=scenario)
        except (RuntimeError, ValueError) as e:
            raise YamlFileError(f"overrides '{overrides}': {e}") from e
    ValidateScenario(scenario, str(filename))
    return scenario
