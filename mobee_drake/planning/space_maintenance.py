"""A state-action space that reshapes itself as its agent learns (dissertation ch. 9.4.5).

The source's future work: states found unreachable could be pruned and the interesting regions
built up, shortcuts made between frequently linked far-apart states and often infeasible
transitions removed, "all of this ... facilitated by intrinsic motivation": an addition is
interesting (its model starts optimistic, as every state-action's does, Alg. 6) until it is
predictable. Each rule below reads only the agent's learned model and what it has done (and,
for ``develop``, the states its learner favours); a round of maintenance
(:meth:`Maintenance.Plan`) applies every enabled rule at once, and :func:`CarryExplorer` moves
the learned model onto the new space (:meth:`Maintenance.Apply` does both): nothing learned
about a state-action that stays is lost, and new ones start as the agent's first ones did.

The rules (:class:`MaintenanceConfig` holds their parameters):

- ``prune``: a state the robot was never in (no action arrived in it, none was tried from it,
  as the model shows or as :attr:`Maintenance.entered` saw it, nor does its learner say it was
  there), after ``prune_after`` tries of the actions into it (those ``drop`` removed included),
  is dropped with every action into or out of it (the lattice's states beyond the shoulder's
  cable constraints, ch. 7.3). The state the robot is in is never dropped.
- ``drop``: a transition tried ``drop_after`` times that missed its goal on at least
  ``drop_miss_share`` of them is removed, unless it is its state's last action.
- ``shortcut``: when the agent has gone from a state through a second to a third, not linked
  to the first, ``shortcut_after`` times (two consecutive actions that each arrived, the second
  from where the first did), an action from the first straight to the third is added, unless
  ``drop`` removed that transition before (no shortcut brings a dropped transition back).
- ``grow``: halfway between a state pruned in this round and each state that had an action into
  it, a new state, joined both ways to every state within ``join_within`` times that action's
  length of it: the boundary of the reachable region is probed more finely, down to
  ``min_spacing``, never back where a state was pruned, and while the space has fewer than
  ``max_states`` states. (The source does not say how a new state is linked. The default, 1,
  joins it on a lattice to the action's two ends and to the round's other new states within
  that length, the one across the favoured or pruned state included; on a roadmap of long
  edges to every state as near as the edge is long, which can make the roadmap dense:
  docs/adaptive_space.md. 0.5 joins it only to the states no farther than the action's ends: a
  state grown toward a pruned one, to the end that stays.)
- ``develop``: the same halfway between each state the learner favours (it names them, e.g. the
  reach learner's states whose reaches worked best for many targets, ch. 9.4.5) and each of its
  neighbours: the regions that matter get more states.
"""

import collections
from collections.abc import Iterable
import copy
import dataclasses as dc
import math
import pathlib
from typing import ClassVar

import numpy as np

from mobee_drake.planning.explorers import Explorer, MissShares, ObservedOutcomes
from mobee_drake.planning.state_space import StateActionSpace

RULES = ("prune", "drop", "shortcut", "grow", "develop")
# The rules that add states.
_NEW_STATES = ("grow", "develop")


