"""Exploring agents on the kinematic iCub, run until a stop condition: the shared step of the
ch. 7 experiments and of the MDP the ch. 8 reach learner starts from."""

import dataclasses
import pathlib
import time

from pydrake.systems.analysis import InitializeParams

from mobee_drake.experiments.battery import JobStopped
from mobee_drake.mobee.params import Dissertation
from mobee_drake.planning.explorers import MissShares
from mobee_drake.planning.supervisor import ExploreAttractor, ExploringAgent
from mobee_drake.scenario import BuildScenario, ResumableConfiguration, Scenario
from mobee_drake.station.checkpoint import (
    HasCheckpoint,
    LoadCheckpoint,
    SaveCheckpoint,
    SavedWallSeconds,
)
from mobee_drake.station.runner import Advance
from mobee_drake.station.world_events import MakeSimulator

# Actions between an exploration's checkpoints (a fifth of a rank-4 lattice run's time went to
# writing them when one was written after almost every action).
CHECKPOINT_EVERY = 20


@dataclasses.dataclass
class ExplorationRun:
    """What an exploration run did (:func:`Explore`); per-agent lists follow ``agents``.

    Attributes:
        agents: The agents' names.
        tries: Per agent, the tries of each state-action.
        values: Per agent, each state-action's value V(s, a) at the end.
        misses: Per agent, the share of each state-action's tries that missed its goal.
        goals: Per agent, the centre of each state-action's goal state (fractions of the
            joints' ranges).
        actions: Per agent, the actions it completed.
        snapshots: The first agent's ``tries`` and ``values`` once it had done the key's
            number of actions.
        coverage: After every chunk: the actions done by all, then per agent its state-actions
            tried at least once.
        simulated_seconds: Simulated time at the end.
        wall_seconds: Wall time of the run (over its resumptions, when it is checkpointed).
        penetrating_steps: Control periods in which two solids penetrated.
        labels: The experiment's setting of the run (e.g. ``gamma`` and ``run``).
        table_contacts: Ch. 7.4 only: per agent, the contact samples of each state-action.
    """

    agents: list[str]
    tries: list[list[int]]
    values: list[list[float]]
    misses: list[list[float]]
    goals: list[list[list[float]]]
    actions: list[int]
    snapshots: dict[int, dict[str, list]]
    coverage: list[list[int]]
    simulated_seconds: float
    wall_seconds: float
    penetrating_steps: int
    labels: dict = dataclasses.field(default_factory=dict)
    table_contacts: list[list[int]] | None = None

    def ToJson(self) -> dict:
        """The run as a battery job's result."""
        return dataclasses.asdict(self)

    @classmethod
    def FromJson(cls, data: dict) -> "ExplorationRun":
        """A run as read back from a job's result (JSON keys are strings; results written
        before the labels had a field of their own hold them at the top level)."""
        fields = {f.name for f in dataclasses.fields(cls)}
        labels = {k: v for k, v in data.items() if k not in fields} | data.get("labels", {})
        snapshots = {int(count): taken for count, taken in data["snapshots"].items()}
        known = {k: v for k, v in data.items() if k in fields}
        return cls(**dict(known, snapshots=snapshots, labels=labels))


def ExplorationScenario(
    agents: list[ExploringAgent], objects=(), robot=None, random_seed: int = 0
) -> Scenario:
    """A headless kinematic scenario in which ``agents`` explore (``robot``: the iCub's
    configuration, by default the upper body's joints; agent i's generator is seeded with
    ``random_seed + i``)."""
    scenario = Scenario()
    if robot is not None:
        scenario.robot = robot
        scenario.visualization.trail_marker = ""  # (headless; the default marker is the iCub's)
    scenario.objects = list(objects)
    scenario.attractor = ExploreAttractor(agents=agents)
    scenario.time_step = 0.02
    scenario.mobee = Dissertation()  # (ch. 7 with the source's constants)
    scenario.random_seed = random_seed
    scenario.data_log.enabled = False  # (The experiments keep their own data.)
    return scenario


