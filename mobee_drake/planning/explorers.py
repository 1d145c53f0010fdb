"""Agents that explore a state-action space (dissertation Alg. 8, ch. 7.2.1).

Every agent learns the same model: transition counts initialised optimistically (each action
observed once failing, leaving the agent where it was, and once succeeding; the 60-40
initialisation of Table 7.1 observes one more success) and the intrinsic reward of each
state-action, the last observation's information gain (Alg. 6). Agents differ in how they choose
the next action: their strategy (see :mod:`mobee_drake.planning.strategies`). A planner keeps
learning from outcomes too.

Every agent draws from its own seeded generator; ties of the greedy choice are broken at random
too, so a run is reproducible from its seed.
"""

import copy
import dataclasses as dc
import json
import math
import pathlib

import numpy as np
from scipy import sparse

from mobee_drake.atomic_files import CurrentGeneration
from mobee_drake.planning.curiosity import TransitionCounts
from mobee_drake.planning.state_space import StateActionSpace
from mobee_drake.planning.strategies import STRATEGIES
from mobee_drake.planning.value_iteration import VALUE_TIE, ValueIteration

INITIALIZATIONS = {"50-50": 1, "60-40": 2}  # successes observed after the one failure


@dc.dataclass
class ExplorerConfig:
    strategy: str = "curious"
    # "50-50" (Table 6.1) or "60-40" (Table 7.1).
    initialization: str = "50-50"
    gamma: float = 0.9
    delta: float = 1e-3
    # The state the "planner" strategy heads for.
    goal_state: int = -1

    def Errors(self) -> list[str]:
        """What is wrong with the settings that their types cannot say (empty: nothing)."""
        errors = []
        if self.strategy not in STRATEGIES:
            errors.append(f"strategy must be one of {', '.join(STRATEGIES)}, got '{self.strategy}'")
        if self.initialization not in INITIALIZATIONS:
            errors.append(
                f"initialization must be {' or '.join(INITIALIZATIONS)}, got "
                f"'{self.initialization}'"
            )
        if not (math.isfinite(self.gamma) and 0 <= self.gamma < 1):
            errors.append(f"gamma must be in [0, 1), got {self.gamma}")
        if not (math.isfinite(self.delta) and self.delta > 0):
            errors.append(f"delta must be > 0, got {self.delta}")
        return errors


class Explorer:
    """One agent exploring one state-action space, its generator seeded with ``seed``."""

    def __init__(
        self, space: StateActionSpace, config: ExplorerConfig | None = None, seed: int = 0
    ):
        config = config or ExplorerConfig()
        for error in config.Errors():
            raise ValueError(error)
        if STRATEGIES[config.strategy].seeks_goal and not 0 <= config.goal_state < space.num_states:
            raise ValueError(
                f"strategy '{config.strategy}' needs a goal_state in 0..{space.num_states - 1}, "
                f"got {config.goal_state}"
            )
        self.space, self.config = space, config
        self.rng = np.random.default_rng(seed)
        self.transitions = TransitionCounts(space.num_state_actions, space.num_states)
        self.rewards = np.zeros(space.num_state_actions)
        self.tries = np.zeros(space.num_state_actions, dtype=int)
        for sa, (s, g) in enumerate(zip(space.action_state, space.action_goal)):
            self.rewards[sa] = self.transitions.Observe(sa, s)
            for _ in range(INITIALIZATIONS[config.initialization]):
                self.rewards[sa] = self.transitions.Observe(sa, g)

    @property
    def seeks_goal(self) -> bool:
        """Whether its strategy heads for its ``goal_state`` (see :mod:`.strategies`)."""
        return STRATEGIES[self.config.strategy].seeks_goal

    def Copy(self) -> "Explorer":
        """An independent copy (model, tries and generator), sharing the space and config."""
        twin = copy.copy(self)
        twin.rng = copy.deepcopy(self.rng)
        twin.transitions = copy.deepcopy(self.transitions)
        twin.rewards, twin.tries = self.rewards.copy(), self.tries.copy()
        return twin

    def Values(self) -> tuple[np.ndarray, np.ndarray]:
        """V(s, a) and V(s) by value iteration on the current model (Alg. 7)."""
        return ValueIteration(
            self.transitions.Probabilities(),
            self.rewards,
            self.space.action_state,
            self.space.num_states,
            self.config.gamma,
            self.config.delta,
        )

    def ChooseAction(self, state: int) -> int:
        """The state-action to try next from ``state``."""
        actions = self.space.Actions(state)
        if len(actions) == 0:
            raise ValueError(f"state {state} has no actions")
        scores = STRATEGIES[self.config.strategy].Scores(self, actions)
        best = actions[np.flatnonzero(scores >= scores.max() - VALUE_TIE)]
        return int(self.rng.choice(best))

    def Observe(self, state_action: int, outcome: int) -> float:
        """Records the outcome of a tried state-action; returns the intrinsic reward (Alg. 6)."""
        self.tries[state_action] += 1
        self.rewards[state_action] = self.transitions.Observe(state_action, outcome)
        return self.rewards[state_action]