@dc.dataclass
class MaintenanceConfig:
    """When the space is maintained and by which rules (see the module)."""

    # Actions between rounds of maintenance (0: never).
    every: int = 100
    # The rules applied at each round, of prune, drop, shortcut, grow and develop (develop
    # needs a learner that names its favoured states, e.g. the reach learner's best reaches).
    rules: list[str] = dc.field(default_factory=lambda: ["prune", "drop", "shortcut", "grow"])
    # prune: tries of the actions into a state, none arriving, before the state is dropped.
    prune_after: int = 6
    # drop: tries of a transition, and the share of them that missed, before it is removed.
    drop_after: int = 5
    drop_miss_share: float = 0.8
    # shortcut: chains of two arriving actions from one state to a third before the shortcut.
    shortcut_after: int = 5
    # develop: the learner's favoured states developed per round, and the different targets
    # a state's reach needs records of to be favoured (the reach learner's).
    develop_top: int = 3
    develop_min_targets: int = 5
    # A new state is at least this far (fractions of range) from every other.
    min_spacing: float = 0.05
    # The space grows while it has fewer states than this (0: no limit).
    max_states: int = 0
    # grow, develop: a new state is joined both ways to every state within this share of the
    # length of the action it grew from (at least 0.5, the distance to that action's ends).
    join_within: float = 1.0
    # No round at or after this many actions (0: no such limit): a run that ends there is
    # measured on the space it explored, not on one just reshaped.
    until: int = 0

    # Fields added after batteries that record these settings were kept: left out of a job's
    # recorded arguments at these values (experiments.battery).
    LATER_FIELDS: ClassVar[dict] = {"join_within": 1.0}

    def Errors(self) -> list[str]:
        """What is wrong with the settings that their types cannot say (empty: nothing)."""
        errors = [
            f"unknown rule '{r}'; the rules are {', '.join(RULES)}"
            for r in self.rules
            if r not in RULES
        ]
        for name in ("every", "max_states", "until"):
            if getattr(self, name) < 0:
                errors.append(f"{name} must be >= 0, got {getattr(self, name)}")
        for name in (
            "prune_after",
            "drop_after",
            "shortcut_after",
            "develop_top",
            "develop_min_targets",
        ):
            if getattr(self, name) < 1:
                errors.append(f"{name} must be >= 1, got {getattr(self, name)}")
        if not 0 < self.drop_miss_share <= 1:
            errors.append(f"drop_miss_share must be in (0, 1], got {self.drop_miss_share}")
        if not self.min_spacing > 0:
            errors.append(f"min_spacing must be > 0, got {self.min_spacing}")
        if not 0.5 <= self.join_within < math.inf:
            errors.append(
                f"join_within must be >= 0.5 (the action's ends) and finite, got {self.join_within}"
            )
        return errors


@dc.dataclass(frozen=True)
class SpaceChange:
    """One change of a round, in the indices of the space before the round: a ``rule``'s dropped
    state (and its ``centre``), dropped or added action (``states``: its state and goal) or new
    state (``centre``, and ``states``: the pruned state, or the favoured state's neighbour, and
    the state it grew from)."""

    actions_done: int
    rule: str
    states: tuple[int, ...]
    centre: tuple[float, ...] = ()


@dc.dataclass(frozen=True)
class SpaceEdit:
    """A reshaped space and where each old state and state-action went (-1: dropped)."""

    space: StateActionSpace
    state_index: np.ndarray
    action_index: np.ndarray


def EditSpace(
    space: StateActionSpace,
    *,
    drop_states=(),
    drop_actions=(),
    new_centres=(),
    new_actions=(),
) -> SpaceEdit:
    """``space`` with ``new_centres`` appended (their indices follow the old states'),
    ``new_actions`` added ((state, goal) pairs over old and new indices), then
    ``drop_actions`` (old state-action indices) and ``drop_states`` (old or new indices, with
    every action into or out of them) removed: the new space, where each old state and
    state-action went. States keep their order, new ones last; actions are sorted by state,
    then goal."""
    centres = np.vstack([space.centres, np.reshape(new_centres, (-1, space.centres.shape[1]))])
    total = len(centres)
    kept_states = np.ones(total, dtype=bool)
    kept_states[list(drop_states)] = False
    state_index = np.where(kept_states, np.cumsum(kept_states) - 1, -1)
    old = np.arange(space.num_state_actions)
    kept_old = np.ones(space.num_state_actions, dtype=bool)
    kept_old[list(drop_actions)] = False
    pairs = {
        (int(s), int(g)): int(sa)
        for sa, s, g in zip(old, space.action_state, space.action_goal)
        if kept_old[sa]
    }
    for s, g in new_actions:
        pairs.setdefault((int(s), int(g)), -1)
    kept = sorted(
        (state_index[s], state_index[g], sa)
        for (s, g), sa in pairs.items()
        if s != g and kept_states[s] and kept_states[g]
    )
    action_index = np.full(space.num_state_actions, -1)
    for new, (_, _, sa) in enumerate(kept):
        if sa >= 0:
            action_index[sa] = new
    states = np.array([s for s, _, _ in kept], dtype=int)
    goals = np.array([g for _, g, _ in kept], dtype=int)
    edited = StateActionSpace(centres[kept_states], states, goals)
    return SpaceEdit(edited, state_index[: space.num_states], action_index)


