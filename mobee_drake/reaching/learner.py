"""The reach learner (dissertation ch. 8.1-8.3): problem-tries over a learned MDP with reaches.

The state-action space is the learned MDP's (ch. 6-7) plus one *reaching* state-action per state,
numbered after the transitions (reach of state s = ``num_transitions + s``; with the rank-3
lattice of ch. 7.2, 432 + s, the source's numbering: its favourite reaches 489 and 509 start from
states 57 and 77). The MDP's transition probabilities plan the moves and, as in ch. 8.1, are not
updated; a reach ends the policy (its row of T is empty), so its value is its reward.

Rewards per problem (a reach target x*) come from the state-actions' histories (eq. 8.2):
transitions predict eq. 8.1 (0 when untried); reaches predict by strategy (ch. 8.3.2; see
:mod:`mobee_drake.reaching.strategies`).

A *problem-try* (ch. 8.3.1): value iteration on the problem's rewards, the greedy state-action
of the robot's state, recorded in its history with the prediction of eq. 8.1 or 8.5 made before
it ran and the reward it got: a reach gets eq. 8.4 and ends the try; a transition gets 0, or -10
when it did not reach a state of higher value (ch. 8.1). The rewards are predicted anew before
every action, so a transition that just failed is avoided at once. After ``max_actions`` actions
without a reach the try times out.

Exploration (ch. 8.3.2) picks the least-tried problem (random among ties). Evaluations (ch. 8.3.3)
put the robot in a random state (a reward of 1 on every transition into it), then try the
shuffled problems greedily (eq. 8.1 and 8.5); an evaluation's summed reward (ch. 8.3.1, 8.3.3)
counts the reaches' rewards and the -10 of every failed transition (each :class:`TryResult` keeps
both). Evaluations never write to the learner's histories. Choice where the source is silent:
during an evaluation problem-try, its own records (a failed transition's -10) are kept in a
scratch copy of the histories for the rest of that try only, so the greedy policy does not
repeat a failing transition until it times out.

Beyond the source (ch. 9.4.1, ``learn_mdp``): the MDP is learned at the same time as the reaches,
its outcome counts updated by the transitions (from the optimistic initialisation of ch. 6, or from
a model learned before). A transition that fails to climb the value function is then ambiguous: the
robot's own MDP may be wrong, or the problem's target may be in the way. MoBeE's fields tell them
apart: if they felt a workspace object during the transition (self-collisions feel the robot's own
body), it is the problem's: -10 in its history and no model update; otherwise it is a model update
and records 0. Choice where the source is silent: a transition that felt an object but did climb
records 0 and does not update the model either (the object disturbed it, so its outcome says
nothing about the robot alone).

The greedy policy takes, among state-actions of equal value, the first in state-action order
(a state's transitions, then its reach: an argmax), or with ``tie_break="random"`` one drawn from
the try's generator (the source is silent).

Readings where the source is ambiguous (issue 33), each a named option with the reference first:

- ``plateau_rule``, when a transition failed (ch. 8.1: whenever the state it ends in has no higher
  value than the state it left, higher by more than rounding, ``VALUE_TIE``): ``strict``, that
  rule as stated, so a move across a plateau of equal value fails even when it arrives where it
  was sent; ``arrival``, a transition that ends in the state it was sent to never fails (the
  rule's purpose, 8.1: to catch moves the target blocks);
  ``random-tie``, the strict rule with ties of value broken at random (what ``tie_break="random"``
  does), so a plateau's reach is chosen as often as its moves.
- ``evaluation_history``, what an evaluation remembers of its own failures (ch. 8.3.3 is silent):
  ``per-problem``, nothing beyond its problem-try (each gets a scratch copy of the histories),
  or ``per-evaluation``, the records of the transitions that failed in its earlier problem-tries
  (added to each later copy), so eq. 8.1 predicts their failure on the next problems too; the
  reaches' rewards stay within their problem-try either way.

The learner draws from its own seeded generator and keeps a log of every action it took, from
which its histories are rebuilt exactly (checkpoints, :meth:`ReachLearner.LoadArrays`).
"""

