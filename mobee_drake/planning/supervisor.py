"""Agents on the robot: the exploration loop of Alg. 8 as a Drake system (dissertation ch. 6.1).

An *action* sets MoBeE's attractor, for the agent's joints, to the centre of the goal state; it
ends when the robot has settled (every joint of the agent slower than ``settle_speed`` for
``settle_time``, and at least ``min_duration`` after the start) or after ``timeout``. The outcome
is the state holding the final configuration; the agent observes it (Alg. 6) and chooses the next
action (Alg. 7-8). Several agents run at once, each on its own joints and blind to the others
(ch. 7.4); joints of no agent are held at home. An agent with the "planner" strategy heads for
its goal state and stops once an action has ended there.

Where the learned model lives: the supervisor's state is one abstract value, a tuple of
:class:`AgentRecord`, updated by a periodic unrestricted update (the polling period of the
original learner, 0.2 s). Drake deep-copies abstract state at every unrestricted update, so the
records are immutable: copying one returns the same object, and an update builds a new record
(copying the agent's model) only when that agent's action ends. Polling therefore costs no copy
of a model.
"""

import dataclasses as dc

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem

from mobee_drake.planning.explorers import Explorer, ExplorerConfig
from mobee_drake.planning.state_space import StateActionSpace


@dc.dataclass
class ActionTiming:
    """When an action ends (ch. 6.1; the original MoBeE learner's values, in radians)."""

    settle_speed: float = np.radians(2.0)  # rad/s, every joint of the agent
    settle_time: float = 0.5  # s the robot must stay that slow
    min_duration: float = 0.5  # s before an action may end
    timeout: float = 20.0  # s


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

    def __deepcopy__(self, memo) -> "AgentRecord":
        return self


@dc.dataclass
class Agent:
    """An agent's configuration: its name, joints, state-action space and exploration settings."""

    name: str
    joints: list[str]
    space: StateActionSpace
    explorer: ExplorerConfig = dc.field(default_factory=ExplorerConfig)
    # A model learned before (its space must be ``space``); None: start afresh.
    model: Explorer | None = None


class ExplorationSupervisor(LeafSystem):
    """Runs exploring agents on the robot and writes MoBeE's attractor.

    .. pydrake_system::

        name: ExplorationSupervisor
        input_ports:
        - robot_state
        output_ports:
        - attractor

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
    ):
        super().__init__()
        self._agents = list(agents)
        self._timing = timing or ActionTiming()
        self._lower, self._upper, self._home = lower, upper, np.asarray(home, dtype=float)
        self._n = len(joints)
        self._columns = []
        for agent in self._agents:
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

    def _StateOf(self, agent: Agent, columns: np.ndarray, q: np.ndarray) -> int:
        return agent.space.StateOfConfiguration(
            q[columns], self._lower[columns], self._upper[columns]
        )

    def _Begin(
        self,
        agent: Agent,
        columns,
        explorer: Explorer,
        q: np.ndarray,
        time: float,
        actions_done: int,
    ) -> AgentRecord:
        state = self._StateOf(agent, columns, q)
        return AgentRecord(
            explorer=explorer,
            state=state,
            state_action=explorer.ChooseAction(state),
            started=time,
            slow_since=np.inf,
            actions_done=actions_done,
        )

    def _Start(self, context, state) -> None:
        q = self._state_port.Eval(context)[: self._n]
        records = tuple(
            self._Begin(
                agent,
                columns,
                agent.model.Copy() if agent.model else Explorer(agent.space, agent.explorer),
                q,
                context.get_time(),
                0,
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
        for i, (agent, columns) in enumerate(zip(self._agents, self._columns)):
            record = records[i]
            if record.arrived:
                continue
            slow = np.max(np.abs(v[columns])) < timing.settle_speed
            slow_since = min(record.slow_since, now) if slow else np.inf
            elapsed = now - record.started
            settled = (
                elapsed >= timing.min_duration and slow and now - slow_since >= timing.settle_time
            )
            if settled or elapsed >= timing.timeout:
                explorer = record.explorer.Copy()
                outcome = self._StateOf(agent, columns, q)
                explorer.Observe(record.state_action, outcome)
                if explorer.config.strategy == "planner" and outcome == explorer.config.goal_state:
                    records[i] = dc.replace(
                        record,
                        explorer=explorer,
                        state=outcome,
                        actions_done=record.actions_done + 1,
                        arrived=True,
                    )
                else:
                    records[i] = self._Begin(
                        agent, columns, explorer, q, now, record.actions_done + 1
                    )
                changed = True
            elif slow_since != record.slow_since:
                records[i] = dc.replace(record, slow_since=slow_since)
                changed = True
        if changed:
            state.get_mutable_abstract_state(int(self._records)).set_value(tuple(records))

    def _CalcAttractor(self, context, output) -> None:
        q_star = self._home.copy()
        for agent, columns, record in zip(
            self._agents, self._columns, context.get_abstract_state(int(self._records)).get_value()
        ):
            q_star[columns] = agent.space.Centre(
                agent.space.action_goal[record.state_action],
                self._lower[columns],
                self._upper[columns],
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
        config, columns = self._agents[i], self._columns[i]
        records = list(self.Records(context))
        explorer = records[i].explorer.Copy()
        if explorer.config.strategy != "planner":
            raise ValueError(
                f"agent '{agent}' explores ('{explorer.config.strategy}'); only a "
                "'planner' agent takes goals"
            )
        if not 0 <= goal < config.space.num_states:
            raise ValueError(
                f"agent '{agent}': goal state {goal} is not a state "
                f"(0..{config.space.num_states - 1})"
            )
        explorer.config = dc.replace(explorer.config, goal_state=goal)
        q = self._state_port.Eval(context)[: self._n]
        state = self._StateOf(config, columns, q)
        if state == goal:
            records[i] = dc.replace(records[i], explorer=explorer, state=state, arrived=True)
        else:
            records[i] = self._Begin(
                config, columns, explorer, q, context.get_time(), records[i].actions_done
            )
        self.SetRecords(context, tuple(records))

    @property
    def agent_names(self) -> list[str]:
        return [agent.name for agent in self._agents]

    @property
    def agents(self) -> tuple[Agent, ...]:
        return tuple(self._agents)