def CarryExplorer(explorer: Explorer, edit: SpaceEdit) -> Explorer:
    """``explorer``'s model moved onto ``edit``'s space: each kept state-action keeps its
    counts, intrinsic reward and tries, its outcomes in kept states (prune drops only states no
    action arrived in, so no outcome observed is lost); new state-actions start optimistic
    (Alg. 6's initialisation). The generator carries on."""
    space, state_index, action_index = edit.space, edit.state_index, edit.action_index
    carried = Explorer(space, explorer.config)
    carried.rng = explorer.rng
    old = np.flatnonzero(action_index >= 0)
    new = action_index[old]
    columns = np.flatnonzero(state_index >= 0)
    counts = np.zeros((len(old), space.num_states))
    counts[:, state_index[columns]] = explorer.transitions.counts[np.ix_(old, columns)]
    carried.transitions.counts[new] = counts
    carried.rewards[new] = explorer.rewards[old]
    carried.tries[new] = explorer.tries[old]
    return carried


class SpaceTooLarge(MemoryError):
    """A round planned a space whose learned model would not fit in the memory available."""


# A round holds about this many copies of the outcome counts at once (the model's, the
# carried one and the rows moved into it; a reach learner's then its own and its T).
COUNTS_COPIES = 3


def AvailableMemory(meminfo: str = "/proc/meminfo", cgroup: str = "/sys/fs/cgroup") -> int | None:
    """The bytes this process could still take: Linux's ``MemAvailable`` and free swap, or the
    room left under its cgroup's limit if that is less; None where the system does not say."""
    try:
        lines = pathlib.Path(meminfo).read_text().splitlines()
        info = dict(line.split(":", 1) for line in lines)
        available = 1024 * sum(int(info[key].split()[0]) for key in ("MemAvailable", "SwapFree"))
    except (OSError, KeyError, ValueError):
        return None
    cgroup = pathlib.Path(cgroup)
    try:
        limit = (cgroup / "memory.max").read_text().strip()
        if limit != "max":
            used = int((cgroup / "memory.current").read_text())
            available = min(available, int(limit) - used)
    except (OSError, ValueError):
        pass
    return available


def _CheckModelFits(space: StateActionSpace, done: int) -> None:
    """Refuses a planned ``space`` whose outcome counts (dense: state-actions by states, as
    :class:`~mobee_drake.planning.curiosity.TransitionCounts` holds them), at
    :data:`COUNTS_COPIES` copies, would need more memory than is available, naming the round
    and what would bound it, rather than fail deep in the carry with numpy's bare MemoryError
    (or the machine's OOM killer)."""
    one_copy, available = 8 * space.num_state_actions * space.num_states, AvailableMemory()
    if available is not None and COUNTS_COPIES * one_copy > available:
        raise SpaceTooLarge(
            f"space maintenance after {done} actions (or problem-tries): the round planned "
            f"{space.num_states} states and {space.num_state_actions:,} state-actions, whose "
            f"outcome counts need {one_copy / 2**30:.1f} GiB a copy, and a round holds about "
            f"{COUNTS_COPIES}: more than the {available / 2**30:.1f} GiB available; bound the "
            "space (max_states, or a smaller join_within)"
        )