def _InitialCounts(explorer: Explorer, rows: np.ndarray, columns: np.ndarray) -> np.ndarray:
    """The counts of Alg. 6's initialisation at (``rows``, ``columns``): each state-action
    once in its own state, then in its goal (each first observation of an outcome counts 2:
    the new bin's 1 and itself)."""
    space = explorer.space
    goal = 1.0 + INITIALIZATIONS[explorer.config.initialization]
    own = np.where(columns == space.action_state[rows], 2.0, 0.0)
    return np.where(columns == space.action_goal[rows], goal, own)


def ObservedOutcomes(explorer: Explorer) -> sparse.csr_array:
    """(state-actions, states), sparse: the outcomes observed since the initialisation, stored
    where a count or the initialisation is not zero (none elsewhere)."""
    counts, space = explorer.transitions.counts, explorer.space
    every = np.arange(space.num_state_actions)
    rows, columns = np.nonzero(counts)
    cells = np.unique(
        np.concatenate([rows, every, every]) * counts.shape[1]
        + np.concatenate([columns, space.action_state, space.action_goal])
    )
    rows, columns = np.divmod(cells, counts.shape[1])
    bins, initial = counts[rows, columns], _InitialCounts(explorer, rows, columns)
    new_bins = (bins > 0) & (initial == 0)  # (each began with a 1 of its own)
    observed = np.rint(bins - initial - new_bins).astype(int)
    return sparse.csr_array((observed, (rows, columns)), shape=counts.shape)


def MissShares(explorer: Explorer) -> np.ndarray:
    """Per state-action, the share of its tries that did not arrive in its goal (0: untried)."""
    space = explorer.space
    hits = ObservedOutcomes(explorer)[np.arange(space.num_state_actions), space.action_goal]
    return np.where(explorer.tries > 0, 1 - hits / np.maximum(explorer.tries, 1), 0.0)


def ExplorerToArrays(explorer: Explorer) -> tuple[dict[str, np.ndarray], dict]:
    """The learned model as arrays (counts, rewards, tries, the space) and the rest as JSON-able
    data (configuration, generator state), for saving and exact resuming."""
    space = explorer.space
    arrays = dict(
        counts=explorer.transitions.counts,
        rewards=explorer.rewards,
        tries=explorer.tries,
        centres=space.centres,
        action_state=space.action_state,
        action_goal=space.action_goal,
    )
    return arrays, dict(
        config=dc.asdict(explorer.config), generator=explorer.rng.bit_generator.state
    )


def ExplorerFromArrays(
    arrays, data: dict, config: ExplorerConfig | None = None, seed: int = 0
) -> Explorer:
    """The inverse of :func:`ExplorerToArrays`; with ``config``, the saved model under another
    configuration (e.g. a planner reusing what an explorer learned) with a generator seeded with
    ``seed``."""
    space = StateActionSpace(
        np.asarray(arrays["centres"]),
        np.asarray(arrays["action_state"]),
        np.asarray(arrays["action_goal"]),
    )
    explorer = Explorer(space, config or ExplorerConfig(**data["config"]), seed)
    explorer.transitions.counts[...] = arrays["counts"]
    explorer.rewards[...] = arrays["rewards"]
    explorer.tries[...] = arrays["tries"]
    if config is None:
        explorer.rng.bit_generator.state = data["generator"]
    return explorer


def LoadAgentModel(folder: str, name: str, config: ExplorerConfig, seed: int = 0) -> Explorer:
    """Agent ``name``'s model from a checkpoint folder (its newest generation, or the folder's
    own files), under ``config``, its generator seeded with ``seed``.

    Raises:
        ValueError: naming the file, when the folder has no model for that agent.
    """
    base = (CurrentGeneration(folder) or pathlib.Path(folder)) / name
    for suffix in (".npz", ".json"):
        if not base.with_suffix(suffix).is_file():
            raise ValueError(f"{base.with_suffix(suffix)}: no saved model of agent '{name}'")
    return ExplorerFromArrays(
        np.load(base.with_suffix(".npz")),
        json.loads(base.with_suffix(".json").read_text()),
        config,
        seed,
    )
