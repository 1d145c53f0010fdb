"""Regions of a goal (or sensorimotor) space: interest, recursive splits, the selection modes.

Baranes & Oudeyer (IROS 2010), Sec. II-D-2 and II-D-3: each region keeps its goals and competences
in time order; its interest is eq. 2; a region holding more than g_max goals is cut in two where the
difference of interest between the halves is largest; goals are drawn by mode 1 (region chosen by
eq. 3), mode 2 (whole space) or mode 3 (region of lowest mean competence, eq. 1).
"""

import dataclasses

import numpy as np

from mobee_drake.goal_babbling.competence import CompetenceSpread, Interest, MaskedInterests
from mobee_drake.goal_babbling.config import InterestConfig


@dataclasses.dataclass
class Region:
    """An axis-aligned box of the space and what was attempted inside it while it was a leaf.

    Attributes:
        low: Lower corner.
        high: Upper corner.
        born: Number of points the whole tree held when the region was created.
        points: Attempted points in time order.
        values: Their competences, in the same order.
        interest: What eq. 3 draws regions by: eq. 2 over values (or their spread, with
            InterestConfig.region_measure = "variance").
        split_at: Number of points the tree held when this region was split (None while a leaf).
        split_dimension: Dimension of the cut (None while a leaf).
        split_value: Coordinate of the cut (None while a leaf).
        children: (lower half, upper half) once split.
    """

    low: np.ndarray
    high: np.ndarray
    born: int
    points: list = dataclasses.field(default_factory=list)
    values: list = dataclasses.field(default_factory=list)
    interest: float = 0.0
    split_at: int | None = None
    split_dimension: int | None = None
    split_value: float | None = None
    children: tuple["Region", "Region"] | None = None

    def MeanCompetence(self) -> float:
        """Gamma'' of the region (eq. 1); 0 while empty."""
        return float(np.mean(self.values)) if self.values else 0.0

    def Sample(self, rng: np.random.Generator) -> np.ndarray:
        """A point drawn uniformly in the box."""
        return rng.uniform(self.low, self.high)


def BestSplit(
    points: np.ndarray, values: np.ndarray, window: int, min_child: int, weighted: bool = False
) -> tuple[int, float] | None:
    """The axis-aligned cut that maximises |interest(lower) - interest(upper)| (Sec. II-D-3).

    Candidate cuts are the midpoints between consecutive distinct coordinates, in every dimension,
    that leave at least min_child points on each side (our choice). Ties go to the most balanced
    cut, then to the lowest dimension and coordinate. With ``weighted`` (explauto's criterion,
    InterestConfig.split_criterion = "weighted") the score is |L| |G| |interest(L) - interest(G)|,
    |L| and |G| the numbers of points on each side.

    Args:
        points: (k, d) points in time order.
        values: (k,) their competences.
        window: zeta of eq. 2.
        min_child: Least number of points on either side.
        weighted: Multiply the difference by the sizes of both sides.

    Returns:
        (dimension, cut value), or None when no cut is admissible.
    """
    points = np.asarray(points, dtype=float)
    values = np.asarray(values, dtype=float)
    count = points.shape[0]
    best_key, best = None, None
    for dimension in range(points.shape[1]):
        coordinates = np.unique(points[:, dimension])
        if coordinates.size < 2:
            continue
        cuts = 0.5 * (coordinates[:-1] + coordinates[1:])
        lower_masks = points[None, :, dimension] < cuts[:, None]
        lower_counts = lower_masks.sum(axis=1)
        admissible = (lower_counts >= min_child) & (count - lower_counts >= min_child)
        if not admissible.any():
            continue
        cuts, lower_masks, lower_counts = (
            cuts[admissible],
            lower_masks[admissible],
            lower_counts[admissible],
        )
        differences = np.abs(
            MaskedInterests(values, lower_masks, window)
            - MaskedInterests(values, ~lower_masks, window)
        )
        if weighted:
            differences = differences * lower_counts * (count - lower_counts)
        imbalance = np.abs(2 * lower_counts - count)
        index = np.lexsort((imbalance, -differences))[0]
        key = (-differences[index], imbalance[index])
        if best_key is None or key < best_key:
            best_key, best = key, (dimension, float(cuts[index]))
    return best


def InterestProbabilities(interests: np.ndarray) -> np.ndarray:
    """P_n = |interest_n - min_i interest_i| / sum_i |interest_i - min_i interest_i| (eq. 3).

    When all interests are equal the sum is 0; we then draw uniformly (our choice).

    Args:
        interests: Interests of the candidate regions.

    Returns:
        Probabilities, one per region.
    """
    interests = np.asarray(interests, dtype=float)
    weights = np.abs(interests - interests.min())
    total = weights.sum()
    if total <= 0.0:
        return np.full(interests.size, 1.0 / interests.size)
    return weights / total