class Maintenance:
    """One agent's space maintenance: its settings, what it has seen of the agent's chains of
    actions (for ``shortcut``), and every change made so far."""

    def __init__(self, config: MaintenanceConfig, num_states: int):
        for error in config.Errors():
            raise ValueError(f"space maintenance: {error}")
        self.config = config
        # chains[a, c]: how often the agent went a -> b -> c, each action arriving.
        self.chains = np.zeros((num_states, num_states), dtype=int)
        # The start and the end of the last action, if it arrived (else -1, -1).
        self._previous, self._arrival = -1, -1
        # Per state, whether an action started or ended there: kept through `drop`, which
        # forgets the model's counts of the transitions it removes (never pruned).
        self.entered = np.zeros(num_states, dtype=bool)
        # Per state, the tries of the transitions into it that `drop` removed (for `prune`,
        # which counts every try into a state).
        self.dropped_tries = np.zeros(num_states, dtype=int)
        self.changes: list[SpaceChange] = []
        # The (start, goal) centres of every transition dropped (no shortcut brings one back).
        self._dropped: list[tuple[tuple[float, ...], tuple[float, ...]]] = []

    def Observe(self, space: StateActionSpace, state: int, state_action: int, outcome: int):
        """Notes an action's outcome (the agent's model observes it separately). A chain is
        two arriving actions, the second from where the first arrived (a reach, or a new
        problem's target pushing the arm, may leave the robot elsewhere)."""
        self.entered[[state, outcome]] = True
        arrived = outcome == space.action_goal[state_action]
        chained = self._previous >= 0 and state == self._arrival
        if arrived and chained and self._previous != outcome:
            self.chains[self._previous, outcome] += 1
        self._previous, self._arrival = (state, int(outcome)) if arrived else (-1, -1)

    def Due(self, actions_done: int) -> bool:
        """Whether a round is due after ``actions_done`` actions."""
        every, until = self.config.every, self.config.until
        before_the_end = not until or actions_done < until
        return every > 0 and actions_done > 0 and actions_done % every == 0 and before_the_end

    def Plan(
        self, explorer: Explorer, state: int, actions_done: int, favoured=(), visited=()
    ) -> "SpaceEdit | None":
        """A round of every enabled rule on ``explorer``'s space, the robot in ``state``, the
        learner's ``favoured`` states given (for ``develop``) and the states it was in that its
        model does not show (``visited``: never pruned): the edit (None: no change), recorded
        as made (the chain counts follow it). A state whose every action would go (to pruned
        states, with nothing grown beside it) keeps those goals."""
        space = explorer.space
        pruned = []
        if "prune" in self.config.rules:
            kept = [state, *visited, *np.flatnonzero(self.entered)]
            pruned = _Prunable(explorer, self.config, kept, self.dropped_tries)
        while True:
            changes = self._Changes(explorer, pruned, actions_done, favoured)
            if not changes:
                return None
            edit = EditSpace(
                space,
                drop_states=pruned,
                drop_actions=[_ActionOf(space, *c.states) for c in changes if c.rule == "drop"],
                new_centres=[c.centre for c in changes if c.rule in _NEW_STATES],
                new_actions=_NewActions(space, changes, self.config.join_within),
            )
            kept = np.flatnonzero(edit.state_index >= 0)
            actions_out = np.bincount(edit.space.action_state, minlength=edit.space.num_states)
            stranded = kept[actions_out[edit.state_index[kept]] == 0]
            if not len(stranded):
                break
            goals = space.action_goal[np.isin(space.action_state, stranded)]
            kept_pruned = [u for u in pruned if u not in goals]
            if len(kept_pruned) == len(pruned):
                break  # (no pruning strands them: nothing more to keep)
            pruned = kept_pruned
        _CheckModelFits(edit.space, actions_done)
        for change in changes:
            if change.rule == "shortcut":  # (an action now: no chain to count)
                self.chains[change.states] = 0
        for change in changes:
            if change.rule == "drop":
                self.dropped_tries[change.states[1]] += int(
                    explorer.tries[_ActionOf(space, *change.states)]
                )
        self._dropped += [_Pair(space, *c.states) for c in changes if c.rule == "drop"]
        self.chains = _Moved(self.chains, edit.state_index, edit.space.num_states)
        self.entered = _MovedPerState(self.entered, edit.state_index, edit.space.num_states)
        self.dropped_tries = _MovedPerState(
            self.dropped_tries, edit.state_index, edit.space.num_states
        )
        self._previous, self._arrival = (
            int(edit.state_index[s]) if s >= 0 else -1 for s in (self._previous, self._arrival)
        )
        self.changes += changes
        return edit

    def Apply(self, explorer: Explorer, state: int, actions_done: int) -> tuple[Explorer, int]:
        """:meth:`Plan`'s round carried out: the explorer on the new space and the robot's
        state there (the same explorer and state when nothing changes)."""
        edit = self.Plan(explorer, state, actions_done)
        if edit is None:
            return explorer, state
        return CarryExplorer(explorer, edit), int(edit.state_index[state])

    def _Changes(
        self, explorer: Explorer, pruned: list[int], actions_done: int, favoured=()
    ) -> list[SpaceChange]:
        """Every enabled rule's changes, given the states to prune."""
        config, space, rules = self.config, explorer.space, set(self.config.rules)
        changes = [
            SpaceChange(actions_done, "prune", (s,), tuple(space.centres[s].tolist()))
            for s in pruned
        ]
        if "drop" in rules:
            changes += [
                SpaceChange(
                    actions_done, "drop", (int(space.action_state[sa]), int(space.action_goal[sa]))
                )
                for sa in _Droppable(explorer, config, pruned)
            ]
        if "shortcut" in rules:
            changes += [
                SpaceChange(actions_done, "shortcut", pair) for pair in self._Shortcuts(space)
            ]
        if "grow" in rules:  # (from each pruned state to each state with an action into it)
            pairs = [
                (u, r) for u in pruned for r in space.action_state[space.action_goal == u]
                if r not in pruned
            ]  # fmt: skip
            changes += _Halfway(
                space, config, pairs, "grow", actions_done, [], self._Pruned(), len(pruned)
            )
        if "develop" in rules:  # (from each favoured state to each of its neighbours)
            pairs = [
                (g, f) for f in favoured if f not in pruned
                for g in space.action_goal[space.Actions(f)] if g not in pruned
            ]  # fmt: skip
            grown = [c for c in changes if c.rule == "grow"]
            changes += _Halfway(
                space, config, pairs, "develop", actions_done, grown, self._Pruned(), len(pruned)
            )
        return changes

    def ToData(self) -> tuple[np.ndarray, dict]:
        """(the chain counts, the rest as JSON-able data), for a checkpoint."""
        changes = [dc.asdict(c) for c in self.changes]
        previous, arrival = int(self._previous), int(self._arrival)
        entered = np.flatnonzero(self.entered).tolist()
        data = dict(previous=previous, arrival=arrival, changes=changes, entered=entered)
        data["dropped_tries"] = self.dropped_tries.tolist()
        return self.chains.copy(), data | dict(dropped=self._dropped)

    @classmethod
    def FromData(cls, config: MaintenanceConfig, chains, data: dict) -> "Maintenance":
        """The inverse of :meth:`ToData`, under ``config``."""
        maintenance = cls(config, len(chains))
        maintenance.chains = np.array(chains, dtype=int)
        maintenance._previous = data["previous"]
        # (-1 from a checkpoint from before the arrival was kept: the next chain starts afresh)
        maintenance._arrival = data.get("arrival", -1)
        # (none from a checkpoint from before they were kept: the model's counts alone)
        maintenance.entered[data.get("entered", [])] = True
        if "dropped_tries" in data:
            maintenance.dropped_tries = np.array(data["dropped_tries"], dtype=int)
        maintenance.changes = [
            SpaceChange(**dict(c, states=tuple(c["states"]), centre=tuple(c["centre"])))
            for c in data["changes"]
        ]
        # (none from a checkpoint from before they were kept)
        maintenance._dropped = [tuple(map(tuple, pair)) for pair in data.get("dropped", [])]
        return maintenance

    def Continued(self) -> "Maintenance":
        """A copy for a new run on the space this one shaped: what it counted and changed
        carries on, but no chain runs on from the last run's last action."""
        continued = copy.deepcopy(self)
        continued._previous, continued._arrival = -1, -1
        return continued

    def _Pruned(self) -> np.ndarray:
        """(p, d): the centres of the states pruned in earlier rounds (no new state goes
        back there)."""
        return np.array([c.centre for c in self.changes if c.rule == "prune" and c.centre])

    def _Shortcuts(self, space: StateActionSpace) -> list[tuple[int, int]]:
        """The chains taken often enough between states not linked now nor dropped before."""
        linked = set(zip(space.action_state.tolist(), space.action_goal.tolist()))
        often = np.argwhere(self.chains >= self.config.shortcut_after)
        return [
            (int(a), int(c)) for a, c in often
            if (a, c) not in linked and _Pair(space, a, c) not in set(self._dropped)
        ]  # fmt: skip


