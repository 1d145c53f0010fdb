"""The one seam between the station and its clients, and the one place their contract is declared.

A client (an exploring agent, the reach executor, motor babbling, sliders, your own) is a
callable ``AddToBuilder(parts: StationParts) -> ClientPorts | None`` handed to
:func:`~mobee_drake.station.builder.MakeMobeeStation` as ``prebuild_callback``. It is called once,
while the station's diagram is being built: it adds its systems to ``parts.builder``, connects
their inputs to the station's outputs named here, and returns a :class:`ClientPorts` declaring
everything it offers the station: the ports MoBeE reads (its attractor and, if the client sets
them, the forces on the markers and in configuration space) and the optional hooks below, each
the system that implements it. Returning None leaves MoBeE's attractor and forces as inputs of
the station's diagram, for a script to fix.

The hooks, each a Protocol here (the station reads them through ``Station.Hooks``, never by
searching the diagram; a system that implements one undeclared is named in a warning):

- ``outcome`` (:class:`ReportsOutcome`): what the client achieved, in the run's summary (several
  systems: each under its name);
- ``action_counters`` (:class:`CountsActions`): actions completed, after each of which a run
  with a checkpoint saves one;
- ``data_log`` (:class:`LogsData`): columns of the run's data log (one system or several);
- ``checkpointed`` (:class:`Checkpointed`): state that is more than numbers, in files of its own;
- ``world_events``: abstract output ports of ``list[WorldEvent]``, requests to edit the world
  (see :mod:`mobee_drake.station.world_events`).

The station checks the declaration when it is built (:func:`CheckClientPorts`): a hook whose
system lacks the method, or has it with other parameters, is refused there, naming the system,
the method, and the nearest name the system has. The station imports no client; a scenario's
client config classes implement the callable (see :mod:`mobee_drake.scenario`).
"""

import dataclasses as dc
import difflib
import inspect
import logging
import pathlib
from typing import Protocol

from pydrake.geometry import Meshcat, SceneGraph
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import (
    DiagramBuilder,
    InputPort,
    LeafSystem,
    OutputPort,
    PortDataType,
)

from mobee_drake.mobee.system import Mobee
from mobee_drake.world.live_world import LiveWorld

# A client's vector output port that the data log keeps (see LogsData).
DATA_LOG_PORT = "data_log"


@dc.dataclass
class StationParts:
    """What a client may connect to while the station is built."""

    builder: DiagramBuilder
    plant: MultibodyPlant
    scene_graph: SceneGraph
    mobee: Mobee
    world: LiveWorld
    # (q, v) of MoBeE's joints, whichever robot model runs.
    robot_state: OutputPort
    meshcat: Meshcat | None
    # The run's seed: a client draws its random numbers from generators seeded with it.
    random_seed: int
    # MoBeE's control period (s), the period of a client that acts as often.
    period: float = 0.01
    # Prefix of the client's system names (a companion robot's name and "_"; "" for the robot).
    prefix: str = ""
    # The joints the client owns (among composed behaviours, see station/composition.py;
    # empty: every joint of MoBeE's).
    joints: tuple[str, ...] = ()

    def OwnedJoints(self) -> list[str]:
        """The joints the client owns."""
        return list(self.joints) or list(self.mobee.joints)


class ReportsOutcome(Protocol):
    def Outcome(self, context) -> dict:
        """What the client achieved in ``context`` (its own), as JSON-able data."""


class CountsActions(Protocol):
    def CompletedActions(self, context) -> int:
        """How many actions it has completed, in ``context`` (its own)."""


class LogsData(Protocol):
    """A system whose vector output port :data:`DATA_LOG_PORT` the log keeps, a column an entry."""

    def DataLogColumns(self) -> list[tuple[str, str]]:
        """(name, unit) of each entry of the port."""


class Checkpointed(Protocol):
    """A system whose state is more than numbers: it writes and reads files of its own."""

    def WriteCheckpoint(self, context, folder: pathlib.Path) -> None:
        """Writes its state in ``context`` (its own) into ``folder``."""

    def ReadCheckpoint(self, context, folder: pathlib.Path) -> None:
        """Restores its state from ``folder`` into ``context`` (its own)."""


@dc.dataclass
class ClientPorts:
    """Everything a client offers the station (see the module): its system (a typed handle for
    scripts), the attractor q* of MoBeE's joints, optionally the forces on MoBeE's markers
    (eq. 5.10) and its configuration-space force (eq. 5.9), and its hooks."""

    system: LeafSystem
    attractor: OutputPort
    marker_forces: OutputPort | None = None
    config_force: OutputPort | None = None
    # One system, or several (behaviours composed: see mobee_drake.station.composition).
    outcome: ReportsOutcome | list[ReportsOutcome] | None = None
    action_counters: list[CountsActions] = dc.field(default_factory=list)
    data_log: LogsData | list[LogsData] | None = None
    checkpointed: list[Checkpointed] = dc.field(default_factory=list)
    world_events: list[OutputPort] = dc.field(default_factory=list)
    # Among composed behaviours: the outputs it offers the others and the inputs it needs from
    # them, by name (a client that runs alone needs nothing).
    offers: dict[str, OutputPort] = dc.field(default_factory=dict)
    needs: dict[str, InputPort] = dc.field(default_factory=dict)


