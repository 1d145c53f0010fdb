"""Runs a built station: advances it with a progress bar, checkpoints it, reports."""

import contextlib
import dataclasses as dc
import math
import pathlib
import time

from pydrake.systems.analysis import InitializeParams, Simulator, SimulatorConfig
from pydrake.systems.framework import Context

from mobee_drake.atomic_files import WriteTextAtomically
from mobee_drake.owned_folders import OwnedFolder
from mobee_drake.progress import ProgressBar
from mobee_drake.station.builder import Station
from mobee_drake.station.checkpoint import (
    HasCheckpoint,
    LoadCheckpoint,
    LogSegments,
    SaveCheckpoint,
)
from mobee_drake.station.data_log import CheckpointedLog, WriteTable
from mobee_drake.station.outcome import RunOutcome, TargetLines
from mobee_drake.station.recording import CompactRecording
from mobee_drake.station.safety import CheckStart, SafetyReport
from mobee_drake.station.world_events import MakeSimulator


@dc.dataclass
class RunSummary:
    simulated_time: float
    wall_time: float
    safety: SafetyReport
    recording: str | None = None
    data_log: str | None = None
    # Where a resumed run started (s), and, for a run its checkpoint had finished, where it was.
    resumed_at: float | None = None
    finished_before: float | None = None
    # What the run achieved (see :mod:`mobee_drake.station.outcome`).
    outcome: dict = dc.field(default_factory=dict)

    def ToJson(self) -> dict:
        """The summary as strict-JSON data (a distance never reached is null)."""
        data = dc.asdict(self)
        data["realtime_factor"] = self.realtime_factor if self.wall_time > 0 else None
        return data

    @property
    def realtime_factor(self) -> float:
        return self.simulated_time / self.wall_time if self.wall_time > 0 else float("inf")

    def Format(self) -> str:
        if self.finished_before is not None:
            return (
                f"nothing to do: the checkpoint is at {self.finished_before:.2f} s, at or past "
                "the run's duration (give a longer --duration to go on)"
            )
        lines = [] if self.resumed_at is None else [f"resumed at {self.resumed_at:.2f} s"]
        lines += [
            f"simulated {self.simulated_time:.2f} s in {self.wall_time:.2f} s "
            f"({self.realtime_factor:.1f}x real time)"
        ]
        lines.append("closest approach of the robot's solids (m; '-' = never inside a field):")
        for name, distance in self.safety.closest_approach.items():
            lines.append(f"  {name:20s} {'-' if distance is None else f'{distance:+.4f}'}")
        lines.append(
            f"penetrations of solid geometry: {self.safety.penetrating_steps} control "
            f"periods, deepest {1000 * self.safety.deepest_penetration:.2f} mm; the safety "
            f"barrier acted in {self.safety.barrier_periods}"
        )
        for group, figures in self.outcome.items():
            lines.append(f"outcome, {group}:")
            shown = {"targets": TargetLines, "world_events": list}.get(group, _Lines)(figures)
            lines += [f"  {line}" for line in shown]
        if self.recording:
            lines.append(f"recording: {self.recording}")
        if self.data_log:
            lines.append(f"data log: {self.data_log}")
        return "\n".join(lines)


def _Lines(figures: dict, prefix: str = "") -> list[str]:
    lines = []
    for key, value in figures.items():
        if isinstance(value, dict):
            lines += _Lines(value, f"{prefix}{key}: ")
        else:
            shown = f"{value:.4g}" if isinstance(value, float) else value
            lines.append(f"{prefix}{key}: {shown}")
    return lines