def StartExploration(scenario: Scenario, checkpoint: pathlib.Path | None = None):
    """The scenario built and initialised (from the checkpoint in ``checkpoint``, if there is
    one): the station, its simulator, the exploration supervisor and the supervisor's context."""
    station = BuildScenario(scenario)
    simulator = MakeSimulator(station)
    if checkpoint is not None and HasCheckpoint(checkpoint):
        LoadCheckpoint(
            station, simulator.get_mutable_context(), checkpoint, ResumableConfiguration(scenario)
        )
        simulator.Initialize(InitializeParams(suppress_initialization_events=True))
    else:
        simulator.Initialize()
    supervisor = station.client
    return station, simulator, supervisor, supervisor.GetMyContextFromRoot(simulator.get_context())


def Explore(
    scenario: Scenario,
    stop,
    snapshots=(),
    chunk: float = 2.0,
    checkpoint: pathlib.Path | None = None,
    observer=None,
    progress=None,
    should_stop=None,
    checkpoint_every: int = CHECKPOINT_EVERY,
) -> ExplorationRun:
    """Runs until ``stop(records)``; returns what the agents learned and did.

    With ``checkpoint`` (a checkpoint folder), the run resumes from the checkpoint there, saves
    one after the chunk in which ``checkpoint_every`` more actions were done, and keeps the
    final one (the learned models, for a planner to reuse); the data returned then covers the
    whole run (the model, its actions, simulated time and penetrations are in the checkpoint,
    and its wall time), but for ``coverage`` and ``snapshots``, which begin where it resumed.
    ``observer(station)``, if given, returns a callable run on the root context after every
    chunk of the simulation and a function giving the run's ``table_contacts``; ``progress(n)``, if
    given, is told the number of actions done after every chunk; ``should_stop()``, if given, is
    asked after every chunk, and when True the run saves its checkpoint (if it has one) and raises
    :class:`~mobee_drake.experiments.battery.JobStopped`."""
    station, simulator, supervisor, supervisor_context = StartExploration(scenario, checkpoint)
    context = simulator.get_context()
    configuration = ResumableConfiguration(scenario) if checkpoint is not None else ""
    records = supervisor.Records(supervisor_context)
    saved = done = sum(r.actions_done for r in records)
    observe, observed = observer(station) if observer else (None, lambda: None)
    resumed = SavedWallSeconds(checkpoint) if checkpoint is not None else 0.0
    taken, coverage, start = {}, [], time.perf_counter() - resumed

    def Save() -> None:
        SaveCheckpoint(
            station, context, checkpoint, configuration, wall_seconds=time.perf_counter() - start
        )

    while not stop(records):  # (A resumed run that was done stops at once.)
        Advance(station, simulator, context.get_time() + chunk, after_chunk=observe)
        records = supervisor.Records(supervisor_context)
        done = sum(r.actions_done for r in records)
        if checkpoint is not None and done >= saved + checkpoint_every:
            Save()
            saved = done
        if progress is not None:
            progress(done)
        if should_stop is not None and should_stop():
            if checkpoint is not None:
                Save()
            raise JobStopped(f"stopped after {done} actions")
        coverage.append([done] + [int((r.explorer.tries > 0).sum()) for r in records])
        for count in snapshots:
            if count not in taken and records[0].actions_done >= count:
                taken[count] = dict(
                    tries=records[0].explorer.tries.tolist(),
                    values=records[0].explorer.Values()[0].tolist(),
                )
    if checkpoint is not None and (done > saved or not HasCheckpoint(checkpoint)):
        Save()  # (the final model; or none was completed)
    report = station.monitor.Report(station.monitor.GetMyContextFromRoot(context))
    return ExplorationRun(
        agents=supervisor.agent_names,
        tries=[r.explorer.tries.tolist() for r in records],
        values=[r.explorer.Values()[0].tolist() for r in records],
        misses=[MissShares(r.explorer).tolist() for r in records],
        goals=[r.explorer.space.centres[r.explorer.space.action_goal].tolist() for r in records],
        actions=[r.actions_done for r in records],
        snapshots=taken,
        coverage=coverage,
        simulated_seconds=context.get_time(),
        wall_seconds=time.perf_counter() - start,
        penetrating_steps=report.penetrating_steps,
        table_contacts=observed(),
    )