class ClientContractError(TypeError):
    """A client whose declared hook its system does not implement as declared."""


# Each hook field of ClientPorts and the Protocol its systems implement.
HOOKS = {
    "outcome": ReportsOutcome,
    "action_counters": CountsActions,
    "data_log": LogsData,
    "checkpointed": Checkpointed,
}


def _Methods(protocol) -> dict:
    """The methods a hook's Protocol asks for, by name."""
    return {
        name: method
        for name, method in inspect.getmembers(protocol, inspect.isfunction)
        if not name.startswith("_")
    }


def _Name(system) -> str:
    return system.get_name() if isinstance(system, LeafSystem) else type(system).__name__


def _CheckImplements(system, protocol, hook: str) -> None:
    name = _Name(system)
    for method, declared in _Methods(protocol).items():
        found = getattr(system, method, None)
        if not callable(found):
            methods = [m for m in dir(system) if not m.startswith("_")]
            near = difflib.get_close_matches(method, methods, n=1, cutoff=0.5)
            raise ClientContractError(
                f"client system '{name}', declared as {hook}, has no method {method}"
                + (f" (it has {near[0]})" if near else "")
            )
        expected = [p for p in inspect.signature(declared).parameters if p != "self"]
        signature = inspect.signature(found)
        try:  # (called as the station calls it: extra optional parameters are fine)
            signature.bind(*expected)
        except TypeError:
            given = ", ".join(signature.parameters)
            raise ClientContractError(
                f"client system '{name}': {method}({given}) must take "
                f"({', '.join(expected)}) to be its {hook} hook"
            ) from None


def Declared(ports: ClientPorts, hook: str) -> list:
    """The systems (or ports) ``ports`` declares for ``hook``, a list whatever was given."""
    declared = getattr(ports, hook)
    if declared is None:
        return []
    return list(declared) if isinstance(declared, (list, tuple)) else [declared]


def CheckClientPorts(ports: ClientPorts) -> None:
    """Refuses a declaration whose hooks are not implemented as declared (see the module).

    Raises:
        ClientContractError: naming the system, the hook and the method.
    """
    for hook, protocol in HOOKS.items():
        for system in Declared(ports, hook):
            _CheckImplements(system, protocol, hook)
    for system in Declared(ports, "data_log"):
        _CheckDataLogPort(system)
    if ports.needs:
        raise ClientContractError(
            f"client system '{_Name(ports.system)}' needs ports ("
            + ", ".join(ports.needs)
            + ") that only other behaviours offer: run it among them (station/composition.py)"
        )
    for port in Declared(ports, "world_events"):
        if not isinstance(port, OutputPort):
            raise ClientContractError(f"world_events must list output ports, got {port!r}")
        if port.get_data_type() != PortDataType.kAbstractValued:
            raise ClientContractError(
                f"world_events port '{port.get_system().get_name()}.{port.get_name()}' must be "
                "abstract (a list of WorldEvent)"
            )


def _CheckDataLogPort(system) -> None:
    """A data_log system's port: a vector of one entry per column it names."""
    name = _Name(system)
    if not system.HasOutputPort(DATA_LOG_PORT):
        raise ClientContractError(
            f"client system '{name}', declared as data_log, has no output port '{DATA_LOG_PORT}'"
        )
    port, columns = system.GetOutputPort(DATA_LOG_PORT), system.DataLogColumns()
    if port.get_data_type() != PortDataType.kVectorValued or port.size() != len(columns):
        raise ClientContractError(
            f"client system '{name}': its '{DATA_LOG_PORT}' port must be a vector of "
            f"{len(columns)} entries, one per column of DataLogColumns()"
        )


def WarnOfUndeclaredHooks(systems, declared: list[ClientPorts | None]) -> None:
    """Logs a warning for each system that implements a hook no client declares it for (it is
    not read: see the module), so that a hook left out of a declaration is not silently lost."""
    offered = {
        (id(system), hook)
        for ports in declared
        if ports is not None
        for hook in HOOKS
        for system in Declared(ports, hook)
    }
    for system in systems:
        for hook, protocol in HOOKS.items():
            implements = all(callable(getattr(system, m, None)) for m in _Methods(protocol))
            if implements and (id(system), hook) not in offered:
                logging.getLogger(__name__).warning(
                    "system '%s' implements the %s hook, but no client declares it in its "
                    "ClientPorts: the station does not read it",
                    _Name(system),
                    hook,
                )


class ClientConfig(Protocol):
    """A scenario's client: a dataclass that the scenario's YAML names by its tag."""

    def Validate(self) -> None:
        """Raises ValueError for values no robot could take (checked when a scenario loads)."""

    def AddToBuilder(self, parts: StationParts) -> ClientPorts:
        """Adds the client's systems to the station being built (see the module)."""
