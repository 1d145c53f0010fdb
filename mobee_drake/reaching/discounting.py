"""When does a greedy reach planner move? The discount against the reward's spread (issue 23, 5).

A reach ends the policy, so its value is its predicted reward; a transition earns nothing and
is discounted. Take a transition that reaches its goal state with probability ``p`` and otherwise
leaves the robot where it was (the learned MDP of ch. 8: P(goal) 0.81 on average, the rest of the
mass on staying). Let the reach here predict ``r`` and the goal state be worth ``V'``. Moving is
worth ``gamma (p V' + (1 - p) V)``, and if moving is the greedy choice, ``V`` is that value:

    V = gamma p V' / (1 - gamma (1 - p)) = f V',   f = gamma p / (1 - gamma (1 - p)).

So the greedy policy leaves its state only when ``f V' > r``: when the neighbour's reach predicts
more than ``1 / f`` times this one's (:func:`StepRatio`: 1.137 for gamma 0.9, p 0.81). Along a
shortest path of ``d`` steps to a state whose reach predicts ``R``, every state on the way is
worth ``f`` times the next (as long as moving on beats reaching there), so a start ``d`` steps away
moves only when ``R / r > (1 / f)^d`` (:func:`PathRatio`).

Eq. 8.4 rewards a miss of ``e`` (in the distance unit ``u``) with ``1 / (1 + e / u)``, so between
misses ``e_min`` and ``e_max`` the reward ratio is at most ``(1 + e_max / u) / (1 + e_min / u)``
(:func:`RewardRatio`): in metres, misses of 1-33 cm give at most 1.32, less than the threshold
of three steps; in centimetres 17.

:func:`MoveThreshold` measures the least ratio with the project's value iteration on any MDP
(the reach learner's T), by bisection, so the closed form can be checked against it; ``mobee-drake
experiment ch8-discounting --model <the MDP's folder>`` prints the numbers of a learned MDP
(``runs/mdp_tries5/model`` of a ch8 battery).
"""

import collections

import numpy as np

from mobee_drake.reaching.learner import ReachLearner


def StepRatio(gamma: float, p: float) -> float:
    """The least ratio of the neighbour's reach reward to this state's for which one transition
    (success ``p``, else staying) is the greedy choice: ``(1 - gamma (1 - p)) / (gamma p)``."""
    if not (0 < gamma < 1 and 0 < p <= 1):
        raise ValueError(f"need 0 < gamma < 1 and 0 < p <= 1, got gamma {gamma} and p {p}")
    return (1 - gamma * (1 - p)) / (gamma * p)


def PathRatio(gamma: float, p: float, steps: int) -> float:
    """The least reward ratio that moves a greedy policy ``steps`` transitions to a reach."""
    if steps < 0:
        raise ValueError(f"steps must be >= 0, got {steps}")
    return StepRatio(gamma, p) ** steps


def RewardRatio(miss_min: float, miss_max: float, unit: float) -> float:
    """The largest ratio of eq. 8.4's rewards between misses in [miss_min, miss_max] (m),
    distances counted in ``unit`` (m)."""
    if not (0 <= miss_min <= miss_max and unit > 0):
        raise ValueError(
            f"need 0 <= miss_min <= miss_max and unit > 0, got {miss_min}, {miss_max}, {unit}"
        )
    return (1 + miss_max / unit) / (1 + miss_min / unit)


def Steps(learner: ReachLearner, goals) -> np.ndarray:
    """The fewest transitions from every state to any of ``goals`` (breadth first over the
    MDP's state-actions)."""
    space = learner.space
    into = collections.defaultdict(list)
    for state, goal in zip(space.action_state, space.action_goal):
        into[int(goal)].append(int(state))
    steps = np.full(space.num_states, -1)
    queue = collections.deque(int(g) for g in goals)
    steps[list(queue)] = 0
    while queue:
        state = queue.popleft()
        for before in into[state]:
            if steps[before] < 0:
                steps[before] = steps[state] + 1
                queue.append(before)
    return steps


def Moves(learner: ReachLearner, start: int, goals, ratio: float) -> bool:
    """Whether the greedy policy at ``start`` takes a transition when every reach predicts 1
    but those of ``goals``, which predict ``ratio`` (transitions 0)."""
    rewards = np.zeros(learner.num_state_actions)
    rewards[learner.num_transitions :] = 1.0
    rewards[[learner.Reach(g) for g in goals]] = ratio
    q, _ = learner.Values(rewards)
    transitions = learner.space.Actions(start)
    return bool(q[transitions].max() > q[learner.Reach(start)])


def MoveThreshold(
    learner: ReachLearner, start: int, goals, high: float = 100.0, tolerance: float = 1e-6
) -> float:
    """The least reward ratio (goals' reaches over all others) for which the greedy policy at
    ``start`` moves, by bisection with value iteration (inf when even ``high`` does not)."""
    if not Moves(learner, start, goals, high):
        return float("inf")
    low = 1.0
    while high - low > tolerance:
        middle = 0.5 * (low + high)
        low, high = (low, middle) if Moves(learner, start, goals, middle) else (middle, high)
    return high


def PredictedSpread(learner: ReachLearner) -> tuple[np.ndarray, np.ndarray]:
    """Per problem (the learner's targets): the ratio of the largest to the smallest eq. 8.5
    prediction over the reaches of all states, and the share of start states from which the
    greedy policy on eq. 8.1 and 8.5 takes a transition (an evaluation that moves)."""
    ratios, moving = [], []
    states = range(learner.space.num_states)
    for target in learner.targets:
        rewards = learner.Rewards(target, "greedy")
        predictions = rewards[learner.num_transitions :]
        ratios.append(predictions.max() / predictions.min())
        q, _ = learner.Values(rewards)
        moving.append(
            np.mean([q[learner.space.Actions(s)].max() > q[learner.Reach(s)] for s in states])
        )
    return np.array(ratios), np.array(moving)


def BestOverOwn(misses, unit: float) -> np.ndarray:
    """What moving could gain, from measured reaches: ``misses[s, j]`` is the miss (m) of a reach
    from start state s for problem j (NaN where the state was not reached); per entry, the ratio
    of the best state's eq. 8.4 reward for that problem to this state's, distances counted in
    ``unit`` (m). An evaluation that starts in s can only profit from moving where the ratio beats
    :func:`PathRatio` for the steps to the best state."""
    misses = np.asarray(misses, dtype=float)
    if misses.ndim != 2 or not np.all(np.isnan(misses) | (misses >= 0)) or unit <= 0:
        raise ValueError(
            f"need misses >= 0 (states x problems, NaN where unmeasured) and unit > 0, got "
            f"shape {misses.shape} and unit {unit}"
        )
    rewards = 1.0 / (1.0 + misses / unit)
    return np.nanmax(rewards, axis=0, keepdims=True) / rewards
