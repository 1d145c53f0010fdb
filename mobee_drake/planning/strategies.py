"""How an exploring agent chooses its next action: strategies as small classes in a registry.

A strategy scores the actions of the current state; the agent takes the best, breaking ties at
random with its own generator (so equal scores make a uniformly random choice). The shipped ones
(dissertation Alg. 8, ch. 6.5, ch. 7.2.1):

- ``curious`` (AC): greedy on V(s, a) of value iteration (Alg. 7) on the intrinsic rewards;
- ``random`` (RAND): every action scores the same;
- ``least_tried`` (LT): the action tried least often;
- ``planner``: greedy on the values of a reward for arriving in the agent's ``goal_state`` (see
  :mod:`mobee_drake.planning.planner`).

A user adds one without editing the package: ``RegisterStrategy("mine", Mine())`` before the
scenario that names it (``explorer: {strategy: mine}``) is built.
"""

from typing import Protocol

import numpy as np

from mobee_drake.planning.planner import PlanValues


class Strategy(Protocol):
    # Whether it heads for the agent's ``goal_state``: such an agent needs one, stops once an
    # action has ended there, and takes new goals (``ExploringAgent.SetPlannerGoal``).
    seeks_goal: bool

    def Scores(self, explorer, actions: np.ndarray) -> np.ndarray:
        """The score of each of ``actions`` (the current state's) for ``explorer``."""


class Curious:
    seeks_goal = False

    def Scores(self, explorer, actions: np.ndarray) -> np.ndarray:
        return explorer.Values()[0][actions]


class Random:
    seeks_goal = False

    def Scores(self, explorer, actions: np.ndarray) -> np.ndarray:
        return np.zeros(len(actions))


class LeastTried:
    seeks_goal = False

    def Scores(self, explorer, actions: np.ndarray) -> np.ndarray:
        return -explorer.tries[actions].astype(float)


class Planner:
    seeks_goal = True

    def Scores(self, explorer, actions: np.ndarray) -> np.ndarray:
        goal = {explorer.config.goal_state: 1.0}
        return PlanValues(explorer, goal, gamma=explorer.config.gamma)[0][actions]


STRATEGIES: dict[str, Strategy] = {
    "curious": Curious(),
    "random": Random(),
    "least_tried": LeastTried(),
    "planner": Planner(),
}


def RegisterStrategy(name: str, strategy: Strategy) -> None:
    """Makes ``strategy`` available to exploring agents as ``name``."""
    if name in STRATEGIES:
        raise ValueError(f"an exploration strategy named '{name}' exists already")
    if not isinstance(getattr(strategy, "seeks_goal", None), bool):
        raise TypeError(f"strategy '{name}' must say whether it seeks_goal (True or False)")
    STRATEGIES[name] = strategy
