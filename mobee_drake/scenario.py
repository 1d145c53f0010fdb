"""Scenarios: what to simulate, read from YAML, built into a station with its client, and run.

This is the composition root: the only module that knows the station and every client. A
scenario (``diagrams/*.yaml``) is a :class:`~mobee_drake.station.config.StationConfig` (the robot,
its world, MoBeE, what moves the robot, what to show, the random seed) plus the client that sets
MoBeE's attractor (one tag of ``Client``) and the duration. :func:`LoadScenario` reads one (a
file, or the name of a shipped scenario); errors name the file, the key and, where YAML gives it,
the line. :func:`BuildScenario` builds it; :func:`RunScenario` runs it.

A client of your own is a dataclass with ``Validate()`` and ``AddToBuilder(parts)`` (see
:mod:`mobee_drake.station.parts`): build it with
``MakeMobeeStation(config, prebuild_callback=client.AddToBuilder)``, no scenario file needed.
"""

import dataclasses as dc
import math
import pathlib

import numpy as np
from pydrake.common.yaml import yaml_dump_typed
from pydrake.geometry import Meshcat
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator, SimulatorConfig
from pydrake.systems.primitives import ConstantVectorSource
import yaml

from mobee_drake import __version__
from mobee_drake.behaviours.pointing import PointAt
from mobee_drake.planning.supervisor import ExploreAttractor
from mobee_drake.resources import ResolveScenarioFile, UnknownScenario
from mobee_drake.robots.model_file import ModelFileConfig
from mobee_drake.station.attractors import FixedAttractor, RandomAttractors, SliderAttractor
from mobee_drake.station.builder import MakeMobeeStation, Station
from mobee_drake.station.composition import Behaviour, ComposeBehaviours
from mobee_drake.station.config import DataLog, StationConfig, StationConfigErrors, Visualization
from mobee_drake.station.executor import StateActionAttractor
from mobee_drake.station.parts import ClientPorts, StationParts
from mobee_drake.station.runner import RunStation, RunSummary
from mobee_drake.station.viewer import RecordingMeshcat
from mobee_drake.world.live_world import MakeShape
from mobee_drake.world.objects import Box, Cylinder, Mesh, SceneObject
from mobee_drake.yaml_io import (
    CheckYamlStructure,
    DidYouMean,
    InvalidYaml,
    LoadYamlFile,
    LoadYamlOverride,
    TaggedData,
    YamlFileError,
)

# The longest run a scenario may ask for (s; our choice: about 116 simulated days, far beyond any
# experiment of the sources, and short enough that a typo like 1e308 is caught, not simulated).
MAX_DURATION = 1e7
# The clients a scenario file can name, by their YAML tags.
# A client that runs among several, on joints of its own.
BehaviourClient = (
    FixedAttractor
    | RandomAttractors
    | SliderAttractor
    | ExploreAttractor
    | StateActionAttractor
    | PointAt
)


@dc.dataclass
class BehaviourConfig:
    """A client on joints (and markers) of its own, beside others (ch. 9.4.2)."""

    name: str = ""
    # MoBeE's joints it moves; no other behaviour may claim them.
    joints: list[str] = dc.field(default_factory=list)
    # The markers it pushes, if any; no other behaviour may push them.
    markers: list[str] = dc.field(default_factory=list)
    client: BehaviourClient = dc.field(default_factory=FixedAttractor)


@dc.dataclass
class Behaviours:
    """Several clients on one robot at once (``mobee_drake.station.composition``): e.g. gaze on
    the neck and a reach planner on the arm. Joints no behaviour owns stay at home."""

    behaviours: list[BehaviourConfig] = dc.field(default_factory=list)

    def Validate(self) -> None:
        if not self.behaviours:
            raise ValueError("Behaviours: list at least one behaviour")
        for b in self.behaviours:
            if not b.name or not b.joints:
                raise ValueError(f"Behaviours: each needs a name and joints, got {b.name!r}")
            try:
                b.client.Validate()
            except ValueError as e:
                raise ValueError(f"behaviour '{b.name}': {e}") from None

    def AddToBuilder(self, parts: StationParts) -> ClientPorts:
        return ComposeBehaviours(
            parts,
            [
                Behaviour(b.name, tuple(b.joints), b.client.AddToBuilder, tuple(b.markers))
                for b in self.behaviours
            ],
        )


Client = BehaviourClient | Behaviours


@dc.dataclass
class Scenario(StationConfig):
    """Everything a run needs (see ``diagrams/`` for examples)."""

    # What sets MoBeE's attractor: one of the Client tags.
    attractor: Client = dc.field(default_factory=FixedAttractor)
    # Seconds to simulate.
    duration: float = 10.0
    # Drake's simulator settings (the target real-time rate; the station's systems are discrete,
    # so the integrator's settings do not matter).
    simulator_config: SimulatorConfig = dc.field(default_factory=SimulatorConfig)


