"""How the reach learner explores (ch. 8.3.2): strategies as small classes in a registry.

A strategy predicts the reward of every reaching state-action for a problem-try's target; the
learner plans on those predictions (transitions always predict eq. 8.1). The shipped ones:

- ``random``: 1 on one reaching state-action drawn at the start of the problem-try, 0 on the rest;
- ``greedy`` (greedy optimistic): eq. 8.5;
- ``intrinsic`` (intrinsically motivated): eq. 8.7, the expected error of eq. 8.5's prediction;
- ``goal_babbling`` (beyond the source, :mod:`mobee_drake.reaching.goals`): eq. 8.5 toward a goal
  that SAGG-RIAC chose in the targets' workspace, instead of the least-tried problem.

A user adds one without editing the package: ``RegisterReachStrategy("mine", Mine())``, then
``ReachLearningConfig(strategy="mine")``.
"""

from typing import Protocol

import numpy as np


class ReachStrategy(Protocol):
    # Whether SAGG-RIAC chooses the targets (else the least-tried problem is tried).
    babbles_goals: bool

    def StartTry(self, num_states: int, rng: np.random.Generator) -> int:
        """What the strategy draws at the start of a problem-try (-1: nothing)."""

    def ReachRewards(self, histories, target: np.ndarray, reaches: np.ndarray, drawn: int):
        """The predicted rewards of the reaching state-actions ``reaches`` for ``target``."""


class Greedy:
    babbles_goals = False

    def StartTry(self, num_states: int, rng: np.random.Generator) -> int:
        return -1

    def ReachRewards(self, histories, target, reaches, drawn) -> np.ndarray:
        return histories.PredictEach(reaches, target)  # eq. 8.5


class Intrinsic(Greedy):
    def ReachRewards(self, histories, target, reaches, drawn) -> np.ndarray:
        return np.array([histories.PredictIntrinsic(sa, target) for sa in reaches])  # eq. 8.7


class Random(Greedy):
    def StartTry(self, num_states: int, rng: np.random.Generator) -> int:
        return int(rng.integers(num_states))  # the state whose reach gets the reward

    def ReachRewards(self, histories, target, reaches, drawn) -> np.ndarray:
        return (np.arange(len(reaches)) == drawn).astype(float)


class GoalBabbling(Greedy):
    babbles_goals = True


REACH_STRATEGIES: dict[str, ReachStrategy] = {
    "random": Random(),
    "greedy": Greedy(),
    "intrinsic": Intrinsic(),
    "goal_babbling": GoalBabbling(),
}


def RegisterReachStrategy(name: str, strategy: ReachStrategy) -> None:
    """Makes ``strategy`` available to the reach learner as ``name``."""
    if name in REACH_STRATEGIES:
        raise ValueError(f"a reach-learning strategy named '{name}' exists already")
    REACH_STRATEGIES[name] = strategy
