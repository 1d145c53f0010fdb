"""Goal babbling for the reach learner: SAGG-RIAC choosing palm targets (Baranes & Oudeyer 2010).

The fourth exploration strategy of :mod:`mobee_drake.reaching.learner` (``goal_babbling``) does
not cycle through the 27 problems: it poses its own reach targets anywhere in the workspace they
cover, with the goal-selection machinery of SAGG-RIAC (:mod:`mobee_drake.goal_babbling.regions`):
uniform goals until the goal space is first split, then the three modes (interest, eq. 3; uniform;
lowest mean competence, eq. 1), the region tree split past g_max goals where the halves' interests
(eq. 2) differ most. Each goal is one problem-try: the greedy optimistic policy (eq. 8.1, 8.5)
plans the transitions and the reach toward it (the low level: MDP planning and MoBeE's workspace
forcing instead of SAGG-RIAC's learned Jacobian); its competence is eq. 7 and Sec. II-D-1.

Choices where neither source says:

- the goal space is the box around the problems' targets, grown by ``margin`` (the targets'
  radius by default): the region the 27 problems sample, so the evaluations measure the same task;
- ``x_start`` of eq. 7 is where the palm was when the problem-try began (before its transitions):
  the attempt is the whole policy, and a pre-reach pose close to the goal is not penalised for
  leaving little distance to close;
- a problem-try that times out without a reach gets the lowest competence, min_C.
"""

import dataclasses as dc

import numpy as np

from mobee_drake.goal_babbling.competence import Competence, ReachingCost
from mobee_drake.goal_babbling.config import InterestConfig
from mobee_drake.goal_babbling.regions import RegionTree, SelectRegion


@dc.dataclass
class ReachGoalsConfig:
    """The goal selection of SAGG-RIAC (g_max, zeta, the modes, eps_C, min_C) and the space."""

    interest: InterestConfig = dc.field(default_factory=InterestConfig)
    # The goal space: the targets' bounding box grown by this much on every side (m).
    margin: float = 0.05

    def Validate(self) -> None:
        if not self.margin >= 0:
            raise ValueError(f"the goal space's margin must be >= 0, got {self.margin}")


class GoalBabbler:
    """Chooses reach goals by competence progress and records the competence of each attempt."""

    def __init__(self, targets: np.ndarray, config: ReachGoalsConfig):
        config.Validate()
        self.config = config
        self.low = targets.min(axis=0) - config.margin
        self.high = targets.max(axis=0) + config.margin
        self.tree = RegionTree(self.low, self.high, config.interest)
        # Every attempt: the goal and its competence, in order (the tree is rebuilt from them).
        self.goals: list[np.ndarray] = []
        self.competences: list[float] = []

    def Select(self, rng: np.random.Generator) -> np.ndarray:
        """The next goal: uniform in the goal space until its first split, then modes 1-3."""
        if len(self.tree.leaves) > 1:
            _, region = SelectRegion(self.tree.leaves, rng, self.config.interest.mode_probabilities)
            if region is not None:
                return region.Sample(rng)
        return rng.uniform(self.low, self.high)

    def Record(self, goal: np.ndarray, start: np.ndarray, reached: np.ndarray | None) -> float:
        """Adds an attempt at ``goal`` from palm position ``start`` that ended at ``reached``
        (None: timed out) to the tree; returns its competence (eq. 7, Sec. II-D-1)."""
        interest = self.config.interest
        if reached is None:
            competence = interest.min_competence
        else:
            competence = Competence(
                ReachingCost(goal, reached, start, interest.min_competence),
                interest.competence_tolerance,
                interest.min_competence,
            )
        self._Add(goal, competence)
        return competence

    def _Add(self, goal, competence: float) -> None:
        goal = np.asarray(goal, dtype=float)
        self.tree.Add(goal, competence)
        self.goals.append(goal)
        self.competences.append(competence)

    def ToArrays(self) -> dict[str, np.ndarray]:
        return dict(
            goals=np.array(self.goals, dtype=float).reshape(-1, 3),
            goal_competences=np.array(self.competences, dtype=float),
        )

    def LoadArrays(self, arrays) -> None:
        """Replays saved attempts into this (fresh) babbler: the same tree, split for split."""
        for goal, competence in zip(arrays["goals"], arrays["goal_competences"], strict=True):
            self._Add(goal, float(competence))
