"""MoBeE's joint-limit forces (dissertation eq. 5.12-5.13, Fig. 5.3).

As printed, eq. 5.12 has two typos: the middle case must read ``q_min + delta < q < q_max - delta``,
and the slopes of the outer cases must be ``-f_max/delta`` for the force to be ``+f_max`` at
``q_min``, ``-f_max`` at ``q_max`` and zero on the free band, as Fig. 5.3 shows. We implement the
function of Fig. 5.3: a linear spring of length ``delta`` inside each limit,

    f_lim = (f_max / delta) * (max(0, q_min + delta - q) - max(0, q - (q_max - delta))),

continuous everywhere, and growing linearly beyond a limit.
"""

import numpy as np


def JointLimitForce(q: np.ndarray, q_min: np.ndarray, q_max: np.ndarray,
                    delta: np.ndarray | float, f_max: np.ndarray | float) -> np.ndarray:
    """The per-joint limit force ``f_lim(q)`` (eq. 5.12-5.13, with the typos above corrected)."""
    lower_spring = np.maximum(0.0, q_min + delta - q)
    upper_spring = np.maximum(0.0, q - (q_max - delta))
    return (f_max / delta) * (lower_spring - upper_spring)
