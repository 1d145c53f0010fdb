"""Agents on the robot: the exploration loop of Alg. 8 as a Drake system (dissertation ch. 6.1).

An *action* sets MoBeE's attractor, for the agent's joints, to the centre of the goal state; it ends
when the robot has settled (:mod:`mobee_drake.station.settling`, watching the agent's joints) or
timed out. The outcome is the state holding the final configuration; the agent observes it (Alg. 6)
and chooses the next action (Alg. 7-8). Several agents run at once, each on its own joints and blind
to the others (ch. 7.4); joints of no agent are held at home. An agent with the "planner" strategy
heads for its goal state and stops once an action has ended there.

Where the learned model lives: the supervisor's state is one abstract value, a tuple of
:class:`AgentRecord`, updated by a periodic unrestricted update (the polling period of the
original learner, 0.2 s). Drake deep-copies abstract state at every unrestricted update, so the
records are immutable: copying one returns the same object, and an update builds a new record
(copying the agent's model) only when that agent's action ends. Polling therefore costs no copy
of a model.
"""

import copy
import dataclasses as dc
import json
import pathlib
import re

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem

from mobee_drake.array_files import WriteArrays
from mobee_drake.atomic_files import CurrentGeneration, StrictJson
from mobee_drake.planning.actuation_noise import NoisyPosture, ValidateNoise
from mobee_drake.planning.explorers import (
    Explorer,
    ExplorerConfig,
    ExplorerFromArrays,
    ExplorerToArrays,
    LoadAgentModel,
)
from mobee_drake.planning.space_maintenance import Maintenance, MaintenanceConfig
from mobee_drake.planning.state_space import FromGraph, Lattice, StateActionSpace
from mobee_drake.planning.strategies import STRATEGIES
from mobee_drake.station.parts import ClientPorts, StationParts
from mobee_drake.station.settling import ActionTiming
from mobee_drake.trm.roadmap import TaskRelevantRoadmap


@dc.dataclass(frozen=True)
class AgentRecord:
    """One agent's learned model and the action in flight. Immutable: see the module."""

    explorer: Explorer
    state: int  # the state the action started from
    state_action: int  # the action in flight
    started: float  # its start time (s)
    slow_since: float  # since when the agent's joints have been slow (inf: not slow)
    actions_done: int
    # A planner that arrived in its goal state stops there (its attractor stays on the goal).
    arrived: bool = False
    # The maintenance of a space that reshapes itself (ch. 9.4.5; None: a fixed space). The
    # explorer's space is the agent's space now.
    maintenance: Maintenance | None = None
    # Where each action ended: the agent's joints, fractions of their ranges (a measure of
    # where the arm has been that does not depend on how the space is cut).
    settled: tuple[tuple[float, ...], ...] = ()

    def __deepcopy__(self, memo) -> "AgentRecord":
        return self


# The data log's columns of an agent (and of one whose space reshapes itself): name, unit.
_LOGGED = (("state", "index"), ("state_action", "index"), ("actions_done", "count"))
_LOGGED_MAINTENANCE = (("states", "count"), ("state_actions", "count"), ("space_changes", "count"))


def _LoggedValues(record: AgentRecord) -> tuple:
    """The values of an agent's data-log columns (see ExplorationSupervisor.DataLogColumns)."""
    logged = (record.state, record.state_action, record.actions_done)
    if record.maintenance is None:
        return logged
    space = record.explorer.space
    return logged + (space.num_states, space.num_state_actions, len(record.maintenance.changes))


@dc.dataclass
class Agent:
    """An agent's configuration: its name, joints, state-action space and exploration settings."""

    name: str
    joints: list[str]
    space: StateActionSpace
    explorer: ExplorerConfig = dc.field(default_factory=ExplorerConfig)
    # A model learned before (its space must be ``space``); None: start afresh.
    model: Explorer | None = None
    # Seeds the agent's generator (a fresh model's; a given model brings its own).
    seed: int = 0
    # Reshapes the space as the agent learns (ch. 9.4.5; None: the space stays).
    maintenance: MaintenanceConfig | None = None
    # With ``model`` and ``maintenance``: the maintenance that reshaped the model's space (what
    # it pruned and dropped: nothing grows back there), carried on; None: a fresh one.
    maintained_before: Maintenance | None = None


