"""State-action spaces over a set of joints (dissertation ch. 6.2-6.3, Fig. 7.1, 7.4, 7.8, 7.9).

States are the Voronoi regions of sample configurations ("centres"), given in fractions of each
joint's range of motion (0 = lower limit, 1 = upper limit). The state of a configuration is the
nearest centre (Euclidean distance in that normalised space). Each state has actions that set
MoBeE's attractor to the centre of a neighbouring state: either its nearest *equidistant*
neighbours (all centres at the smallest distance from it) or its k nearest neighbours (ties
broken by index).
"""

import dataclasses as dc
import itertools

import numpy as np
from scipy.spatial import cKDTree

# Centres closer than this (in fractions of range) count as equidistant.
_TIE_TOLERANCE = 1e-9


@dc.dataclass(frozen=True)
class StateActionSpace:
    """States (their centres) and actions (pairs of a state and its goal state)."""

    # (m, d) state centres, fractions of each joint's range of motion.
    centres: np.ndarray
    # (n_sa,) the state each action belongs to, sorted, and (n_sa,) the state it intends to reach.
    action_state: np.ndarray
    action_goal: np.ndarray

    @property
    def num_states(self) -> int:
        return len(self.centres)

    @property
    def num_state_actions(self) -> int:
        return len(self.action_state)

    def Actions(self, state: int) -> np.ndarray:
        """The indices of the state-actions available in ``state``."""
        start, stop = np.searchsorted(self.action_state, [state, state + 1])
        return np.arange(start, stop)

    def StateOf(self, fractions: np.ndarray) -> int:
        """The state (nearest centre) of a configuration given in fractions of range."""
        return int(self._tree.query(fractions)[1])

    def StateOfConfiguration(self, q: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> int:
        """The state of joint positions ``q`` (rad) of joints with limits ``lower``, ``upper``."""
        return self.StateOf((q - lower) / (upper - lower))

    def Centre(self, state: int, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
        """A state's centre as joint positions (rad) of joints with limits ``lower``, ``upper``
        (a centre at a limit lands on it, not a rounding error beyond it)."""
        return np.clip(lower + self.centres[state] * (upper - lower), lower, upper)

    @property
    def _tree(self) -> cKDTree:
        tree = self.__dict__.get("_kdtree")
        if tree is None:
            tree = cKDTree(self.centres)
            object.__setattr__(self, "_kdtree", tree)
        return tree


def _Connect(centres: np.ndarray, *, k: int | None) -> StateActionSpace:
    distances = np.linalg.norm(centres[:, None, :] - centres[None, :, :], axis=2)
    np.fill_diagonal(distances, np.inf)
    states, goals = [], []
    for s, row in enumerate(distances):
        if k is None:
            neighbours = np.flatnonzero(row <= row.min() + _TIE_TOLERANCE)
        else:
            neighbours = np.argsort(row, kind="stable")[:k]
        states += [s] * len(neighbours)
        goals += sorted(neighbours.tolist())
    return StateActionSpace(centres, np.array(states), np.array(goals))


def Lattice(levels, dimension: int, *, k: int | None = None) -> StateActionSpace:
    """A hyper-lattice: every combination of ``levels`` (fractions of range) on each joint.

    Actions go to the nearest equidistant neighbours, or to the ``k`` nearest with ``k``.
    The dissertation's spaces (4 joints: shoulder pitch, roll, yaw, elbow):

    - hypercube, levels (0.25, 0.75): 16 states, 64 state-actions (Fig. 7.1);
    - rank 3, levels (0.25, 0.5, 0.75): 81 states, 432 state-actions (Fig. 7.4), or 1296 with
      ``k=16`` (the space of ch. 7.2.1);
    - rank 4, (0.2, 0.4, 0.6, 0.8) or (0.125, 0.375, 0.625, 0.875): 256 states, 1536
      state-actions (Fig. 7.8, 7.9);
    - the torso, 3 joints at (0.25, 0.5, 0.75) with ``k=8``: 27 states, 216 state-actions.
    """
    centres = np.array(list(itertools.product(sorted(levels), repeat=dimension)), dtype=float)
    return _Connect(centres, k=k)


def FromGraph(centres: np.ndarray, edges: np.ndarray) -> StateActionSpace:
    """States at ``centres`` (fractions of range) with an action both ways along each of the
    undirected ``edges`` (pairs of state indices), e.g. a task-relevant roadmap's (ch. 9.4.5)."""
    centres = np.asarray(centres, dtype=float)
    edges = np.asarray(edges, dtype=int).reshape(-1, 2)
    if centres.ndim != 2 or len(centres) < 2 or not np.all(np.isfinite(centres)):
        raise ValueError(f"centres must be a finite (m >= 2, d) array, got shape {centres.shape}")
    if len(edges) and (edges.min() < 0 or edges.max() >= len(centres)):
        raise ValueError(f"edges must join states 0..{len(centres) - 1}")
    pairs = sorted(
        {(int(a), int(b)) for a, b in edges if a != b}
        | {(int(b), int(a)) for a, b in edges if a != b}
    )
    if not pairs:
        raise ValueError("a state-action space needs at least one edge")
    states, goals = np.array(pairs).T
    return StateActionSpace(centres, states, goals)


def FromSamples(samples: np.ndarray, *, k: int | None = None) -> StateActionSpace:
    """A state-action space over arbitrary sample configurations (fractions of range)."""
    samples = np.asarray(samples, dtype=float)
    if samples.ndim != 2 or len(samples) < 2:
        raise ValueError(f"samples must be an (m >= 2, d) array, got shape {samples.shape}")
    if not np.all(np.isfinite(samples)):
        raise ValueError("samples must be finite")
    return _Connect(samples, k=k)
