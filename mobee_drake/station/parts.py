"""The one seam between the station and its clients.

A client (an exploring agent, the reach executor, motor babbling, sliders, your own) is a
callable ``AddToBuilder(parts: StationParts) -> ClientPorts | None`` handed to
:func:`~mobee_drake.station.builder.MakeMobeeStation` as ``prebuild_callback``. It is called once,
while the station's diagram is being built: it adds its systems to ``parts.builder``, connects
their inputs to the station's outputs named here, and returns the ports the station should read
its attractor (and, if the client sets them, the marker forces) from. Returning None leaves
MoBeE's attractor and forces as inputs of the station's diagram, for a script to fix. The station
imports no client; a scenario's client config classes implement the callable
(see :mod:`mobee_drake.scenario`).
"""

import dataclasses as dc
from typing import Protocol

from pydrake.geometry import Meshcat, SceneGraph
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import DiagramBuilder, LeafSystem, OutputPort

from mobee_drake.mobee.system import Mobee
from mobee_drake.world.live_world import LiveWorld


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
    # Prefix of the client's system names (a companion robot's name and "_"; "" for the robot).
    prefix: str = ""


@dc.dataclass
class ClientPorts:
    """What a client offers the station: its system (a typed handle for scripts), the attractor
    q* of MoBeE's joints, and optionally the forces on MoBeE's markers (eq. 5.10) and its
    configuration-space force (eq. 5.9)."""

    system: LeafSystem
    attractor: OutputPort
    marker_forces: OutputPort | None = None
    config_force: OutputPort | None = None


class ClientConfig(Protocol):
    """A scenario's client: a dataclass that the scenario's YAML names by its tag."""

    def Validate(self) -> None:
        """Raises ValueError for values no robot could take (checked when a scenario loads)."""

    def AddToBuilder(self, parts: StationParts) -> ClientPorts:
        """Adds the client's systems to the station being built (see the module)."""
