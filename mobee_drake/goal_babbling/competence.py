"""Competence and interest of SAGG-RIAC (Baranes & Oudeyer, IROS 2010, Sec. II-D and III-C-1)."""

import numpy as np


def ReachingCost(
    goal: np.ndarray, final: np.ndarray, start: np.ndarray, min_competence: float
) -> float:
    """C(x_g, x_f, x_start) = -D(x_g, x_f) / D(x_start, x_g) (eq. 7).

    Args:
        goal: x_g.
        final: x_f, where the attempt ended.
        start: x_start, where it began.
        min_competence: min_C, returned when D(x_start, x_g) = 0 and D(x_g, x_f) != 0 (eq. 7).

    Returns:
        The cost (<= 0); 0 when start, goal and end coincide.
    """
    remaining = float(np.linalg.norm(np.asarray(goal) - np.asarray(final)))
    initial = float(np.linalg.norm(np.asarray(goal) - np.asarray(start)))
    if initial == 0.0:
        return 0.0 if remaining == 0.0 else min_competence
    return -remaining / initial


def Competence(cost: float, tolerance: float, min_competence: float) -> float:
    """Gamma = min_C if C <= min_C; C if min_C < C <= eps_C; 0 otherwise (Sec. II-D-1).

    Args:
        cost: C of the attempt.
        tolerance: eps_C < 0.
        min_competence: min_C < eps_C.

    Returns:
        The competence in [min_C, 0].
    """
    if cost <= min_competence:
        return min_competence
    if cost <= tolerance:
        return cost
    return 0.0


def LocalCompetence(competences: np.ndarray) -> float:
    """Gamma'' = mean of the competences of the goals in a region (eq. 1).

    Args:
        competences: The region's competences.

    Returns:
        Their mean (0 for an empty region).
    """
    competences = np.asarray(competences, dtype=float)
    return float(competences.mean()) if competences.size else 0.0


def MaskedInterests(values: np.ndarray, masks: np.ndarray, window: int) -> np.ndarray:
    """Interest (eq. 2) of several sub-sequences of one time-ordered sequence at once.

    For each row of masks, the selected values keep their time order; the most recent w = min(count,
    window) of them, w rounded down to even, form an older and a newer half, and the interest is
    |sum(older) - sum(newer)| / w. With at least `window` values this is eq. 2 exactly; with fewer
    we use all of them (our choice). Fewer than 2 values give 0.

    Args:
        values: (k,) competences in time order.
        masks: (m, k) booleans; row i selects a sub-sequence.
        window: zeta.

    Returns:
        (m,) interests.
    """
    masks = np.asarray(masks, dtype=bool)
    # rank_from_end[i, j]: how many selected values come at or after j (1 = the most recent).
    rank_from_end = np.cumsum(masks[:, ::-1], axis=1)[:, ::-1]
    counts = masks.sum(axis=1)
    half = np.minimum(counts, window) // 2
    newer = masks & (rank_from_end <= half[:, None])
    older = masks & (rank_from_end > half[:, None]) & (rank_from_end <= 2 * half[:, None])
    difference = np.abs(older.astype(float) @ values - newer.astype(float) @ values)
    width = np.maximum(2 * half, 1)
    return np.where(half > 0, difference / width, 0.0)


def Interest(competences: np.ndarray, window: int) -> float:
    """interest(R) = |sum(older half) - sum(newer half)| / zeta over the last zeta values (eq. 2).

    Args:
        competences: The region's competences in time order.
        window: zeta.

    Returns:
        The interest (see MaskedInterests for fewer than zeta values).
    """
    competences = np.asarray(competences, dtype=float)
    return float(
        MaskedInterests(competences, np.ones((1, competences.size), dtype=bool), window)[0]
    )


def CompetenceSpread(competences: np.ndarray, window: int) -> float:
    """The standard deviation of the last ``window`` competences (0 with fewer than 2): a
    region's measure for the variance-only selector (InterestConfig.region_measure = "variance",
    not the paper's). It is blind to time order, and like eq. 2's value on competences without a
    trend it grows in proportion to their spread, so eq. 3 over it draws regions by competence
    variance alone.

    Args:
        competences: The region's competences in time order.
        window: zeta.

    Returns:
        The spread (>= 0).
    """
    recent = np.asarray(competences, dtype=float)[-window:]
    return float(recent.std()) if recent.size > 1 else 0.0
