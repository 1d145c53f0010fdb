"""MoBeE's joint-limit forces (dissertation eq. 5.12-5.13, Fig. 5.3).

As printed, eq. 5.12 has two typos: the middle case must read ``q_min + delta < q < q_max - delta``,
and the slopes of the outer cases must be ``-f_max/delta`` for the force to be ``+f_max`` at
``q_min``, ``-f_max`` at ``q_max`` and zero on the free band, as Fig. 5.3 shows. We implement the
function of Fig. 5.3: a linear spring of length ``delta`` inside each limit,

    f_lim = (f_max / delta) * (max(0, q_min + delta - q) - max(0, q - (q_max - delta))),

continuous everywhere, and growing linearly beyond a limit.
"""

import numpy as np


class JointLimits:
    """``f_lim`` for fixed limits and constants, with the band edges computed once."""

    def __init__(self, q_min: np.ndarray, q_max: np.ndarray, delta: float, f_max: float):
        self._lower_edge, self._upper_edge = q_min + delta, q_max - delta
        self._slope = f_max / delta

    def Bands(self) -> tuple[np.ndarray, np.ndarray]:
        """(R, c): the depths ``R q + c`` of the joints into their lower bands (first n rows) and
        their upper bands (last n rows), positive inside a band: where ``f_lim`` is not zero."""
        n = len(self._lower_edge)
        return np.vstack([-np.eye(n), np.eye(n)]), np.concatenate(
            [self._lower_edge, -self._upper_edge]
        )

    def Force(self, q: np.ndarray) -> np.ndarray:
        """The per-joint limit force ``f_lim(q)`` (eq. 5.12-5.13, typos corrected)."""
        return self.ForceAtDepths(np.stack([self._lower_edge - q, q - self._upper_edge]))

    def ForceAtDepths(self, depths: np.ndarray) -> np.ndarray:
        """``f_lim`` from the depths of :meth:`Bands`, as two rows: lower bands, upper bands."""
        inside = np.maximum(depths, 0.0)
        return self._slope * (inside[0] - inside[1])


def JointLimitForce(
    q: np.ndarray,
    q_min: np.ndarray,
    q_max: np.ndarray,
    delta: np.ndarray | float,
    f_max: np.ndarray | float,
) -> np.ndarray:
    """The per-joint limit force ``f_lim(q)`` (eq. 5.12-5.13, with the typos above corrected)."""
    return JointLimits(q_min, q_max, delta, f_max).Force(q)