import dataclasses as dc
import json
from typing import Protocol

import numpy as np
from scipy import sparse

from mobee_drake.planning.curiosity import SetProbabilityRow, TransitionCounts
from mobee_drake.planning.space_maintenance import SpaceEdit
from mobee_drake.planning.state_space import StateActionSpace
from mobee_drake.planning.value_iteration import VALUE_TIE, ValueIteration
from mobee_drake.reaching.goals import GoalBabbler, ReachGoalsConfig
from mobee_drake.reaching.predictors import (
    PredictorConfig,
    ReachReward,
    RewardHistories,
    TransitionReward,
)
from mobee_drake.reaching.strategies import REACH_STRATEGIES

# How the greedy policy picks among state-actions of equal value: the first in state-action order
# (the state's transitions by index, then its reach), or one drawn at random.
TIE_BREAKS = ("first", "random")
# When a transition fails (see the module's docstring).
PLATEAU_RULES = ("strict", "arrival", "random-tie")
# What an evaluation's problem-tries remember of each other (see the module's docstring).
EVALUATION_HISTORIES = ("per-problem", "per-evaluation")


@dc.dataclass
class ReachLearningConfig:
    """The reach learner's settings (ch. 8.3-8.4: gamma 0.9, 10 actions per problem-try)."""

    strategy: str = "intrinsic"
    gamma: float = 0.9
    # Value iteration stops when no V(s, a) changes by this much in a sweep.
    delta: float = 1e-4
    max_actions: int = 10
    seed: int = 0
    # The source's weighted averages (eq. 8.1-8.7) or a Gaussian process (ch. 8.5).
    predictor: PredictorConfig = dc.field(default_factory=PredictorConfig)
    # Whether the MDP is learned with the reaches (ch. 9.4.1) or fixed (ch. 8.1).
    learn_mdp: bool = False
    # The goal_babbling strategy's goal selection.
    goals: ReachGoalsConfig = dc.field(default_factory=ReachGoalsConfig)
    # One of TIE_BREAKS (the source is silent; "first" is what an argmax over the state's
    # state-actions does, transitions before the reach).
    tie_break: str = "first"
    # One of PLATEAU_RULES and of EVALUATION_HISTORIES (the source is ambiguous or silent).
    plateau_rule: str = "strict"
    evaluation_history: str = "per-problem"

    def EffectiveTieBreak(self) -> str:
        """How ties of value are broken: ``tie_break``, or "random" under ``random-tie``."""
        return "random" if self.plateau_rule == "random-tie" else self.tie_break

    def Validate(self) -> None:
        self.predictor.Validate()
        self.goals.Validate()
        for name, value, allowed in (
            ("tie_break", self.tie_break, TIE_BREAKS),
            ("plateau_rule", self.plateau_rule, PLATEAU_RULES),
            ("evaluation_history", self.evaluation_history, EVALUATION_HISTORIES),
        ):
            if value not in allowed:
                raise ValueError(f"unknown {name} '{value}'; choose one of " + ", ".join(allowed))
        if self.plateau_rule == "random-tie" and self.tie_break == "random":
            raise ValueError(
                "plateau_rule 'random-tie' breaks ties at random already; keep tie_break 'first'"
            )
        if self.predictor.eq81 == "prose" and self.predictor.kind != "weighted":
            raise ValueError("eq81 'prose' is a reading of the weighted average (eq. 8.1) only")
        if self.strategy not in REACH_STRATEGIES:
            raise ValueError(
                f"unknown reach-learning strategy '{self.strategy}'; strategies "
                "are " + ", ".join(REACH_STRATEGIES)
            )
        if not 0 <= self.gamma < 1:
            raise ValueError(f"gamma must be in [0, 1), got {self.gamma}")
        if self.max_actions < 1:
            raise ValueError(f"max_actions must be >= 1, got {self.max_actions}")