def _CheckAgent(agent: Agent, joints: list[str]) -> None:
    """Raises ValueError (a one-line message) when ``agent`` cannot run on MoBeE's ``joints``."""
    unknown = [j for j in agent.joints if j not in joints]
    if unknown:
        raise ValueError(
            f"agent '{agent.name}': unknown joints {unknown}; MoBeE's "
            "joints are: " + ", ".join(joints)
        )
    if (
        agent.model is not None
        and agent.model.space.num_state_actions != agent.space.num_state_actions
    ):
        raise ValueError(
            f"agent '{agent.name}': its model has "
            f"{agent.model.space.num_state_actions} state-actions, its "
            f"space {agent.space.num_state_actions}"
        )
    if agent.space.centres.shape[1] != len(agent.joints):
        raise ValueError(
            f"agent '{agent.name}': its space has "
            f"{agent.space.centres.shape[1]} dimensions for "
            f"{len(agent.joints)} joints"
        )
    if agent.maintenance is not None and STRATEGIES[agent.explorer.strategy].seeks_goal:
        raise ValueError(
            f"agent '{agent.name}': a space that reshapes itself is for exploring "
            f"agents; strategy '{agent.explorer.strategy}' heads for a goal state, "
            "whose number a round would change"
        )
    if agent.maintenance is not None and "develop" in agent.maintenance.rules:
        raise ValueError(
            f"agent '{agent.name}': the rule 'develop' needs a learner that favours "
            "states (the reach learner's); an exploring agent favours none"
        )