def ChangesByRule(rules: Iterable[str]) -> dict[str, int]:
    """How many changes each rule made, ``rules`` naming each change's rule."""
    counts = collections.Counter(rules)
    return {rule: counts.get(rule, 0) for rule in RULES}


def _Pair(space: StateActionSpace, state: int, goal: int) -> tuple[tuple[float, ...], ...]:
    """An action's (start, goal) centres: what names it across edits of the space."""
    return tuple(space.centres[state].tolist()), tuple(space.centres[goal].tolist())


def _ActionOf(space: StateActionSpace, state: int, goal: int) -> int:
    actions = space.Actions(state)
    return int(actions[space.action_goal[actions] == goal][0])


def VisitedStates(explorer: Explorer) -> np.ndarray:
    """Per state, whether the model shows the robot there: an action arrived there, or one
    was tried from there (the start)."""
    space, m = explorer.space, explorer.space.num_states
    arrived = ObservedOutcomes(explorer).sum(axis=0) > 0
    return arrived | (np.bincount(space.action_state, weights=explorer.tries, minlength=m) > 0)


def _Prunable(
    explorer: Explorer, config: MaintenanceConfig, kept, dropped_tries: np.ndarray
) -> list[int]:
    """States the robot was never in (:func:`VisitedStates`, nor ``kept``: where it is, and
    where its learner saw it) whose incoming actions were tried ``prune_after`` times (those
    ``drop`` removed included: ``dropped_tries``, per state)."""
    space = explorer.space
    tried_into = np.bincount(space.action_goal, weights=explorer.tries, minlength=space.num_states)
    tried_into += dropped_tries
    prunable = ~VisitedStates(explorer) & (tried_into >= config.prune_after)
    prunable[list(kept)] = False
    return np.flatnonzero(prunable).tolist()


