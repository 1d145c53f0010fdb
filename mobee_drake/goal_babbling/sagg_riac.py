"""SAGG-RIAC: self-adaptive goal generation over the SSA-like low level (Baranes & Oudeyer, IROS
2010, Alg. 1).
"""

import numpy as np

from mobee_drake.goal_babbling.low_level import Learner
from mobee_drake.goal_babbling.regions import RegionTree, SelectRegion


class SaggRiac(Learner):
    """Goal babbling in S' with goals chosen by competence progress (Sec. II-D, Algorithm 1).

    Every r goal attempts the arm returns to rest (Sec. II-D-4). Each goal is approached through l
    subgoals x_i = x_start + (i / l) (x_g - x_start) (Sec. III-C-2; the paper prints (i / l)(x_g -
    x_start), which omits the start), each a reaching attempt whose competence is recorded in the
    region holding it. Subgoals that fall outside S' (possible when the arm starts outside it) are
    attempted but not recorded (our choice).

    Attributes:
        tree: The regions of S'.
        goal_log: One row per (sub)goal: time step at its end, x, y, competence, mode (0 for a
            subgoal that is not a goal), goal index, points recorded in the tree so far.
    """

    name = "SAGG-RIAC"

    def __init__(self, config, evaluator=None):
        super().__init__(config, evaluator)
        self.goal_space_low = np.asarray(config.goal_space_low, dtype=float)
        self.goal_space_high = np.asarray(config.goal_space_high, dtype=float)
        self.tree = RegionTree(self.goal_space_low, self.goal_space_high, config.interest)
        self.goal_log = []

    def SelectGoal(self) -> tuple[np.ndarray, int]:
        """Goal self-generation (Sec. II-D-3): uniform in S' until the first split, then modes 1-3.

        Returns:
            (goal, mode); mode 2 also stands for the initial uniform draws.
        """
        if len(self.tree.leaves) < 2:
            return self.rng.uniform(self.goal_space_low, self.goal_space_high), 2
        mode, region = SelectRegion(
            self.tree.leaves, self.rng, self.config.interest.mode_probabilities
        )
        if region is None:
            return self.rng.uniform(self.goal_space_low, self.goal_space_high), mode
        return region.Sample(self.rng), mode

    def _Loop(self) -> None:
        attempt = 0
        while True:
            if attempt % self.config.reset_every_attempts == 0:
                self.arm.Reset()
            goal, mode = self.SelectGoal()
            start = self.arm.position.copy()
            num_subgoals = self.config.num_subgoals
            for index in range(1, num_subgoals + 1):
                subgoal = start + (index / num_subgoals) * (goal - start)
                competence = self.ReachGoal(subgoal)
                if np.all(subgoal >= self.goal_space_low) and np.all(
                    subgoal <= self.goal_space_high
                ):
                    self.tree.Add(subgoal, competence)
                is_goal = index == num_subgoals
                self.goal_log.append(
                    (
                        self.time_steps,
                        subgoal[0],
                        subgoal[1],
                        competence,
                        mode if is_goal else 0,
                        attempt,
                        self.tree.num_points,
                    )
                )
            attempt += 1