class Robot(Protocol):
    """What the learner needs of a robot (see :mod:`mobee_drake.reaching.robot`)."""

    def SetProblem(self, target: np.ndarray) -> None:
        """Puts the problem's target object into the world (replacing the previous one)."""

    def EndProblem(self) -> None:
        """Takes the problem's target out of the world, if it is there (a reach does it)."""

    def State(self) -> int:
        """The MDP state of the robot's configuration."""

    def Transition(self, goal: int) -> int:
        """Moves toward state ``goal``'s centre; returns the state where the robot settled."""

    def Reach(self, target: np.ndarray) -> np.ndarray:
        """Reaches for ``target`` from the current state; returns where the marker got to."""

    def FeltObject(self) -> bool:
        """Whether MoBeE's fields felt a workspace object (not the robot's own body) during the
        last action; asked only when the MDP is learned with the reaches."""

    def MarkerPosition(self) -> np.ndarray:
        """Where the reaching marker is now (asked by the goal_babbling strategy)."""

    def LearningFrame(self, target: np.ndarray) -> np.ndarray:
        """``target`` (world) in the frame the learner learns in, now: the shoulder's, placed as
        it was with the torso at home (ch. 9.4.2: the learning happens in the shoulder's frame,
        so a torso that moves does not disturb it). While the torso stays home, ``target``."""


@dc.dataclass
class TryResult:
    """What one problem-try did."""

    problem: int
    actions: int
    # The reach's reward, or None when the try timed out.
    reward: float | None
    # The reaching state-action tried, or -1.
    reach: int
    failed_transitions: int
    # Where the reach put the marker, or None when the try timed out.
    reached: list[float] | None = None


# Columns of the action log: problem-try, problem (goal_babbling: the problem nearest the goal),
# state-action, state before, state after, estimate, reward, target (or goal) x, y, z in the
# learning frame (Robot.LearningFrame: the world's, while the torso stays home).
LOG_COLUMNS = (
    "try",
    "problem",
    "state_action",
    "state",
    "outcome",
    "estimate",
    "reward",
    "x",
    "y",
    "z",
)


def SortedTransitions(probabilities: np.ndarray, order: np.ndarray) -> sparse.csr_array:
    """T as the reach learner's value iteration reads it, sparse: the transitions' rows
    ``probabilities`` (k, m), then one empty row per state (a reach ends the policy), in
    ``order`` (its state-actions sorted by state)."""
    m = probabilities.shape[1]
    rows = sparse.vstack([sparse.csr_array(probabilities), sparse.csr_array((m, m))])
    return sparse.csr_array(rows[order])


def _WithDefaults(saved: dict, defaults: dict) -> dict:
    """``saved`` (a configuration as JSON data) with every key it lacks taken from
    ``defaults`` (the same configuration's defaults), nested mappings included."""
    filled = dict(saved)
    for key, value in defaults.items():
        if key not in filled:
            filled[key] = value
        elif isinstance(value, dict) and isinstance(filled[key], dict):
            filled[key] = _WithDefaults(filled[key], value)
    return filled


