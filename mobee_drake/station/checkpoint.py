"""Checkpoints of a running station: what was learned and where the robot is, to resume.

A checkpoint is a folder: ``simulation.npz`` holds the time and every discrete state of the
diagram by system name (the robot, the monitors, the world events applied, the clients' action
bookkeeping; the viewer's trail is optional, so a run recorded with Meshcat can resume headless
and back) and ``world.json`` the live world (its objects' roles, shapes and poses). A system whose
state is more than numbers (an exploring agent's learned model in abstract state) implements

- ``WriteCheckpoint(context, folder)``: writes it into ``folder`` (its own context), and
- ``ReadCheckpoint(context, folder)``: restores it,

and the checkpoint calls both for every such system of the diagram, knowing none of them. The
folder is written next to its destination and renamed into place, so a crash never leaves a
half-written checkpoint, and loading it into the same scenario continues the run exactly where
it was saved.
"""

import json
import pathlib
from typing import Protocol, runtime_checkable

import numpy as np

from mobee_drake.atomic_files import WriteFolderAtomically
from mobee_drake.station.builder import Station

# Systems whose state only serves the viewer: a checkpoint may have them or not.
_VIEWER_SYSTEMS = ("trail",)


@runtime_checkable
class CheckpointedSystem(Protocol):
    """A system whose state is more than numbers: it writes and reads files of its own."""

    def WriteCheckpoint(self, context, folder: pathlib.Path) -> None:
        """Writes its state in ``context`` (its own) into ``folder``."""

    def ReadCheckpoint(self, context, folder: pathlib.Path) -> None:
        """Restores its state from ``folder`` into ``context`` (its own)."""


def _DiscreteStates(station: Station, context):
    """(key, value) of every discrete state group of the diagram, keyed by system name."""
    for system in station.diagram.GetSystems():
        sub_context = system.GetMyContextFromRoot(context)
        for i in range(sub_context.num_discrete_state_groups()):
            yield f"{system.get_name()}/{i}", sub_context.get_discrete_state(i).value()


def _CheckpointedSystems(station: Station) -> list:
    """The systems that write and read checkpoint files of their own (see the module)."""
    return [s for s in station.diagram.GetSystems() if isinstance(s, CheckpointedSystem)]


def SaveCheckpoint(station: Station, context, folder: str | pathlib.Path) -> None:
    """Saves the state of ``context`` (the diagram's root context) into ``folder``."""

    def Write(staging: pathlib.Path) -> None:
        np.savez(
            staging / "simulation.npz",
            time=context.get_time(),
            **{key: value for key, value in _DiscreteStates(station, context)},
        )
        (staging / "world.json").write_text(json.dumps(station.world.Snapshot(context)))
        for system in _CheckpointedSystems(station):
            system.WriteCheckpoint(system.GetMyContextFromRoot(context), staging)

    WriteFolderAtomically(folder, Write)


def LoadCheckpoint(station: Station, context, folder: str | pathlib.Path) -> None:
    """Restores a checkpoint of the same scenario into ``context`` (the diagram's root context).

    Raises:
        ValueError: naming the folder, when it does not hold a checkpoint of this diagram.
    """
    folder = pathlib.Path(folder)
    if not (folder / "simulation.npz").is_file():
        raise ValueError(f"{folder}: not a checkpoint (no simulation.npz)")
    saved = np.load(folder / "simulation.npz")
    context.SetTime(float(saved["time"]))
    for key, current in _DiscreteStates(station, context):
        system_name, group = key.rsplit("/", 1)
        if key not in saved.files:
            if system_name in _VIEWER_SYSTEMS:
                continue
            raise ValueError(
                f"{folder}: no saved state for '{system_name}': a checkpoint of another scenario?"
            )
        value = saved[key]
        if value.shape != current.shape:
            raise ValueError(
                f"{folder}: the saved state of '{system_name}' has shape "
                f"{value.shape}, the scenario's {current.shape}"
            )
        system = station.diagram.GetSubsystemByName(system_name)
        system.GetMyMutableContextFromRoot(context).get_mutable_discrete_state(
            int(group)
        ).SetFromVector(value)
    station.world.Restore(context, json.loads((folder / "world.json").read_text()))
    for system in _CheckpointedSystems(station):
        system.ReadCheckpoint(system.GetMyMutableContextFromRoot(context), folder)
