"""Runs a scenario: builds it, advances it with a progress bar, applies world events, reports."""

import dataclasses as dc
import os
import pathlib
import time

from pydrake.geometry import Meshcat
from pydrake.systems.analysis import InitializeParams, Simulator

from mobee_drake.planning.supervisor import ExplorationSupervisor
from mobee_drake.simulation.builder import BuildSimulation, Simulation
from mobee_drake.simulation.checkpoint import LoadCheckpoint, SaveCheckpoint
from mobee_drake.simulation.safety import SafetyReport
from mobee_drake.simulation.scenario import Scenario
from mobee_drake.simulation.world import SupervisorEventPorts


@dc.dataclass
class RunSummary:
    simulated_time: float
    wall_time: float
    safety: SafetyReport
    recording: str | None = None

    @property
    def realtime_factor(self) -> float:
        return self.simulated_time / self.wall_time if self.wall_time > 0 else float("inf")

    def Format(self) -> str:
        lines = [
            f"simulated {self.simulated_time:.2f} s in {self.wall_time:.2f} s "
            f"({self.realtime_factor:.1f}x real time)"
        ]
        lines.append("closest approach of the robot's solids (m; '-' = never inside a field):")
        for name, distance in self.safety.closest_approach.items():
            lines.append(f"  {name:20s} {'-' if distance is None else f'{distance:+.4f}'}")
        lines.append(
            f"penetrations of solid geometry: {self.safety.penetrating_steps} control "
            f"periods, deepest {1000 * self.safety.deepest_penetration:.2f} mm"
        )
        if self.recording:
            lines.append(f"recording: {self.recording}")
        return "\n".join(lines)


def _WriteAtomically(path: pathlib.Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_suffix(path.suffix + ".tmp")
    temporary.write_text(text)
    os.replace(temporary, path)


def Advance(
    simulation: Simulation,
    simulator: Simulator,
    until: float,
    *,
    progress: bool = False,
    after_chunk=None,
) -> None:
    """Advances to ``until``, applying the scenario's world events whose time is in [now, until).

    ``after_chunk(context)``, if given, is called after each of the (at most 500) chunks the run is
    advanced in: the progress bar's and the checkpoints' occasions.
    """
    context = simulator.get_mutable_context()
    start = context.get_time()
    events = sorted(
        (e for e in simulation.scenario.world_events if start <= e.time < until),
        key=lambda e: e.time,
    )
    # Progress is reported in at most 500 chunks.
    chunks = max(1, min(500, int(round((until - start) / simulation.scenario.time_step))))
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(
            total=round(until - start, 3),
            leave=False,
            bar_format="{l_bar}{bar}| {n:.1f}/{total:.1f} s simulated [{elapsed}<{remaining}]",
        )
    requests = SupervisorEventPorts(simulation.diagram)

    def ApplyRequests():
        for port in requests:  # Supervisors' requests, applied once each, in order.
            name = port.get_system().get_name()
            issued = port.Eval(port.get_system().GetMyContextFromRoot(context))
            for event in issued[simulation.applied_requests.get(name, 0) :]:
                simulation.world.Apply(context, event)
            simulation.applied_requests[name] = len(issued)

    ApplyRequests()
    for k in range(1, chunks + 1):
        target = start + (until - start) * k / chunks
        while events and events[0].time <= target:
            event = events.pop(0)
            simulator.AdvanceTo(event.time)
            simulation.world.Apply(context, event)
        before = context.get_time()
        simulator.AdvanceTo(target)
        ApplyRequests()
        if bar is not None:
            bar.update(round(context.get_time() - before, 3))
        if after_chunk is not None:
            after_chunk(context)
    if bar is not None:
        bar.close()


def _ActionsDone(simulation: Simulation, context) -> int:
    """How many actions the exploring agents have completed (0 without agents)."""
    supervisor = simulation.diagram.GetSubsystemByName("attractor")
    if not isinstance(supervisor, ExplorationSupervisor):
        return 0
    return sum(r.actions_done for r in supervisor.Records(supervisor.GetMyContextFromRoot(context)))


def RunScenario(
    scenario: Scenario,
    *,
    meshcat: Meshcat | None = None,
    record: str | None = None,
    realtime_rate: float = 0.0,
    progress: bool = False,
    checkpoint: str | None = None,
) -> RunSummary:
    """Runs ``scenario`` until its duration; with ``record`` saves a Meshcat recording (HTML).

    With ``checkpoint`` (a folder), a run resumes from the checkpoint there if there is one, and
    saves one whenever an exploring agent has completed an action (and at the end), so that an
    interrupted run loses at most the actions in flight.
    """
    if record and meshcat is None:
        meshcat = Meshcat()
    simulation = BuildSimulation(scenario, meshcat)
    simulator = Simulator(simulation.diagram)
    simulator.set_target_realtime_rate(realtime_rate)
    context = simulator.get_mutable_context()
    if checkpoint and (pathlib.Path(checkpoint) / "simulation.npz").is_file():
        LoadCheckpoint(simulation, context, checkpoint)
        simulator.Initialize(InitializeParams(suppress_initialization_events=True))
        # The world's changes live in SceneGraph's Context, not in the checkpoint: replay them.
        for event in sorted(scenario.world_events, key=lambda e: e.time):
            if event.time < context.get_time():
                simulation.world.Apply(context, event)
    else:
        simulator.Initialize()
    if record:
        simulation.visualizer.StartRecording()
    saved = [_ActionsDone(simulation, context)]

    def AfterChunk(context):
        done = _ActionsDone(simulation, context)
        if checkpoint and done > saved[0]:
            SaveCheckpoint(simulation, context, checkpoint)
            saved[0] = done

    start = time.perf_counter()
    simulated_before = context.get_time()
    Advance(simulation, simulator, scenario.duration, progress=progress, after_chunk=AfterChunk)
    if checkpoint:
        SaveCheckpoint(simulation, context, checkpoint)
    wall = time.perf_counter() - start
    context = simulator.get_context()
    recording = None
    if record:
        simulation.visualizer.StopRecording()
        simulation.visualizer.PublishRecording()
        path = pathlib.Path(record)
        _WriteAtomically(path, meshcat.StaticHtml())
        recording = str(path.resolve())
    report = simulation.monitor.Report(simulation.monitor.GetMyContextFromRoot(context))
    return RunSummary(
        simulated_time=context.get_time() - simulated_before,
        wall_time=wall,
        safety=report,
        recording=recording,
    )