# The slowest real-time rate a run may ask for (a simulated second in 100 s; slower runs would
# go for days without a line of output).
MIN_REALTIME_RATE = 0.01


def ScenarioErrors(scenario: Scenario) -> list[str]:
    """What is wrong with ``scenario`` that its types cannot say (empty: nothing)."""
    errors = StationConfigErrors(scenario)
    if not (math.isfinite(scenario.duration) and 0 < scenario.duration <= MAX_DURATION):
        errors.append(f"duration must be > 0 and <= {MAX_DURATION:g} s, got {scenario.duration}")
    try:  # Drake's own check of its strings (the integration scheme)
        ApplySimulatorConfig(scenario.simulator_config, Simulator(ConstantVectorSource([0.0])))
    except (RuntimeError, ValueError) as error:
        errors.append(f"simulator_config: {error}")
    simulator = scenario.simulator_config
    for name in ("max_step_size", "accuracy"):
        value = getattr(simulator, name)
        if not (math.isfinite(value) and value > 0):
            errors.append(f"simulator_config {name} must be finite and > 0, got {value}")
    rate = scenario.simulator_config.target_realtime_rate
    if not (rate == 0 or (math.isfinite(rate) and rate >= MIN_REALTIME_RATE)):
        errors.append(
            f"simulator_config target_realtime_rate must be 0 (as fast as it goes) or >= "
            f"{MIN_REALTIME_RATE:g}, got {rate}"
        )
    try:
        scenario.attractor.Validate()
    except ValueError as e:
        errors.append(str(e))
    return errors


# Beyond these a value is more likely a unit mistake (centimetres, millimetres, radians) than
# meant: the largest object size (m) and distance from the world's origin (m).
DOUBTFUL_SIZE = 3.0
DOUBTFUL_DISTANCE = 5.0


def _Sizes(shape) -> list[tuple[str, float, float]]:
    """(what, value in m, the largest plausible value) of an object's shape."""
    if isinstance(shape, Box):
        return [("size", max(shape.size), DOUBTFUL_SIZE)]
    if isinstance(shape, Mesh):
        hull = MakeShape(shape).GetConvexHull()
        points = np.array([hull.vertex(i) for i in range(hull.num_vertices())])
        return [("extent", float((points.max(axis=0) - points.min(axis=0)).max()), DOUBTFUL_SIZE)]
    sizes = [("radius", shape.radius, DOUBTFUL_SIZE / 2)]
    if isinstance(shape, Cylinder):
        sizes.append(("length", shape.length, DOUBTFUL_SIZE))
    return sizes


def _ObjectDoubts(scenario: Scenario) -> list[str]:
    doubts = []
    for o in scenario.objects:
        for what, value, limit in _Sizes(o.shape):
            if value > limit:
                doubts.append(
                    f"objects '{o.name}': {what} {value:g} m; sizes are in metres ({value:g} cm "
                    f"would be {value / 100:g})"
                    + ("; a mesh's scale takes its units to metres" if what == "extent" else "")
                )
        distance = float(np.linalg.norm(o.position))
        if distance > DOUBTFUL_DISTANCE:
            doubts.append(
                f"objects '{o.name}': {distance:g} m from the world's origin, out of any reach; "
                "positions are in metres"
            )
    return doubts


def ScenarioDoubts(scenario: Scenario) -> list[str]:
    """What in ``scenario`` looks like a mistake though it is allowed: sizes or distances far
    beyond a robot's world (a unit slip), world events after the run's end (they never happen),
    joint attractors below pi with fractions (radians in a field of degrees)."""
    doubts = _ObjectDoubts(scenario)
    for event in scenario.world_events:
        if event.time >= scenario.duration:
            doubts.append(
                f"world_events: '{event.object}' at {event.time:g} s, at or after the run's end "
                f"({scenario.duration:g} s): it never happens"
            )
    for name, value in getattr(scenario.attractor, "joints_deg", {}).items():
        if 0 < abs(value) <= math.pi and value != round(value):
            doubts.append(
                f"attractor joints_deg: {name}: {value:g} looks like radians; the angles are in "
                f"degrees ({value:g} rad would be {math.degrees(value):.1f})"
            )
    return doubts


def ValidateScenario(scenario: Scenario, source: str = "scenario") -> None:
    """Raises YamlFileError naming ``source`` and the first thing wrong with ``scenario``."""
    errors = ScenarioErrors(scenario)
    if errors:
        raise YamlFileError(f"{source}: {errors[0]}")