def Advance(
    station: Station,
    simulator: Simulator,
    until: float,
    *,
    progress: bool = False,
    after_chunk=None,
) -> None:
    """Advances to ``until`` in at most 500 chunks; an infinite ``until`` advances a second at a
    time until Ctrl-C (a live run, served until the user ends it).

    ``after_chunk(context)``, if given, is called after each: the progress bar's and the
    checkpoints' occasions. World events are applied by the simulator's monitor (see
    :func:`~mobee_drake.station.world_events.MakeSimulator`).
    """
    context = simulator.get_mutable_context()
    while math.isinf(until):  # (Ended by the KeyboardInterrupt of Ctrl-C.)
        simulator.AdvanceTo(context.get_time() + 1.0)
        if after_chunk is not None:
            after_chunk(context)
    start = context.get_time()
    chunks = max(1, min(500, int(round((until - start) / station.config.time_step))))
    bar = None
    if progress:
        bar = ProgressBar(
            total=round(until - start, 3),
            desc="simulated",
            unit="s",
            leave=False,
            bar_format="{l_bar}{bar}| {n:.1f}/{total:.1f} s simulated [{elapsed}<{remaining}]",
        )
    for k in range(1, chunks + 1):
        before = context.get_time()
        simulator.AdvanceTo(start + (until - start) * k / chunks)
        if bar is not None:
            bar.update(round(context.get_time() - before, 3))
        if after_chunk is not None:
            after_chunk(context)
    if bar is not None:
        bar.close()


def CompletedActions(station: Station, context) -> int:
    """How many actions the station's clients have completed in the root ``context`` (0 when
    none counts them)."""
    counters = station.Hooks("action_counters")
    return sum(c.CompletedActions(c.GetMyContextFromRoot(context)) for c in counters)


def _StartRecording(station: Station, duration: float) -> None:
    """Records at the viewer's frame rate, or at the lower one that keeps ``duration`` within
    the most frames a recording may keep (frames between two recorded ones are dropped)."""
    shown = station.config.visualization
    rate = min(shown.frame_rate, shown.max_recorded_frames / max(duration, 1e-9))
    station.meshcat.StartRecording(frames_per_second=rate, set_visualizations_while_recording=True)


class _CheckpointSaver:
    """A run's checkpoints in one folder: resumed from at the start, saved whenever a client has
    completed an action and at the end (the data log, if kept with them, saved alongside)."""

    def __init__(
        self,
        station: Station,
        folder: str,
        configuration: str,
        log: CheckpointedLog | None,
    ):
        self._station = station
        self._folder = folder
        self._configuration = configuration
        self._log = log
        self._saved_actions = 0

    def Resume(self, context: Context) -> float | None:
        """Loads the folder's checkpoint into ``context``, if it has one; returns its time."""
        if not HasCheckpoint(self._folder):
            return None
        LoadCheckpoint(self._station, context, self._folder, self._configuration)
        resumed = context.get_time()
        if self._log is not None:
            self._log.Resume(LogSegments(self._folder), resumed)
        return resumed

    def Start(self, context: Context) -> None:
        """Counts the actions completed when the simulation starts (none need saving)."""
        self._saved_actions = CompletedActions(self._station, context)

    def Save(self, context: Context) -> None:
        """Saves the checkpoint of ``context`` (and the log's new segments)."""
        segments = self._log.Save(context) if self._log is not None else 0
        SaveCheckpoint(self._station, context, self._folder, self._configuration, segments)

    def AfterChunk(self, context: Context) -> None:
        """Saves when a client has completed an action since the last save."""
        done = CompletedActions(self._station, context)
        if done > self._saved_actions:
            self.Save(context)
            self._saved_actions = done