def _Droppable(explorer: Explorer, config: MaintenanceConfig, pruned: list[int]) -> list[int]:
    """Often infeasible transitions of the states that stay, each state keeping an action."""
    space = explorer.space
    infeasible = (explorer.tries >= config.drop_after) & (
        MissShares(explorer) >= config.drop_miss_share
    )
    infeasible &= ~np.isin(space.action_goal, pruned)  # (dropped with their goal anyway)
    dropped = []
    for s in range(space.num_states):
        if s in pruned:
            continue
        actions = space.Actions(s)
        staying = actions[~np.isin(space.action_goal[actions], pruned)]
        bad = staying[infeasible[staying]]
        if len(bad) == len(staying):  # (its best-known action stays)
            bad = bad[np.argsort(MissShares(explorer)[bad], kind="stable")[1:]]
        dropped += bad.tolist()
    return dropped


def _Halfway(
    space: StateActionSpace,
    config: MaintenanceConfig,
    pairs,
    rule: str,
    actions_done: int,
    earlier: list[SpaceChange],
    pruned_before: np.ndarray,
    pruning: int,
) -> list[SpaceChange]:
    """New states halfway along each (far, near) pair of states, as ``rule``'s changes (their
    states: (far, near)), none nearer than ``min_spacing`` to another state (old, ``earlier``'s
    or new) or to a state pruned in an earlier round (``pruned_before``), and only while the
    space, less the ``pruning`` states this round prunes, has fewer than ``max_states``."""
    centres, made = space.centres, []
    if len(pruned_before):
        centres = np.vstack([centres, pruned_before])
    for far, near in pairs:
        placed = earlier + made
        size = space.num_states - pruning + len(placed)
        if config.max_states and size >= config.max_states:
            break
        middle = (centres[near] + centres[far]) / 2
        others = np.vstack([centres, [c.centre for c in placed]]) if placed else centres
        if np.linalg.norm(others - middle, axis=1).min() >= config.min_spacing:
            made.append(
                SpaceChange(actions_done, rule, (int(far), int(near)), tuple(middle.tolist()))
            )
    return made


def _NewActions(
    space: StateActionSpace, changes: list[SpaceChange], join_within: float
) -> list[tuple[int, int]]:
    """The shortcuts, and each new state joined both ways to every state (old or new) within
    ``join_within`` times the length of the action it grew from."""
    pairs = [c.states for c in changes if c.rule == "shortcut"]
    grown = [c for c in changes if c.rule in _NEW_STATES]
    centres = np.vstack([space.centres] + [[c.centre] for c in grown])
    for i, change in enumerate(grown):
        new = space.num_states + i
        u, r = change.states
        reach = join_within * np.linalg.norm(space.centres[u] - space.centres[r]) + 1e-9
        near = np.flatnonzero(np.linalg.norm(centres - centres[new], axis=1) <= reach)
        pairs += [(new, int(o)) for o in near if o != new] + [(int(o), new) for o in near]
    return pairs


def _MovedPerState(values: np.ndarray, state_index: np.ndarray, num_states: int) -> np.ndarray:
    """A per-state array's values of the states that stay, in their new indices (new states:
    zero)."""
    moved = np.zeros(num_states, dtype=values.dtype)
    kept = np.flatnonzero(state_index >= 0)
    moved[state_index[kept]] = values[kept]
    return moved


def _Moved(chains: np.ndarray, state_index: np.ndarray, num_states: int) -> np.ndarray:
    """The chain counts of the states that stay, in their new indices (new states: none)."""
    moved = np.zeros((num_states, num_states), dtype=int)
    kept = np.flatnonzero(state_index >= 0)
    moved[np.ix_(state_index[kept], state_index[kept])] = chains[np.ix_(kept, kept)]
    return moved
