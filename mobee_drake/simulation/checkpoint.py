"""Checkpoints of a running simulation: what was learned and where the robot is, to resume.

A checkpoint is a folder: ``simulation.npz`` (the time and every discrete state of the diagram by
system name: the robot, the monitors, the attractor sources; the viewer's trail is optional, so a
run recorded with Meshcat can resume headless and back) and, when agents explore,
``<agent>.npz`` (the learned model: counts, rewards, tries, the state-action space) with
``<agent>.json`` (its configuration, its generator's state and the action in flight). The
folder is written next to its destination and renamed into place, so a crash never leaves a
half-written checkpoint, and loading it into the same scenario continues the run exactly where
it was saved.
"""

import dataclasses as dc
import json
import os
import pathlib
import shutil
import tempfile

import numpy as np

from mobee_drake.planning.explorers import ExplorerFromArrays, ExplorerToArrays
from mobee_drake.planning.supervisor import AgentRecord, ExplorationSupervisor
from mobee_drake.simulation.builder import Simulation


def _Supervisor(simulation: Simulation) -> ExplorationSupervisor | None:
    system = simulation.diagram.GetSubsystemByName("attractor")
    return system if isinstance(system, ExplorationSupervisor) else None


# Systems whose state only serves the viewer: a checkpoint may have them or not.
_VIEWER_SYSTEMS = ("trail",)


def _DiscreteStates(simulation: Simulation, context):
    """(key, value) of every discrete state group of the diagram, keyed by system name."""
    for system in simulation.diagram.GetSystems():
        sub_context = system.GetMyContextFromRoot(context)
        for i in range(sub_context.num_discrete_state_groups()):
            yield f"{system.get_name()}/{i}", sub_context.get_discrete_state(i).value()


def WriteFolderAtomically(folder: str | pathlib.Path, write) -> None:
    """Calls ``write(staging)`` on a new folder beside ``folder``, then renames it into place, so
    that ``folder`` is always either the old or the new whole."""
    folder = pathlib.Path(folder)
    folder.parent.mkdir(parents=True, exist_ok=True)
    staging = pathlib.Path(tempfile.mkdtemp(dir=folder.parent, prefix=f".{folder.name}-"))
    write(staging)
    if folder.exists():
        old = folder.with_name(f".{folder.name}-old")
        shutil.rmtree(old, ignore_errors=True)
        os.replace(folder, old)
        os.replace(staging, folder)
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.replace(staging, folder)


def SaveCheckpoint(simulation: Simulation, context, folder: str | pathlib.Path) -> None:
    """Saves the state of ``context`` (the diagram's root context) into ``folder``."""

    def Write(staging: pathlib.Path) -> None:
        np.savez(
            staging / "simulation.npz",
            time=context.get_time(),
            **{key: value for key, value in _DiscreteStates(simulation, context)},
        )
        supervisor = _Supervisor(simulation)
        if supervisor is not None:
            records = supervisor.Records(supervisor.GetMyContextFromRoot(context))
            for name, record in zip(supervisor.agent_names, records):
                arrays, data = ExplorerToArrays(record.explorer)
                np.savez(staging / f"{name}.npz", **arrays)
                data["record"] = {k: v for k, v in dc.asdict(record).items() if k != "explorer"}
                data["record"]["slow_since"] = float(record.slow_since)
                (staging / f"{name}.json").write_text(json.dumps(data, indent=1))

    WriteFolderAtomically(folder, Write)


def LoadCheckpoint(simulation: Simulation, context, folder: str | pathlib.Path) -> None:
    """Restores a checkpoint of the same scenario into ``context`` (the diagram's root context).

    Raises:
        ValueError: naming the folder, when it does not hold a checkpoint of this diagram.
    """
    folder = pathlib.Path(folder)
    if not (folder / "simulation.npz").is_file():
        raise ValueError(f"{folder}: not a checkpoint (no simulation.npz)")
    saved = np.load(folder / "simulation.npz")
    context.SetTime(float(saved["time"]))
    for key, current in _DiscreteStates(simulation, context):
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
        system = simulation.diagram.GetSubsystemByName(system_name)
        system.GetMyMutableContextFromRoot(context).get_mutable_discrete_state(
            int(group)
        ).SetFromVector(value)
    supervisor = _Supervisor(simulation)
    if supervisor is not None:
        records = []
        for name in supervisor.agent_names:
            data = json.loads((folder / f"{name}.json").read_text())
            explorer = ExplorerFromArrays(np.load(folder / f"{name}.npz"), data)
            records.append(AgentRecord(explorer=explorer, **data["record"]))
        supervisor.SetRecords(supervisor.GetMyMutableContextFromRoot(context), tuple(records))