class ExplorationSupervisor(LeafSystem):
    """Runs exploring agents on the robot and writes MoBeE's attractor.

    .. pydrake_system::

        name: ExplorationSupervisor
        input_ports:
        - robot_state
        output_ports:
        - attractor
        - data_log

    ``robot_state`` is (q, v) of MoBeE's joints ``joints``; ``attractor`` is q* for the same joints.
    """

    def __init__(
        self,
        *,
        agents: list[Agent],
        joints: list[str],
        lower: np.ndarray,
        upper: np.ndarray,
        home: np.ndarray,
        timing: ActionTiming | None = None,
        period: float = 0.2,
        transition_noise: float = 0.0,
    ):
        """``transition_noise``: the actuation noise's standard deviation per joint, a fraction
        of its range (see :mod:`mobee_drake.planning.actuation_noise`)."""
        super().__init__()
        ValidateNoise(transition_noise)
        self._noise = transition_noise
        self._agents = list(agents)
        self._timing = timing or ActionTiming()
        self._lower, self._upper, self._home = lower, upper, np.asarray(home, dtype=float)
        self._n = len(joints)
        self._columns = []
        for agent in self._agents:
            _CheckAgent(agent, joints)
            self._columns.append(np.array([joints.index(j) for j in agent.joints]))
        claimed = np.concatenate(self._columns) if self._columns else np.zeros(0, dtype=int)
        if len(set(claimed.tolist())) != len(claimed):
            raise ValueError("two agents share a joint; each joint belongs to at most one agent")
        self._state_port = self.DeclareVectorInputPort("robot_state", 2 * self._n)
        self._records = self.DeclareAbstractState(AbstractValue.Make(tuple()))
        self.DeclareInitializationUnrestrictedUpdateEvent(self._Start)
        self.DeclarePeriodicUnrestrictedUpdateEvent(
            period_sec=period, offset_sec=period, update=self._Poll
        )
        # The same poll on demand (tests, scripts that step the supervisor by hand).
        self.DeclareForcedUnrestrictedUpdateEvent(self._Poll)
        self.DeclareVectorOutputPort(
            "attractor",
            self._n,
            self._CalcAttractor,
            prerequisites_of_calc={self.abstract_state_ticket(self._records)},
        )
        # What the station's data log keeps of each agent (see DataLogColumns).
        self.DeclareVectorOutputPort(
            "data_log",
            len(self.DataLogColumns()),
            lambda context, output: output.SetFromVector(
                [x for r in self.Records(context) for x in _LoggedValues(r)]
            ),
            prerequisites_of_calc={self.abstract_state_ticket(self._records)},
        )

    def DataLogColumns(self) -> list[tuple[str, str]]:
        """Per agent: the state its action started from, the state-action in flight, and the
        actions it has completed; for an agent whose space reshapes itself, also its states,
        its state-actions and the changes made so far (see :mod:`mobee_drake.station.data_log`).
        """
        columns = []
        for agent in self._agents:
            logged = _LOGGED + (_LOGGED_MAINTENANCE if agent.maintenance is not None else ())
            columns += [(f"agent.{agent.name}.{column}", unit) for column, unit in logged]
        return columns

    def _StateOf(self, space: StateActionSpace, columns: np.ndarray, q: np.ndarray) -> int:
        return space.StateOfConfiguration(q[columns], self._lower[columns], self._upper[columns])

    def _Begin(
        self,
        columns,
        explorer: Explorer,
        q: np.ndarray,
        time: float,
        actions_done: int,
        maintenance: Maintenance | None,
        settled: tuple[tuple[float, ...], ...] = (),
    ) -> AgentRecord:
        state = self._StateOf(explorer.space, columns, q)
        return AgentRecord(
            explorer=explorer,
            state=state,
            state_action=explorer.ChooseAction(state),
            started=time,
            slow_since=np.inf,
            actions_done=actions_done,
            maintenance=maintenance,
            settled=settled,
        )

    def _Start(self, context, state) -> None:
        q = self._state_port.Eval(context)[: self._n]
        records = tuple(
            self._Begin(
                columns,
                agent.model.Copy()
                if agent.model
                else Explorer(agent.space, agent.explorer, agent.seed),
                q,
                context.get_time(),
                0,
                agent.maintenance
                and (
                    agent.maintained_before.Continued()
                    if agent.maintained_before
                    else Maintenance(agent.maintenance, agent.space.num_states)
                ),
            )
            for agent, columns in zip(self._agents, self._columns)
        )
        state.get_mutable_abstract_state(int(self._records)).set_value(records)

    def _Poll(self, context, state) -> None:
        x = self._state_port.Eval(context)
        q, v = x[: self._n], x[self._n :]
        now, timing = context.get_time(), self._timing
        records = list(context.get_abstract_state(int(self._records)).get_value())
        changed = False
        for i, columns in enumerate(self._columns):
            record = records[i]
            if record.arrived:
                continue
            slow_since = timing.SlowSince(record.slow_since, now, v[columns])
            if timing.Ended(now, record.started, slow_since):
                explorer = record.explorer.Copy()
                outcome = self._StateOf(explorer.space, columns, q)
                explorer.Observe(record.state_action, outcome)
                explorer, maintenance = self._Maintain(record, explorer, outcome)
                lower, upper = self._lower[columns], self._upper[columns]
                settled = (
                    *record.settled,
                    tuple(((q[columns] - lower) / (upper - lower)).tolist()),
                )
                if explorer.seeks_goal and outcome == explorer.config.goal_state:
                    records[i] = dc.replace(
                        record,
                        explorer=explorer,
                        state=outcome,
                        actions_done=record.actions_done + 1,
                        arrived=True,
                        settled=settled,
                    )  # (a goal-seeking agent's space is not maintained)
                else:
                    records[i] = self._Begin(
                        columns, explorer, q, now, record.actions_done + 1, maintenance, settled
                    )
                changed = True
            elif slow_since != record.slow_since:
                records[i] = dc.replace(record, slow_since=slow_since)
                changed = True
        if changed:
            state.get_mutable_abstract_state(int(self._records)).set_value(tuple(records))

    @staticmethod
    def _Maintain(record: AgentRecord, explorer: Explorer, outcome: int):
        """(the explorer, the maintenance) after the action of ``record`` ended in ``outcome``
        and ``explorer`` observed it: a round of maintenance when one is due (a copy of the
        record's maintenance changes; the record stays as it was)."""
        if record.maintenance is None:
            return explorer, None
        maintenance = copy.deepcopy(record.maintenance)
        maintenance.Observe(record.explorer.space, record.state, record.state_action, outcome)
        if maintenance.Due(record.actions_done + 1):
            explorer, _ = maintenance.Apply(explorer, outcome, record.actions_done + 1)
        return explorer, maintenance

    def _CalcAttractor(self, context, output) -> None:
        q_star = self._home.copy()
        records = context.get_abstract_state(int(self._records)).get_value()
        for i, (agent, columns, record) in enumerate(zip(self._agents, self._columns, records)):
            lower, upper = self._lower[columns], self._upper[columns]
            space = record.explorer.space
            centre = space.Centre(space.action_goal[record.state_action], lower, upper)
            q_star[columns] = NoisyPosture(
                centre, lower, upper, self._noise, agent.seed, i, record.started
            )
        output.SetFromVector(q_star)

    def Records(self, context) -> tuple[AgentRecord, ...]:
        """The agents' records in ``context`` (this system's context)."""
        return context.get_abstract_state(int(self._records)).get_value()

    def SetRecords(self, context, records: tuple[AgentRecord, ...]) -> None:
        """Replaces the agents' records in ``context`` (to resume a saved run)."""
        if len(records) != len(self._agents):
            raise ValueError(f"{len(records)} saved agents for {len(self._agents)} agents")
        context.get_mutable_abstract_state(int(self._records)).set_value(tuple(records))

    def SetPlannerGoal(self, context, agent: str, goal: int) -> None:
        """Gives the "planner" agent ``agent`` a new goal state (ch. 6.5, 7.4.1): from the state
        the robot is in now it plans for the new goal and starts its first action (or, already
        there, stays). ``context`` is this system's context."""
        if agent not in self.agent_names:
            raise ValueError(f"unknown agent '{agent}'; agents: " + ", ".join(self.agent_names))
        i = self.agent_names.index(agent)
        columns = self._columns[i]
        records = list(self.Records(context))
        explorer = records[i].explorer.Copy()
        if not explorer.seeks_goal:
            raise ValueError(
                f"agent '{agent}' explores ('{explorer.config.strategy}'); only an agent whose "
                "strategy seeks a goal (the 'planner') takes goals"
            )
        space = explorer.space
        if not 0 <= goal < space.num_states:
            raise ValueError(
                f"agent '{agent}': goal state {goal} is not a state (0..{space.num_states - 1})"
            )
        explorer.config = dc.replace(explorer.config, goal_state=goal)
        q = self._state_port.Eval(context)[: self._n]
        state = self._StateOf(space, columns, q)
        if state == goal:
            records[i] = dc.replace(records[i], explorer=explorer, state=state, arrived=True)
        else:
            records[i] = self._Begin(
                columns,
                explorer,
                q,
                context.get_time(),
                records[i].actions_done,
                records[i].maintenance,
                records[i].settled,
            )
        self.SetRecords(context, tuple(records))

    @property
    def agent_names(self) -> list[str]:
        return [agent.name for agent in self._agents]

    @property
    def agents(self) -> tuple[Agent, ...]:
        return tuple(self._agents)

    # ----------------------------------------------------------------------------------------
    # The station's checkpoint protocol (see :mod:`mobee_drake.station.checkpoint`) and the
    # runner's count of completed actions.

    def CompletedActions(self, context) -> int:
        return sum(record.actions_done for record in self.Records(context))

    def Outcome(self, context) -> dict:
        """Per agent: actions taken, state-actions tried of all, and the value-iteration
        residual of its model (the largest change another sweep of Alg. 7 would make)."""
        outcome = {}
        for name, record in zip(self.agent_names, self.Records(context)):
            explorer = record.explorer
            q, v = explorer.Values()
            T = explorer.transitions.Probabilities()
            gamma = explorer.config.gamma
            residual = np.abs(explorer.rewards + gamma * T @ v - q).max(initial=0.0)
            outcome[name] = {
                "actions": record.actions_done,
                "state_actions_tried": int((explorer.tries > 0).sum()),
                "state_actions": explorer.space.num_state_actions,
                "value_iteration_residual": float(residual),
            }
        return {"agents": outcome}

    def WriteCheckpoint(self, context, folder: pathlib.Path) -> None:
        """Writes ``<agent>.npz`` (the learned model) and ``<agent>.json`` (its configuration,
        its generator's state and the action in flight) for every agent."""
        records = self.Records(context)
        for name, record, columns in zip(self.agent_names, records, self._columns):
            arrays, data = ExplorerToArrays(record.explorer)
            data["record"] = {
                field.name: getattr(record, field.name)
                for field in dc.fields(record)
                if field.name not in ("explorer", "maintenance", "settled")
            }
            arrays["settled"] = np.reshape(record.settled, (len(record.settled), len(columns)))
            if record.maintenance is not None:
                arrays["maintenance_chains"], data["maintenance"] = record.maintenance.ToData()
            WriteArrays(folder / f"{name}.npz", **arrays)
            # Not slow (inf) is written null: JSON has no infinity.
            slow = float(record.slow_since)
            data["record"]["slow_since"] = slow if np.isfinite(slow) else None
            (folder / f"{name}.json").write_text(StrictJson(data, indent=1))

    def ReadCheckpoint(self, context, folder: pathlib.Path) -> None:
        records = []
        for agent in self._agents:
            data = json.loads((folder / f"{agent.name}.json").read_text())
            arrays = np.load(folder / f"{agent.name}.npz")
            explorer = ExplorerFromArrays(arrays, data)
            record = data["record"]
            record["slow_since"] = np.inf if record["slow_since"] is None else record["slow_since"]
            maintenance = None
            if agent.maintenance is not None:
                maintenance = Maintenance.FromData(
                    agent.maintenance, arrays["maintenance_chains"], data["maintenance"]
                )
            # (none from a checkpoint from before they were kept)
            settled = tuple(map(tuple, arrays["settled"].tolist())) if "settled" in arrays else ()
            records.append(
                AgentRecord(explorer=explorer, maintenance=maintenance, settled=settled, **record)
            )
        self.SetRecords(context, tuple(records))