def RunStation(
    station: Station,
    duration: float,
    *,
    record: str | None = None,
    simulator_config: SimulatorConfig | None = None,
    realtime_rate: float | None = None,
    progress: bool = False,
    checkpoint: str | None = None,
    configuration: str = "",
    data_log: str | None = None,
    on_start=None,
) -> RunSummary:
    """Runs ``station`` until ``duration`` (``math.inf``: until Ctrl-C, for a live view, which
    cannot be recorded) with Drake's ``simulator_config`` (``realtime_rate``,
    if given, overrides its target real-time rate); with ``record`` saves its Meshcat recording
    (HTML; the station must have been built with Meshcat) at the viewer's frame rate, or at the
    lower rate that keeps it within ``max_recorded_frames``; with ``data_log`` (a Parquet file)
    writes the station's data log (see :mod:`mobee_drake.station.data_log`; with a checkpoint
    it is saved with every checkpoint, and a resumed run's log is the uninterrupted run's).
    ``on_start()``, if given, is called when the simulation starts.

    With ``checkpoint`` (a folder: new, empty or one of our checkpoints, and held by this run
    alone; see :mod:`mobee_drake.owned_folders`), a run resumes from the checkpoint there if
    there is one (written with the same ``configuration``, see
    :func:`~mobee_drake.station.checkpoint.LoadCheckpoint`), and saves one whenever a client has
    completed an action (and at the end), so that an interrupted run loses at most the actions in
    flight. A run whose checkpoint is at or past ``duration`` has nothing left to do: it
    simulates nothing and says so (``RunSummary.finished_before``).
    """
    if record and math.isinf(duration):
        raise ValueError("a run served until Ctrl-C cannot be recorded; give it a duration")
    with OwnedFolder(checkpoint, "checkpoint") if checkpoint else contextlib.nullcontext():
        simulator = MakeSimulator(station, simulator_config)
        if realtime_rate is not None:
            simulator.set_target_realtime_rate(realtime_rate)
        context = simulator.get_mutable_context()
        # With checkpoints the log is saved with them (and resumed from them).
        log = None
        if checkpoint and data_log and station.data_log is not None:
            log = CheckpointedLog(station.data_log, checkpoint)
        saver = _CheckpointSaver(station, checkpoint, configuration, log) if checkpoint else None
        resumed = saver.Resume(context) if saver is not None else None
        if resumed is not None and resumed >= duration:
            report = station.monitor.Report(station.monitor.GetMyContextFromRoot(context))
            return RunSummary(0.0, 0.0, report, finished_before=resumed)
        if resumed is None:
            CheckStart(station.diagram, context)
        if record:  # (Before the initialization's drawing, which the recording keeps.)
            _StartRecording(station, duration - (resumed or 0.0))
        start = time.perf_counter()
        # A live run served until Ctrl-C ends normally on it, whenever it comes.
        serving = math.isinf(duration)
        with contextlib.suppress(KeyboardInterrupt) if serving else contextlib.nullcontext():
            simulator.Initialize(
                InitializeParams(suppress_initialization_events=resumed is not None)
            )
            if saver is not None:
                saver.Start(context)
            if on_start is not None:
                on_start()
            start = time.perf_counter()
            after_chunk = saver.AfterChunk if saver is not None else None
            Advance(station, simulator, duration, progress=progress, after_chunk=after_chunk)
        if saver is not None:
            saver.Save(context)
        wall = time.perf_counter() - start
        report = station.monitor.Report(station.monitor.GetMyContextFromRoot(context))
        return RunSummary(
            simulated_time=context.get_time() - (resumed or 0.0),
            wall_time=wall,
            safety=report,
            recording=_SaveRecording(station, record) if record else None,
            data_log=_WriteLog(station, context, data_log, log) if data_log else None,
            resumed_at=resumed,
            outcome=RunOutcome(station, context),
        )


def _SaveRecording(station: Station, record: str) -> str:
    """Stops the station's Meshcat recording and writes it to ``record`` (HTML); its path."""
    station.meshcat.StopRecording()
    station.meshcat.PublishRecording()
    path = pathlib.Path(record)
    WriteTextAtomically(path, CompactRecording(station.meshcat.StaticHtml()))
    return str(path.resolve())


def _WriteLog(station: Station, context, data_log: str, log: CheckpointedLog | None) -> str | None:
    """Writes the run's data log (the checkpoints' segments first, if any) to ``data_log``;
    its path (None: the station keeps no log)."""
    if station.data_log is None:
        return None
    table = log.Table(context) if log is not None else station.data_log.Table(context)
    WriteTable(data_log, table)
    return str(pathlib.Path(data_log).resolve())
