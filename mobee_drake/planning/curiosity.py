"""Learned transition distributions and the curious reward (dissertation Alg. 6, Tables 6.1-6.4).

The distribution of outcomes of a state-action is kept *compressed*: only outcomes that have been
observed have a bin. Observing an outcome (Alg. 6) adds a bin initialised to 1 if the outcome is
new, copies the counts T to P, increments the outcome's bin in P, rewards the agent with the KL
divergence D(P || T) of the normalised counts, and keeps P as the new T. Because zero bins never
take part, the divergence is always defined ("Kail" divergence, ch. 6.4.3).

The counts live in one dense (state-actions x states) array whose zero entries are the bins not
yet created: one row changes per observation, and the curious agent's value iteration reads the
whole array as T. A learner whose space can grow large (the reach learner's) keeps T sparse and
sets the changed row with :func:`SetProbabilityRow`.
"""

import numpy as np
from scipy import sparse


def KlDivergence(p_counts, t_counts) -> float:
    """D_KL(P || T) of two count vectors of equal length, normalised (eq. 6.5)."""
    p = np.asarray(p_counts, dtype=float)
    t = np.asarray(t_counts, dtype=float)
    p, t = p / p.sum(), t / t.sum()
    return float(np.sum(p * np.log(p / t)))


class TransitionCounts:
    """The compressed outcome counts T(s, a) of every state-action."""

    def __init__(self, num_state_actions: int, num_states: int):
        self.counts = np.zeros((num_state_actions, num_states))

    def Observe(self, state_action: int, outcome: int) -> float:
        """Alg. 6: records ``outcome`` of ``state_action`` and returns the reward D(P || T)."""
        row = self.counts[state_action]
        if row[outcome] == 0:
            row[outcome] = 1.0  # A new bin.
        bins = np.flatnonzero(row)
        before = row[bins].copy()
        row[outcome] += 1.0
        return KlDivergence(row[bins], before)

    def Probabilities(self) -> np.ndarray:
        """T(s, a, s') for every state-action (rows of zeros for state-actions never observed)."""
        totals = self.counts.sum(axis=1, keepdims=True)
        return np.divide(self.counts, totals, out=np.zeros_like(self.counts), where=totals > 0)


def SetProbabilityRow(probabilities: sparse.csr_array, row: int, counts: np.ndarray) -> None:
    """Sets ``row`` of a sparse T to ``counts`` normalised, in place: the entries it stores become
    the bins of ``counts``, their values those of :meth:`TransitionCounts.Probabilities` (the
    counts are whole numbers, so their sum does not depend on the order of summation)."""
    bins = np.flatnonzero(counts)
    T, start, end = probabilities, probabilities.indptr[row], probabilities.indptr[row + 1]
    if not np.array_equal(T.indices[start:end], bins):
        T.indices = np.concatenate([T.indices[:start], bins, T.indices[end:]]).astype(
            T.indices.dtype
        )
        T.data = np.concatenate([T.data[:start], np.zeros(len(bins)), T.data[end:]])
        T.indptr[row + 1 :] += len(bins) - (end - start)
    T.data[start : start + len(bins)] = counts[bins] / counts.sum()