def _SavedAgent(folder: str, name: str) -> pathlib.Path:
    """Agent ``name``'s files in a checkpoint folder (its newest generation, or the folder's
    own files), without their suffix."""
    return (CurrentGeneration(folder) or pathlib.Path(folder)) / name


def SavedMaintenance(folder: str, name: str, config: MaintenanceConfig) -> Maintenance | None:
    """The maintenance agent ``name`` saved in a checkpoint folder (its newest generation, or
    the folder's own files), under ``config``; None if its space was not maintained."""
    base = _SavedAgent(folder, name)
    data = json.loads(base.with_suffix(".json").read_text())
    if not data.get("maintenance"):
        return None
    chains = np.load(base.with_suffix(".npz"))["maintenance_chains"]
    return Maintenance.FromData(config, chains, data["maintenance"])


def SavedSettled(folder: str, name: str) -> np.ndarray:
    """(actions, joints): where each action of agent ``name`` saved in a checkpoint folder
    ended (:attr:`AgentRecord.settled`); none from a checkpoint from before they were kept."""
    arrays = np.load(_SavedAgent(folder, name).with_suffix(".npz"))
    return arrays["settled"] if "settled" in arrays else np.zeros((0, 0))


def RoadmapStateSpace(
    folder: str, joints: list[str], all_joints: list[str], lower: np.ndarray, upper: np.ndarray
) -> StateActionSpace:
    """The state-action space of a saved task-relevant roadmap over an agent's ``joints`` (of
    ``all_joints``, whose limits are ``lower`` and ``upper``)."""
    roadmap = TaskRelevantRoadmap.Load(folder)
    missing = [j for j in joints if j not in roadmap.joints]
    if missing:
        raise ValueError(f"{folder}: the roadmap has no joint(s) {', '.join(missing)}")
    mine = [all_joints.index(j) for j in joints]
    theirs = [roadmap.joints.index(j) for j in joints]
    centres = (roadmap.q[:, theirs] - lower[mine]) / (upper[mine] - lower[mine])
    return FromGraph(centres, roadmap.edges)