class RegionTree:
    """Recursive split of a box into regions (Sec. II-D-3), keeping the history of every region."""

    def __init__(self, low, high, config: InterestConfig):
        """Starts with a single region, the whole box.

        Args:
            low: Lower corner of the space.
            high: Upper corner of the space.
            config: g_max, zeta and the smallest admissible half.
        """
        self.config = config
        self.root = Region(
            low=np.asarray(low, dtype=float), high=np.asarray(high, dtype=float), born=0
        )
        self.leaves = [self.root]
        self.all_regions = [self.root]
        self.num_points = 0

    def Leaf(self, point: np.ndarray) -> Region:
        """The leaf whose box holds point (points outside the box go to the nearest leaf along each
        cut).
        """
        region = self.root
        while region.children is not None:
            region = region.children[int(point[region.split_dimension] >= region.split_value)]
        return region

    def LeavesContaining(self, point: np.ndarray, dimensions: np.ndarray) -> list[Region]:
        """Leaves whose box holds point in the given dimensions, whatever their other coordinates.

        Args:
            point: (d,) coordinates; only those in `dimensions` are read.
            dimensions: (d,) booleans; True where the coordinate constrains the leaves.

        Returns:
            The leaves (together they cover the free dimensions).
        """
        found, stack = [], [self.root]
        while stack:
            region = stack.pop()
            if region.children is None:
                found.append(region)
            elif dimensions[region.split_dimension]:
                stack.append(
                    region.children[int(point[region.split_dimension] >= region.split_value)]
                )
            else:
                stack.extend(region.children)
        return found

    def Measure(self, values: list[float]) -> float:
        """A region's measure for eq. 3 from its competences in time order: eq. 2 (the paper), or
        their spread (InterestConfig.region_measure)."""
        window = self.config.window
        if self.config.region_measure == "variance":
            return CompetenceSpread(values, window)
        return Interest(values[-window:], window)

    def Add(self, point: np.ndarray, value: float) -> Region:
        """Records a competence at a point, updates its leaf's interest (eq. 2); splits past g_max.

        Args:
            point: Where the attempt was aimed.
            value: Its competence.

        Returns:
            The leaf that received the point (before any split).
        """
        leaf = self.Leaf(point)
        leaf.points.append(np.asarray(point, dtype=float))
        leaf.values.append(float(value))
        leaf.interest = self.Measure(leaf.values)
        self.num_points += 1
        if len(leaf.values) > self.config.max_region_goals:
            self._Split(leaf)
        return leaf

    def _Split(self, region: Region) -> None:
        points, values = np.array(region.points), np.array(region.values)
        split = BestSplit(
            points,
            values,
            self.config.window,
            self.config.min_child_goals,
            weighted=self.config.split_criterion == "weighted",
        )
        if split is None:
            return
        dimension, cut = split
        lower_high, upper_low = region.high.copy(), region.low.copy()
        lower_high[dimension] = cut
        upper_low[dimension] = cut
        children = (
            Region(low=region.low.copy(), high=lower_high, born=self.num_points),
            Region(low=upper_low, high=region.high.copy(), born=self.num_points),
        )
        for point, value in zip(region.points, region.values, strict=True):
            child = children[int(point[dimension] >= cut)]
            child.points.append(point)
            child.values.append(value)
        for child in children:
            child.interest = self.Measure(child.values)
        region.children, region.split_dimension, region.split_value = children, dimension, cut
        region.split_at = self.num_points
        index = next(i for i, leaf in enumerate(self.leaves) if leaf is region)
        self.leaves[index : index + 1] = list(children)
        self.all_regions.extend(children)

    def LeavesAt(self, num_points: int) -> list[Region]:
        """The leaves as they were once the tree had received num_points points (for Fig. 3-like
        plots).
        """
        return [
            region
            for region in self.all_regions
            if region.born <= num_points
            and (region.split_at is None or region.split_at > num_points)
        ]


def SelectIndex(
    interests: np.ndarray,
    rng: np.random.Generator,
    probabilities: tuple[float, float, float],
    lowest_competence,
) -> tuple[int, int | None]:
    """Draws a selection mode and the index of the region it picks (Sec. II-D-3).

    mode 1 (p_1): an index drawn with eq. 3 over ``interests``; mode 2 (p_2): None, meaning the
    whole space; mode 3 (p_3): ``lowest_competence()``, the index of the region of lowest mean
    competence (eq. 1; called only in mode 3).

    Args:
        interests: (m,) interests of the candidate regions.
        rng: The learner's generator.
        probabilities: (p_1, p_2, p_3).
        lowest_competence: Callable returning the mode-3 index.

    Returns:
        (mode in {1, 2, 3}, index or None).
    """
    mode = int(rng.choice(3, p=np.asarray(probabilities) / np.sum(probabilities))) + 1
    if mode == 1:
        weights = InterestProbabilities(interests)
        return mode, int(rng.choice(len(weights), p=weights))
    if mode == 3:
        return mode, int(lowest_competence())
    return mode, None


def SelectRegion(
    leaves: list[Region], rng: np.random.Generator, probabilities: tuple[float, float, float]
) -> tuple[int, Region | None]:
    """Draws a selection mode and the region it picks (Sec. II-D-3), see SelectIndex.

    mode 1 (p_1): a leaf drawn with eq. 3; mode 2 (p_2): None, meaning the whole space; mode 3
    (p_3): the leaf of lowest mean competence (eq. 1), ties to the first.

    Args:
        leaves: Candidate regions (all non-empty).
        rng: The learner's generator.
        probabilities: (p_1, p_2, p_3).

    Returns:
        (mode in {1, 2, 3}, region or None).
    """
    mode, index = SelectIndex(
        [leaf.interest for leaf in leaves],
        rng,
        probabilities,
        lambda: np.argmin([leaf.MeanCompetence() for leaf in leaves]),
    )
    return mode, None if index is None else leaves[index]
