"""The three baselines of Baranes & Oudeyer (IROS 2010), Sec. IV-B-1: SAGG-Random, ACTUATOR-Random,
ACTUATOR-RIAC.
"""

import numpy as np

from mobee_drake.goal_babbling.low_level import Learner
from mobee_drake.goal_babbling.regions import RegionTree, SelectRegion
from mobee_drake.goal_babbling.sagg_riac import SaggRiac


class SaggRandom(SaggRiac):
    """SAGG-RIAC with its higher level disabled: every goal uniform in S' (same low level, subgoals,
    resets).
    """

    name = "SAGG-Random"

    def SelectGoal(self) -> tuple[np.ndarray, int]:
        """A goal uniform in S'.

        Returns:
            (goal, 2).
        """
        return self.rng.uniform(self.goal_space_low, self.goal_space_high), 2


class ActuatorRandom(Learner):
    """Motor babbling: a small random micro-action every step, back to rest every "max" steps (Sec.
    IV-B-1).
    """

    name = "ACTUATOR-Random"

    def _Loop(self) -> None:
        period = self.config.ActuatorResetPeriod()
        while True:
            self.arm.Reset()
            for _ in range(period):
                self.Act(self.RandomJointStep())


class ActuatorRiac(Learner):
    """R-IAC in the actuator space: regions of (theta, dtheta) chosen by prediction-error decrease.

    The arm cannot jump to a region's theta, so at each step the candidates are the leaves whose
    theta-box holds the current theta (together they cover the whole dtheta-box); a mode and a leaf
    are drawn among them as in Sec. II-D-3 (mode 3: the leaf of largest mean prediction error) and
    dtheta is drawn uniformly in its dtheta-box (our reading of R-IAC with a state context). The
    "competence" recorded is minus the prediction error ||dx - J dtheta|| of the local model before
    the sample is stored, so eq. 2 measures the decrease of prediction error. Back to rest every
    "max" steps, as ACTUATOR-Random.

    Attributes:
        tree: Regions of the 2n-dimensional space (theta, dtheta).
    """

    name = "ACTUATOR-RIAC"

    def __init__(self, config, evaluator=None):
        super().__init__(config, evaluator)
        num_joints = config.arm.num_joints
        low = np.concatenate(
            [
                np.full(num_joints, -config.arm.joint_limit),
                np.full(num_joints, -config.low_level.exploration_joint_step),
            ]
        )
        self.tree = RegionTree(low, -low, config.interest)
        self._state_dimensions = np.arange(2 * num_joints) < num_joints

    def SelectJointStep(self) -> np.ndarray:
        """A micro-action chosen by R-IAC given the current theta.

        Returns:
            (n,) joint step.
        """
        if len(self.tree.leaves) < 2:
            return self.RandomJointStep()
        num_joints = self.config.arm.num_joints
        point = np.concatenate([self.arm.joint_angles, np.zeros(num_joints)])
        candidates = self.tree.LeavesContaining(point, self._state_dimensions)
        _, region = SelectRegion(candidates, self.rng, self.config.interest.mode_probabilities)
        if region is None:
            return self.RandomJointStep()
        return self.rng.uniform(region.low[num_joints:], region.high[num_joints:])

    def _Loop(self) -> None:
        period = self.config.ActuatorResetPeriod()
        while True:
            self.arm.Reset()
            for _ in range(period):
                joint_step = self.SelectJointStep()
                joint_angles = self.arm.joint_angles
                # Predict with the local model before the move (J = 0 while the memory is empty),
                # then learn.
                predicted = np.zeros(2)
                if self.memory.size:
                    jacobians, _, _ = self.memory.EstimateJacobians(
                        joint_angles[None], self.config.low_level.num_neighbours
                    )
                    predicted = jacobians[0] @ joint_step
                displacement = self.Act(joint_step)
                error = float(np.linalg.norm(displacement - predicted))
                self.tree.Add(np.concatenate([joint_angles, joint_step]), -error)
