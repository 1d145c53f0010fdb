"""Is a region's interest learning progress? A permutation test against its own competences.

Eq. 2 takes the difference of the mean competence between the older and the newer half of a
region's last zeta goals. Competences without any trend still give a positive value, which grows
with their spread: the noise floor. The test (issue 34) compares a leaf's interest with the
interests of random reorderings of its own competences (the same values, their time order
destroyed, the window taken from the end as eq. 2 does): an interest above the null's 95th
percentile is progress that the values' spread alone does not explain.
"""

import dataclasses

import numpy as np

from mobee_drake.goal_babbling.competence import CompetenceSpread, Interest
from mobee_drake.goal_babbling.regions import RegionTree

# Reorderings per leaf (the p-value's resolution is 1 / (PERMUTATIONS + 1)).
PERMUTATIONS = 999


def InterestNullP(
    values: np.ndarray, window: int, rng: np.random.Generator, permutations: int = PERMUTATIONS
) -> float:
    """The permutation p-value of eq. 2's interest of ``values`` (in time order): the share of
    reorderings whose interest is at least the observed one, counting the observed order
    ((1 + k) / (1 + permutations)). 1 for fewer than 2 values."""
    values = np.asarray(values, dtype=float)
    if values.size < 2:
        return 1.0
    observed = Interest(values[-window:], window)
    shuffled = rng.permuted(np.tile(values, (permutations, 1)), axis=1)
    null = np.array([Interest(row[-window:], window) for row in shuffled])
    # (A tolerance for the sums' rounding: a reordering of equal interest counts as at least.)
    exceeding = int(np.sum(null >= observed - 1e-12))
    return (1 + exceeding) / (1 + permutations)


@dataclasses.dataclass
class LeafInterest:
    """One leaf of a region tree at the end of a run (issue 34's interest diagnostic).

    Attributes:
        low: Lower corner of its box.
        high: Upper corner.
        goals: Competences it holds.
        mean_competence: eq. 1.
        spread: The standard deviation of its last zeta competences.
        interest: eq. 2 over its last zeta competences.
        null_p: :func:`InterestNullP` of its interest.
    """

    low: list[float]
    high: list[float]
    goals: int
    mean_competence: float
    spread: float
    interest: float
    null_p: float


def LeafInterests(tree: RegionTree, seed: int) -> list[LeafInterest]:
    """The diagnostic of every leaf of ``tree`` (the permutations drawn from ``seed``)."""
    rng = np.random.default_rng(seed)
    window = tree.config.window
    return [
        LeafInterest(
            low=leaf.low.tolist(),
            high=leaf.high.tolist(),
            goals=len(leaf.values),
            mean_competence=leaf.MeanCompetence(),
            spread=CompetenceSpread(leaf.values, window),
            interest=Interest(np.asarray(leaf.values)[-window:], window),
            null_p=InterestNullP(np.asarray(leaf.values), window, rng),
        )
        for leaf in tree.leaves
    ]