# An agent's name: its model's file name in a checkpoint (``<name>.npz``), so no path in it.
AGENT_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]*")


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
    # Start from a model learned before: a checkpoint folder holding ``<name>.npz/json`` (with
    # ``maintenance``, its space as it had reshaped itself).
    model: str = ""
    # Reshape the space as the agent learns (ch. 9.4.5, docs/adaptive_space.md); none: fixed.
    maintenance: MaintenanceConfig | None = None


@dc.dataclass
class ExploreAttractor:
    """The attractor is set by exploring agents (Alg. 8), each on its own joints. Agent i's
    generator is seeded with the scenario's ``random_seed + i``."""

    agents: list[ExploringAgent] = dc.field(default_factory=list)
    timing: ActionTiming = dc.field(default_factory=ActionTiming)
    # A stochastic robot (issue 33): the actuation noise's standard deviation, a fraction of
    # each joint's range (0: none; see mobee_drake.planning.actuation_noise).
    transition_noise: float = 0.0

    def Validate(self) -> None:
        self.timing.Validate()
        ValidateNoise(self.transition_noise)
        names = [agent.name for agent in self.agents]
        if not names:
            raise ValueError("exploring agents: there is none")
        if len(set(names)) != len(names) or not all(names):
            raise ValueError(f"exploring agents need unique, non-empty names, got {names}")
        for name in names:  # (a name is the file name of the agent's model in checkpoints)
            if not AGENT_NAME.fullmatch(name):
                raise ValueError(
                    f"exploring agent name '{name}': use letters, digits, '_' and '-' only "
                    "(it names the agent's files), starting with a letter or digit"
                )
        for agent in self.agents:
            where = f"exploring agent '{agent.name}'"
            if not agent.joints or len(set(agent.joints)) != len(agent.joints):
                raise ValueError(f"{where}: needs joints, each once, got {agent.joints}")
            if not agent.roadmap and not (
                agent.levels and all(0 <= level <= 1 for level in agent.levels)
            ):
                raise ValueError(
                    f"{where}: levels must be fractions of each joint's range in [0, 1], "
                    f"got {agent.levels}"
                )
            if not agent.roadmap and len(set(agent.levels)) < 2:
                raise ValueError(
                    f"{where}: levels need at least two different values (one state is no "
                    f"space to explore), got {agent.levels}"
                )
            states = len(set(agent.levels)) ** len(agent.joints)
            if agent.nearest < 0 or (not agent.roadmap and agent.nearest >= states):
                raise ValueError(
                    f"{where}: nearest must be >= 0 and less than the {states} states, "
                    f"got {agent.nearest}"
                )
            for error in agent.explorer.Errors():
                raise ValueError(f"{where}: explorer {error}")
            for error in agent.maintenance.Errors() if agent.maintenance else ():
                raise ValueError(f"{where}: maintenance {error}")

    def AddToBuilder(self, parts: StationParts) -> ClientPorts:
        mobee = parts.mobee
        lower, upper = mobee.position_limits
        agents = []
        for i, config in enumerate(self.agents):
            seed = parts.random_seed + i
            space = (
                RoadmapStateSpace(config.roadmap, config.joints, mobee.joints, lower, upper)
                if config.roadmap
                else Lattice(config.levels, len(config.joints), k=config.nearest or None)
            )
            model = (
                LoadAgentModel(config.model, config.name, config.explorer, seed)
                if config.model
                else None
            )
            maintained_before = None
            if model is not None and config.maintenance is not None:
                space = model.space  # (as it had reshaped itself)
                maintained_before = SavedMaintenance(config.model, config.name, config.maintenance)
            agents.append(
                Agent(
                    name=config.name,
                    joints=config.joints,
                    space=space,
                    explorer=config.explorer,
                    model=model,
                    seed=seed,
                    maintenance=config.maintenance,
                    maintained_before=maintained_before,
                )
            )
        supervisor = parts.builder.AddNamedSystem(
            f"{parts.prefix}exploration_supervisor",
            ExplorationSupervisor(
                agents=agents,
                joints=mobee.joints,
                lower=lower,
                upper=upper,
                home=mobee.home,
                timing=self.timing,
                transition_noise=self.transition_noise,
            ),
        )
        parts.builder.Connect(parts.robot_state, supervisor.GetInputPort("robot_state"))
        return ClientPorts(
            system=supervisor,
            attractor=supervisor.GetOutputPort("attractor"),
            outcome=supervisor,
            action_counters=[supervisor],
            data_log=supervisor,
            checkpointed=[supervisor],
        )
