"""Value iteration over a state-action space (dissertation Alg. 7), vectorised.

``V(s, a) = R(s, a) + gamma sum_s' T(s, a, s') V(s')`` and ``V(s) = max_a V(s, a)``, from zero,
until the largest change of any ``V(s, a)`` in a sweep is below ``delta``. Alg. 7 as printed only
tracks increases (``V_new - V > max_delta``); starting from zero with non-negative rewards the
values only grow, and we use the absolute change so that negative rewards (ch. 8) converge too.
All state-actions are updated at once from the previous sweep's state values (Jacobi sweeps); a
state without actions has value 0.
"""

import numpy as np
from scipy import sparse

# Values (and the scores made of them) within this of each other are equal: what parts them is
# the rounding of sums taken in another order (a sparse T's, a dense T's: a few 1e-15 apart in
# `mobee-drake bench values`). Absolute: it suits values within about a hundred (ch. 8's
# rewards, -10 to 1, at gamma 0.9 keep them within 100), less where values grow larger.
VALUE_TIE = 1e-12


def ValueIteration(
    transitions: np.ndarray | sparse.sparray,
    rewards: np.ndarray,
    action_state: np.ndarray,
    num_states: int,
    gamma: float,
    delta: float = 1e-3,
    max_sweeps: int = 100_000,
) -> tuple[np.ndarray, np.ndarray]:
    """Returns ``(V(s, a), V(s))``.

    Args:
        transitions: (n_sa, m) T(s, a, s'), rows summing to 1 (or 0 for untried rows); an
            array, or a scipy sparse array where most outcomes were never observed.
        rewards: (n_sa,) R(s, a).
        action_state: (n_sa,) the state of each state-action, sorted.
        num_states: m.
        gamma: discount in [0, 1).
        delta: stop when no V(s, a) changes by ``delta`` or more in a sweep.
        max_sweeps: stop after this many sweeps in any case.
    """
    if not 0 <= gamma < 1:
        raise ValueError(f"gamma must be in [0, 1), got {gamma}")
    if len(rewards) == 0:
        return np.zeros(0), np.zeros(num_states)
    starts = np.minimum(np.searchsorted(action_state, np.arange(num_states)), len(rewards) - 1)
    has_actions = np.zeros(num_states, dtype=bool)
    has_actions[action_state] = True
    q = np.zeros(len(rewards))
    v = np.zeros(num_states)
    for _ in range(max_sweeps):
        q_new = rewards + gamma * (transitions @ v)
        change = np.max(np.abs(q_new - q))
        q = q_new
        v = np.where(has_actions, np.maximum.reduceat(q, starts), 0.0)
        if change < delta:
            break
    return q, v