def LoadScenario(
    filename: str | pathlib.Path,
    overrides: str | list[str] | None = None,
    *,
    scenario_name: str | None = None,
) -> Scenario:
    """Loads a scenario (a file, or a shipped scenario's name; with ``scenario_name``, that
    top-level key of the file), then applies ``overrides``: YAML texts with the same keys, in
    order (e.g. ``{mover: !Dynamic {control: force}}``)."""
    filename = ResolveScenarioFile(filename)
    if filename.parent == pathlib.Path(".") and not filename.exists():
        raise YamlFileError(UnknownScenario(filename))
    scenario = LoadYamlFile(schema=Scenario, filename=filename, child_name=scenario_name)
    scenario = _FilesBeside(scenario, filename.resolve().parent)
    ValidateScenario(scenario, str(filename))
    for text in [overrides] if isinstance(overrides, str) else overrides or []:
        source = f"overrides '{_OneLine(text)}'"
        try:
            CheckYamlStructure(text, source)  # (alias bombs, absurd nesting)
            if not isinstance(TaggedData(text), dict):
                raise YamlFileError(
                    f"{source}: not a YAML mapping; give one, e.g. '{{duration: 5}}'"
                )
            scenario = LoadYamlOverride(schema=Scenario, text=text, defaults=scenario)
        except YamlFileError:
            raise
        except yaml.YAMLError as e:
            raise YamlFileError(InvalidYaml(source, e)) from None
        except (RuntimeError, ValueError, TypeError) as e:
            raise YamlFileError(f"{source}: {DidYouMean(Scenario, str(e))}") from e
        ValidateScenario(scenario, source)
    return scenario


def _FilesBeside(scenario: Scenario, folder: pathlib.Path) -> Scenario:
    """``scenario`` with the relative paths of its model files (a robot's model and overlay, an
    object's mesh) made absolute in ``folder``, the scenario file's."""

    def Beside(name: str) -> str:
        relative = name and "://" not in name and not pathlib.Path(name).is_absolute()
        return str(folder / name) if relative else name

    def Robot(robot):
        if not isinstance(robot, ModelFileConfig):
            return robot
        return dc.replace(robot, file=Beside(robot.file), overlay=Beside(robot.overlay))

    def Object(o: SceneObject) -> SceneObject:
        if not isinstance(o.shape, Mesh):
            return o
        return dc.replace(o, shape=dc.replace(o.shape, file=Beside(o.shape.file)))

    return dc.replace(
        scenario,
        robot=Robot(scenario.robot),
        companions=[dc.replace(c, robot=Robot(c.robot)) for c in scenario.companions],
        objects=[Object(o) for o in scenario.objects],
    )


def _OneLine(text: str, limit: int = 80) -> str:
    """``text`` on one line, cut short: for messages that quote it."""
    text = text.strip().replace("\n", "\\n")
    return text if len(text) <= limit else text[:limit] + "..."


def ResumableConfiguration(scenario: Scenario) -> str:
    """The configuration a checkpoint of ``scenario`` records and must match to be resumed:
    the package's version and the scenario, but for what may change between a run and its
    resumption (the duration, the viewer, the data log, the simulator's pacing)."""
    kept = dc.replace(
        scenario,
        duration=Scenario.duration,
        visualization=Visualization(),
        data_log=DataLog(),
        simulator_config=SimulatorConfig(),
    )
    return f"mobee_drake_version: {__version__}\n" + yaml_dump_typed(kept)


def BuildScenario(scenario: Scenario, meshcat: Meshcat | None = None) -> Station:
    """The station of ``scenario`` with its client (``station.client``); with ``meshcat``, also
    the viewer. A run longer than its data log's ``max_rows`` periods is logged at the longer
    period that keeps it within them (its memory bounded)."""
    log = scenario.data_log
    period = max(log.period or scenario.time_step, scenario.duration / log.max_rows)
    if period != (log.period or scenario.time_step):
        scenario = dc.replace(scenario, data_log=dc.replace(log, period=period))
    return MakeMobeeStation(scenario, meshcat, prebuild_callback=scenario.attractor.AddToBuilder)


def RunScenario(
    scenario: Scenario,
    *,
    meshcat: Meshcat | None = None,
    record: str | None = None,
    realtime_rate: float | None = None,
    progress: bool = False,
    checkpoint: str | None = None,
    data_log: str | None = None,
) -> RunSummary:
    """Builds and runs ``scenario`` for its duration (see
    :func:`~mobee_drake.station.runner.RunStation`); ``record`` (an HTML file) records the run in
    ``meshcat``, or in a Meshcat of its own; ``data_log`` (a Parquet file) receives its log."""
    if record and meshcat is None:
        meshcat = RecordingMeshcat()
    return RunStation(
        BuildScenario(scenario, meshcat),
        scenario.duration,
        record=record,
        simulator_config=scenario.simulator_config,
        realtime_rate=realtime_rate,
        progress=progress,
        checkpoint=checkpoint,
        configuration=ResumableConfiguration(scenario),
        data_log=data_log,
    )
