"""The learned model as a planner (dissertation ch. 6.5, 7.4.1): an external reward on goal states.

With the transition probabilities T learned by exploration, a reward r(s') for arriving in a goal
state gives each state-action the expected reward ``R(s, a) = sum_s' T(s, a, s') r(s')``; value
iteration (Alg. 7) on R and T, and the greedy choice of V(s, a), plan a path that prefers actions
that reliably reach the goal, around those that were seen to fail (an obstacle, a constraint).
"""

from typing import Protocol

import numpy as np

from mobee_drake.planning.curiosity import TransitionCounts
from mobee_drake.planning.state_space import StateActionSpace
from mobee_drake.planning.value_iteration import ValueIteration


class LearnedModel(Protocol):
    """What a plan needs of an agent: its state-action space and its transition counts."""

    space: StateActionSpace
    transitions: TransitionCounts


def PlanValues(
    explorer: LearnedModel,
    goal_rewards: dict[int, float],
    *,
    gamma: float = 0.9,
    delta: float = 1e-6,
) -> tuple[np.ndarray, np.ndarray]:
    """V(s, a) and V(s) for rewards on arriving in goal states (state index -> reward)."""
    space = explorer.space
    reward_of_state = np.zeros(space.num_states)
    for state, reward in goal_rewards.items():
        if not 0 <= state < space.num_states:
            raise ValueError(f"goal state {state} is not a state (0..{space.num_states - 1})")
        reward_of_state[state] = reward
    T = explorer.transitions.Probabilities()
    return ValueIteration(
        T, T @ reward_of_state, space.action_state, space.num_states, gamma, delta
    )


def GreedyPlan(
    explorer: LearnedModel, start: int, goal: int, *, gamma: float = 0.9, max_steps: int = 100
) -> list[int]:
    """The states of the most likely path from ``start`` to ``goal`` following the greedy plan.

    Each step takes the best action of the current state and moves to that action's most likely
    outcome, until the goal, a state visited before, or ``max_steps``.
    """
    q, _ = PlanValues(explorer, {goal: 1.0}, gamma=gamma)
    T = explorer.transitions.Probabilities()
    path = [start]
    while path[-1] != goal and len(path) <= max_steps:
        actions = explorer.space.Actions(path[-1])
        best = actions[np.argmax(q[actions])]
        following = int(np.argmax(T[best]))
        if following in path:
            break
        path.append(following)
    return path
