"""Checkpoints of a running station: what was learned and where the robot is, to resume.

A checkpoint is a folder: ``simulation.npz`` holds the time and every discrete state of the
diagram by system name (the robot, the monitors, the world events applied, the clients' action
bookkeeping; the viewer's trail is optional, so a run recorded with Meshcat can resume headless
and back) and ``world.json`` the live world (its objects' roles, shapes and poses). A system whose
state is more than numbers (an exploring agent's learned model in abstract state) implements

- ``WriteCheckpoint(context, folder)``: writes it into ``folder`` (its own context), and
- ``ReadCheckpoint(context, folder)``: restores it,

and its client declares it among its ``checkpointed`` systems (:mod:`mobee_drake.station.parts`);
the checkpoint calls both for every declared one, knowing none of them.
``configuration.yaml`` records the configuration the run was started with; a checkpoint is only
resumed under the same one. A checkpoint folder keeps *generations* of these files
(:func:`~mobee_drake.atomic_files.WriteGeneration`), so a kill at any moment leaves a complete
checkpoint, and loading the newest into the same scenario continues the run exactly where it was
saved.
"""

import json
import pathlib

import numpy as np

from mobee_drake.array_files import DAMAGED, WriteArrays
from mobee_drake.atomic_files import CurrentGeneration, StrictJson, WriteGeneration
from mobee_drake.station.builder import Station
from mobee_drake.yaml_io import YamlDifferences


class CheckpointError(ValueError):
    """A checkpoint that cannot be resumed here; the message names its folder and why."""


# The configuration a checkpoint was written with.
CONFIGURATION = "configuration.yaml"
# How many of the data log's segments a generation covers.
LOG_SEGMENTS = "log_segments.txt"
# The wall time (s) the run had taken when the generation was saved, over its resumptions.
WALL_SECONDS = "wall_seconds.txt"
# Systems whose state only serves the viewer: a checkpoint may have them or not.
_VIEWER_SYSTEMS = ("trail",)


def _DiscreteStates(station: Station, context):
    """(key, value) of every discrete state group of the diagram, keyed by system name."""
    for system in station.diagram.GetSystems():
        sub_context = system.GetMyContextFromRoot(context)
        for i in range(sub_context.num_discrete_state_groups()):
            yield f"{system.get_name()}/{i}", sub_context.get_discrete_state(i).value()


def WriteCheckpointFiles(station: Station, context, folder: pathlib.Path) -> None:
    """Writes the state of ``context`` (the diagram's root context) into the existing
    ``folder``: the files of one checkpoint (see the module)."""
    WriteArrays(
        folder / "simulation.npz",
        time=context.get_time(),
        **{key: value for key, value in _DiscreteStates(station, context)},
    )
    (folder / "world.json").write_text(StrictJson(station.world.Snapshot(context)))
    for system in station.Hooks("checkpointed"):
        system.WriteCheckpoint(system.GetMyContextFromRoot(context), folder)


def ReadCheckpointFiles(station: Station, context, folder: pathlib.Path) -> None:
    """Restores the files :func:`WriteCheckpointFiles` wrote into ``context``.

    Raises:
        CheckpointError: naming the folder (and file), when it does not hold a checkpoint of this
            diagram, or a file of it is missing, truncated or holds NaN.
    """
    folder = pathlib.Path(folder)
    if not (folder / "simulation.npz").is_file():
        raise CheckpointError(f"{folder}: not a checkpoint (no simulation.npz)")
    try:
        _ReadFiles(station, context, folder)
    except CheckpointError:
        raise
    except (*DAMAGED, KeyError) as error:
        kind = type(error).__qualname__
        if type(error).__module__ != "builtins":  # (zlib.error, zipfile.BadZipFile)
            kind = f"{type(error).__module__}.{kind}"
        raise CheckpointError(f"{folder}: a damaged checkpoint ({kind}: {error})") from None


def _CheckNoNan(path: pathlib.Path) -> dict:
    """The arrays of ``path`` (an .npz), CheckpointError naming the first that holds NaN."""
    arrays = dict(np.load(path))
    for key, value in arrays.items():
        if np.issubdtype(value.dtype, np.floating) and np.isnan(value).any():
            raise CheckpointError(f"{path}: '{key}' holds NaN")
    return arrays


