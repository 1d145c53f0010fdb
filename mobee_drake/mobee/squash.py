"""MoBeE's sigmoidal squashing function L (dissertation eq. 5.8, Fig. 5.2)."""

import numpy as np


def Squash(v: np.ndarray, m: np.ndarray | float, k: np.ndarray | float) -> np.ndarray:
    """Applies ``L`` per dimension: ``m v / (m/k + |v|)`` (eq. 5.8).

    Each dimension is odd, increasing, has slope ``k`` at zero and tends to ``+-m`` as ``|v|``
    grows, so it bounds a force without changing its sign. It does not preserve the direction
    of ``v``.

    Args:
        v: the vector to squash.
        m: the maximum value of each dimension (> 0), a scalar or one per dimension.
        k: the maximum slope of each dimension (> 0), a scalar or one per dimension.
    """
    return m * v / (m / k + np.abs(v))