class ReachLearner:
    """Learns which pre-reach states suit which targets (ch. 8)."""

    def __init__(
        self,
        space: StateActionSpace,
        transition_counts: np.ndarray,
        targets: np.ndarray,
        config: ReachLearningConfig | None = None,
    ):
        """``transition_counts`` are the MDP's outcome counts per state-action (as
        :class:`~mobee_drake.planning.curiosity.TransitionCounts` keeps them; normalised rows give
        T), copied: with ``learn_mdp`` the learner's own transitions add to them."""
        self.config = config = config or ReachLearningConfig()
        config.Validate()
        self.targets = np.asarray(targets, dtype=float)
        self._SetSpace(space, transition_counts)
        self.histories = RewardHistories(self.reaching, config.predictor)
        self.problem_tries = np.zeros(len(self.targets), dtype=int)
        self.rng = np.random.default_rng(config.seed)
        self.log: list[tuple] = []
        self.babbler = (
            GoalBabbler(self.targets, config.goals)
            if REACH_STRATEGIES[config.strategy].babbles_goals
            else None
        )

    def _SetSpace(self, space: StateActionSpace, transition_counts: np.ndarray) -> None:
        """The state-action space and the MDP's outcome counts on it (copied)."""
        m, k = space.num_states, space.num_state_actions
        if transition_counts.shape != (k, m):
            raise ValueError(f"transition counts must be ({k}, {m}), got {transition_counts.shape}")
        self.space, self.num_transitions = space, k
        self.model = TransitionCounts(k, m)
        self.model.counts[...] = transition_counts
        # The state of every state-action (transitions, then one reach per state); a reach's row
        # of T is empty: a reach ends the policy.
        self.action_state = np.concatenate([space.action_state, np.arange(m)])
        self.reaching = np.arange(k + m) >= k
        # Value iteration wants the state-actions sorted by state: T in that order, and where
        # each state-action went.
        self._order = np.argsort(self.action_state, kind="stable")
        self._rank = np.argsort(self._order)
        self._RefreshT()

    def Reshape(self, edit: SpaceEdit, transition_counts: np.ndarray) -> None:
        """Moves the learner onto a reshaped space (ch. 9.4.5, ``edit`` as
        :func:`~mobee_drake.planning.space_maintenance.EditSpace` gives it), the MDP's counts
        there being ``transition_counts``. Every state-action that stays (a transition, or the
        reach of a state that stays) keeps its history under its new number; the log's
        state-actions and states are renumbered (-1: dropped), so that the histories rebuilt
        from it (:meth:`LoadArrays`) are these."""
        space, state_index = edit.space, edit.state_index
        reaches = np.where(state_index >= 0, space.num_state_actions + state_index, -1)
        new_index = np.concatenate([edit.action_index, reaches])
        self._SetSpace(space, transition_counts)
        self.histories = self.histories.Moved(new_index, self.reaching)

        def Moved(index: np.ndarray, old: int) -> int:
            return int(index[old]) if old >= 0 else -1  # (dropped by an earlier round: stays)

        self.log = [
            (t, problem, Moved(new_index, sa), Moved(state_index, s), Moved(state_index, o), *rest)
            for t, problem, sa, s, o, *rest in self.log
        ]

    def PutOnSpace(self, space: StateActionSpace, transition_counts: np.ndarray) -> None:
        """Puts a learner that has not tried anything yet on ``space`` (a run's reshaped space,
        before its checkpoint's log is loaded), the MDP's counts there being
        ``transition_counts``."""
        if self.log:
            raise ValueError("PutOnSpace: the learner has tried already; Reshape moves its history")
        self._SetSpace(space, transition_counts)
        self.histories = RewardHistories(self.reaching, self.config.predictor)

    @property
    def num_state_actions(self) -> int:
        return len(self.action_state)

    def Reach(self, state: int) -> int:
        """The reaching state-action of ``state``."""
        return self.num_transitions + state

    def Actions(self, state: int) -> np.ndarray:
        return np.append(self.space.Actions(state), self.Reach(state))

    # ------------------------------------------------------------------------------------------
    # Planning.

    def Rewards(
        self, target: np.ndarray, strategy: str, histories=None, drawn: int = -1
    ) -> np.ndarray:
        """The problem's rewards: eq. 8.1 on transitions, ``strategy``'s predictions on reaches
        (``drawn``: what the strategy drew at the start of the try)."""
        histories = self.histories if histories is None else histories
        reaches = np.arange(self.num_transitions, self.num_state_actions)
        return np.concatenate(
            [
                histories.PredictEach(range(self.num_transitions), target),
                REACH_STRATEGIES[strategy].ReachRewards(histories, target, reaches, drawn),
            ]
        )

    def Values(self, rewards: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """V(s, a) (in state-action numbering) and V(s) by value iteration (Alg. 7)."""
        q_sorted, v = ValueIteration(
            self._T_sorted,
            rewards[self._order],
            self.action_state[self._order],
            self.space.num_states,
            self.config.gamma,
            self.config.delta,
        )
        q = np.empty_like(q_sorted)
        q[self._order] = q_sorted
        return q, v

    def _Greedy(self, q: np.ndarray, state: int, rng) -> int:
        """The greedy state-action of ``state``; among equal values (``VALUE_TIE``) the first
        (``tie_break`` "first", no draw from ``rng``) or a random one."""
        actions = self.Actions(state)
        scores = q[actions]
        best = actions[scores >= scores.max() - VALUE_TIE]
        return int(best[0] if self.config.EffectiveTieBreak() == "first" else rng.choice(best))

    # ------------------------------------------------------------------------------------------
    # Acting.

    def _RefreshT(self, state_action: int | None = None) -> None:
        """T from the model's counts in value iteration's order, sparse (a row holds the
        outcomes its transition observed; a reach's row is empty): every row, or after an
        observation of ``state_action`` its row alone."""
        if state_action is not None:
            SetProbabilityRow(
                self._T_sorted, self._rank[state_action], self.model.counts[state_action]
            )
            return
        self._T_sorted = SortedTransitions(self.model.Probabilities(), self._order)

    def _Try(
        self,
        robot: Robot,
        problem: int,
        target: np.ndarray,
        strategy: str,
        histories: RewardHistories,
        rng,
        learn: bool,
        failures: list | None = None,
    ) -> TryResult:
        """One problem-try for ``target``; ``learn`` says whether it is exploration (logged; with
        ``learn_mdp`` the model learns) or an evaluation (``histories`` a scratch copy; the
        records of its failed transitions are appended to ``failures``, if given)."""
        robot.SetProblem(target)
        drawn = REACH_STRATEGIES[strategy].StartTry(self.space.num_states, rng)
        failed = 0
        for action in range(1, self.config.max_actions + 1):
            seen = robot.LearningFrame(target)  # (the shoulder may have moved)
            q, v = self.Values(self.Rewards(seen, strategy, histories, drawn))
            state = robot.State()
            sa = self._Greedy(q, state, rng)
            estimate = histories.Predict(sa, seen)  # eq. 8.1 or 8.5, before it runs
            if self.reaching[sa]:
                reached = robot.Reach(target)
                reward = ReachReward(reached, target, self.config.predictor.distance_unit)
                outcome = state
            else:
                sent_to = int(self.space.action_goal[sa])
                outcome = robot.Transition(sent_to)
                arrived = self.config.plateau_rule == "arrival" and outcome == sent_to
                reward = 0.0 if arrived else TransitionReward(v[state], v[outcome])
                if self.config.learn_mdp and not robot.FeltObject():  # ch. 9.4.1: the model's
                    reward = 0.0
                    if learn:
                        self.model.Observe(sa, outcome)
                        self._RefreshT(sa)
                failed += reward < 0
            histories.Record(sa, seen, estimate, reward)
            if failures is not None and not self.reaching[sa] and reward < 0:
                failures.append((sa, seen, estimate, reward))
            if learn:
                self.log.append(
                    (
                        int(self.problem_tries.sum()),
                        problem,
                        sa,
                        state,
                        outcome,
                        estimate,
                        reward,
                        *seen,
                    )
                )
            if self.reaching[sa]:
                return TryResult(problem, action, reward, sa, failed, [float(c) for c in reached])
        robot.EndProblem()  # (out of actions: the try is over, as after a reach)
        return TryResult(problem, self.config.max_actions, None, -1, failed)

    def Explore(self, robot: Robot) -> TryResult:
        """One exploratory problem-try: on the least-tried problem (ch. 8.3.2), or, goal
        babbling, toward a goal of SAGG-RIAC's (counted as a try of the problem nearest it)."""
        if self.babbler is None:
            least = np.flatnonzero(self.problem_tries == self.problem_tries.min())
            problem = int(self.rng.choice(least))
            return self._Explore(robot, problem, self.targets[problem], self.config.strategy)
        goal = self.babbler.Select(self.rng)
        start = robot.MarkerPosition()
        problem = int(np.argmin(np.linalg.norm(self.targets - goal, axis=1)))
        result = self._Explore(robot, problem, goal, "greedy")
        self.babbler.Record(goal, start, result.reached)
        return result

    def _Explore(self, robot: Robot, problem: int, target: np.ndarray, strategy: str) -> TryResult:
        result = self._Try(robot, problem, target, strategy, self.histories, self.rng, learn=True)
        self.problem_tries[problem] += 1
        return result

    def Evaluate(self, robot: Robot, seed, targets: np.ndarray | None = None) -> list[TryResult]:
        """One exploitation evaluation (ch. 8.3.3) with its own generator ``seed``: a random start
        state, then every problem, shuffled, greedily; the learner's state is not changed. The
        problems are the learner's targets, or ``targets`` (one per problem) if given."""
        targets = self.targets if targets is None else np.asarray(targets, dtype=float)
        rng = np.random.default_rng(seed)
        start = int(rng.integers(self.space.num_states))
        order = rng.permutation(len(targets))
        # Ties draw from a generator of their own, so that the start and the order are the same
        # for every learner evaluated with this seed (paired runs), however the walk goes.
        ties = np.random.default_rng(np.random.SeedSequence(seed).spawn(1)[0])
        into_start = np.append(
            (self.space.action_goal == start).astype(float), np.zeros(self.space.num_states)
        )
        q, _ = self.Values(into_start)
        q[self.reaching] = -np.inf  # (the walk moves; where no move leads there, a reach ties)
        for _ in range(self.config.max_actions):
            state = robot.State()
            if state == start:
                break
            robot.Transition(int(self.space.action_goal[self._Greedy(q, state, ties)]))
        # Per evaluation, the failed transitions of its earlier problem-tries (their records).
        failures = None if self.config.evaluation_history == "per-problem" else []
        results = []
        for problem in order:
            histories = self.histories.Copy()
            for record in failures or ():
                histories.Record(*record)
            results.append(
                self._Try(
                    robot,
                    int(problem),
                    targets[problem],
                    "greedy",
                    histories,
                    ties,
                    learn=False,
                    failures=failures,
                )
            )
        return results

    # ------------------------------------------------------------------------------------------
    # Saving and resuming.

    def ToArrays(self) -> tuple[dict[str, np.ndarray], dict]:
        """The learner's state as arrays (the log, tries and, with ``learn_mdp``, the MDP's
        counts) and JSON-able data (configuration, generator state)."""
        arrays = dict(
            log=np.array(self.log, dtype=float).reshape(-1, len(LOG_COLUMNS)),
            problem_tries=self.problem_tries,
        )
        if self.config.learn_mdp:
            arrays["transition_counts"] = self.model.counts
        if self.babbler is not None:
            arrays.update(self.babbler.ToArrays())
        return arrays, dict(config=dc.asdict(self.config), generator=self.rng.bit_generator.state)

    def LoadArrays(self, arrays, data: dict) -> None:
        """Restores :meth:`ToArrays`' state into this (fresh) learner: the histories are rebuilt
        from the log, record by record; a learned MDP is restored from its counts."""
        if self.log:
            raise ValueError("load a saved state into a fresh learner only")
        saved, mine = (json.loads(json.dumps(c)) for c in (data["config"], dc.asdict(self.config)))
        # A key added after the save (a new option) counts at its default value.
        defaults = json.loads(json.dumps(dc.asdict(ReachLearningConfig())))
        saved = _WithDefaults(saved, defaults)
        if saved != mine:
            raise ValueError(f"the saved learner's configuration {saved} is not this one's {mine}")
        for row in np.asarray(arrays["log"]):
            entry = (
                int(row[0]),
                int(row[1]),
                int(row[2]),
                int(row[3]),
                int(row[4]),
                float(row[5]),
                float(row[6]),
                *map(float, row[7:]),
            )
            self.log.append(entry)
            if entry[2] >= 0:  # (-1: a state-action a reshaped space dropped)
                self.histories.Record(entry[2], np.array(entry[7:]), entry[5], entry[6])
        self.problem_tries[...] = arrays["problem_tries"]
        if self.config.learn_mdp:
            self.model.counts[...] = arrays["transition_counts"]
            self._RefreshT()
        if self.babbler is not None:
            self.babbler.LoadArrays(arrays)
        self.rng.bit_generator.state = data["generator"]