def _ReadFiles(station: Station, context, folder: pathlib.Path) -> None:
    saved = _CheckNoNan(folder / "simulation.npz")
    for other in sorted(folder.glob("*.npz")):  # (the agents' models too)
        _CheckNoNan(other)
    time = float(saved["time"])
    if not (np.isfinite(time) and time >= 0):
        raise CheckpointError(f"{folder / 'simulation.npz'}: holds the time {time} s, not >= 0")
    context.SetTime(time)
    for key, current in _DiscreteStates(station, context):
        system_name, group = key.rsplit("/", 1)
        if key not in saved:
            if system_name in _VIEWER_SYSTEMS:
                continue
            raise CheckpointError(
                f"{folder}: no saved state for '{system_name}': a checkpoint of another scenario?"
            )
        value = saved[key]
        if value.shape != current.shape:
            raise CheckpointError(
                f"{folder}: the saved state of '{system_name}' has shape "
                f"{value.shape}, the scenario's {current.shape}"
            )
        system = station.diagram.GetSubsystemByName(system_name)
        system.GetMyMutableContextFromRoot(context).get_mutable_discrete_state(
            int(group)
        ).SetFromVector(value)
    station.world.Restore(context, json.loads((folder / "world.json").read_text()))
    for system in station.Hooks("checkpointed"):
        system.ReadCheckpoint(system.GetMyMutableContextFromRoot(context), folder)


def SaveCheckpoint(
    station: Station,
    context,
    folder: str | pathlib.Path,
    configuration: str = "",
    log_segments: int = 0,
    wall_seconds: float | None = None,
) -> None:
    """Saves the state of ``context`` (the diagram's root context) as the newest generation of
    ``folder`` (see :func:`~mobee_drake.atomic_files.WriteGeneration`), with the
    ``configuration`` it was run with (YAML text; see :func:`LoadCheckpoint`), how many of
    the data log's segments it covers (:class:`~mobee_drake.station.data_log.CheckpointedLog`)
    and, if given, the wall time the run has taken so far (s; :func:`SavedWallSeconds`)."""

    def Write(staging: pathlib.Path) -> None:
        WriteCheckpointFiles(station, context, staging)
        (staging / CONFIGURATION).write_text(configuration)
        (staging / LOG_SEGMENTS).write_text(str(log_segments))
        if wall_seconds is not None:
            (staging / WALL_SECONDS).write_text(repr(float(wall_seconds)))

    WriteGeneration(folder, Write)


def HasCheckpoint(folder: str | pathlib.Path) -> bool:
    return CurrentGeneration(folder) is not None


def LoadCheckpoint(
    station: Station, context, folder: str | pathlib.Path, configuration: str = ""
) -> None:
    """Restores the newest checkpoint in ``folder`` into ``context`` (the diagram's root
    context).

    Raises:
        CheckpointError: naming the folder, when it holds no checkpoint, one of another diagram, or
            one written with another ``configuration`` (naming what differs).
    """
    generation = CurrentGeneration(folder)
    if generation is None:
        raise CheckpointError(f"{folder}: holds no checkpoint")
    if not (generation / CONFIGURATION).is_file():
        raise CheckpointError(
            f"{generation}: a damaged checkpoint (no {CONFIGURATION}); delete this generation "
            "to resume from the one before it, or start afresh in another folder"
        )
    saved = (generation / CONFIGURATION).read_text()
    if saved != configuration:
        differences = YamlDifferences(saved or "{}", configuration or "{}")
        raise CheckpointError(
            f"{folder}: the checkpoint was written with another configuration ("
            + "; ".join(differences[:4])
            + (f"; and {len(differences) - 4} more" if len(differences) > 4 else "")
            + "); resume with the same one, or start afresh in another folder"
        )
    ReadCheckpointFiles(station, context, generation)


def LogSegments(folder: str | pathlib.Path) -> int:
    """How many data-log segments the newest checkpoint in ``folder`` covers (0: none saved)."""
    return _SavedNumber(folder, LOG_SEGMENTS, int, "a count")


def SavedWallSeconds(folder: str | pathlib.Path) -> float:
    """The wall time (s) the run had taken when the newest checkpoint in ``folder`` was saved
    (0: none saved, or one from before it was kept)."""
    return _SavedNumber(folder, WALL_SECONDS, float, "a number of seconds")


def _SavedNumber(folder: str | pathlib.Path, name: str, parse, what: str):
    """The number in file ``name`` of the newest checkpoint in ``folder`` (0 if there is
    none); CheckpointError naming the file if it holds no ``what``."""
    generation = CurrentGeneration(folder)
    path = None if generation is None else generation / name
    if path is None or not path.is_file():
        return parse("0")
    try:
        return parse(path.read_text())
    except ValueError:
        raise CheckpointError(f"{path}: a damaged checkpoint (not {what})") from None
