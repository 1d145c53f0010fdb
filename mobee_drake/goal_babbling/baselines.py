"""The three baselines of Baranes & Oudeyer (IROS 2010), Sec. IV-B-1: SAGG-Random, ACTUATOR-Random,
ACTUATOR-RIAC.
"""

import numpy as np

from mobee_drake.goal_babbling.low_level import Learner
from mobee_drake.goal_babbling.regions import RegionTree, SelectIndex, SelectRegion
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
    """Motor babbling: a small random micro-action every step (Sec. IV-B-1).

    ActuatorConfig.reading "walk" (the reference): the arm keeps its state, back to rest every
    "max" steps. "set": each step first puts the arm in a posture drawn uniformly in the posture
    box (free, like the rest reset), so the samples do not depend on one another.
    """

    name = "ACTUATOR-Random"

    def _Loop(self) -> None:
        if self.config.actuator.reading == "set":
            num_joints = self.config.arm.num_joints
            limit = self.config.actuator.posture_range
            while True:
                self.arm.SetJointAngles(self.rng.uniform(-limit, limit, num_joints))
                self.Act(self.RandomJointStep())
        period = self.config.ActuatorResetPeriod()
        while True:
            self.arm.Reset()
            for _ in range(period):
                self.Act(self.RandomJointStep())


class ActuatorRiac(Learner):
    """R-IAC in the actuator space: regions of (theta, dtheta) chosen by prediction-error decrease.

    The "competence" recorded is minus the prediction error ||dx - J dtheta|| of the local model
    before the sample is stored, so eq. 2 measures the decrease of prediction error. How the
    learner acts given the arm's state is ActuatorConfig.reading (the paper does not say):

    * "walk" (the reference): the arm cannot jump to a region's theta, so at each step the
      candidates are the leaves whose theta-box holds the current theta (together they cover the
      whole dtheta-box); a mode and a leaf are drawn among them as in Sec. II-D-3 (mode 3: the
      leaf of largest mean prediction error) and dtheta is drawn uniformly in its dtheta-box. Back
      to rest every "max" steps, as ACTUATOR-Random. A leaf whose dtheta-box is one-signed in some
      joints, chosen again and again, makes the arm drift.
    * "set": R-IAC as on a stateless robot: a mode and a leaf are drawn among all leaves, a point
      (theta, dtheta) uniformly in it (mode 2: in the whole box, theta within
      ActuatorConfig.posture_range); the arm is put at theta (free, like the rest reset) and makes
      dtheta. No drift is possible.

    Attributes:
        tree: Regions of the 2n-dimensional space (theta, dtheta).
    """

    name = "ACTUATOR-RIAC"

    def __init__(self, config, evaluator=None):
        super().__init__(config, evaluator)
        num_joints = config.arm.num_joints
        posture_limit = (
            config.actuator.posture_range
            if config.actuator.reading == "set"
            else config.arm.joint_limit
        )
        low = np.concatenate(
            [
                np.full(num_joints, -posture_limit),
                np.full(num_joints, -config.low_level.exploration_joint_step),
            ]
        )
        self.tree = RegionTree(low, -low, config.interest)
        self._state_dimensions = np.arange(2 * num_joints) < num_joints
        # "set" reading: the leaves' interests and mean competences as arrays, in slots of our
        # own (a split puts the lower child in its parent's slot and appends the upper one).
        self._slots = {id(self.tree.root): 0}
        self._slot_leaves = [self.tree.root]
        self._interests = np.zeros(1)
        self._mean_competences = np.zeros(1)

    def SelectJointStep(self) -> np.ndarray:
        """A micro-action chosen by R-IAC given the current theta ("walk" reading).

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

    def SelectPoint(self) -> np.ndarray:
        """A point (theta, dtheta) chosen by R-IAC among all regions ("set" reading).

        Returns:
            (2n,) posture and joint step.
        """
        root = self.tree.root
        if len(self.tree.leaves) < 2:
            return root.Sample(self.rng)
        _, slot = SelectIndex(
            self._interests,
            self.rng,
            self.config.interest.mode_probabilities,
            # Mode 3: the region of largest mean prediction error = lowest mean "competence".
            lambda: np.argmin(self._mean_competences),
        )
        return (root if slot is None else self._slot_leaves[slot]).Sample(self.rng)

    def _Record(self, point: np.ndarray, error: float) -> None:
        """Adds a sample's prediction error to the tree and keeps the slot arrays in step."""
        leaf = self.tree.Add(point, -error)
        slot = self._slots[id(leaf)]
        if leaf.children is None:
            self._interests[slot] = leaf.interest
            self._mean_competences[slot] = leaf.MeanCompetence()
            return
        lower, upper = leaf.children
        del self._slots[id(leaf)]
        self._slots[id(lower)] = slot
        self._slots[id(upper)] = len(self._slot_leaves)
        self._slot_leaves[slot] = lower
        self._slot_leaves.append(upper)
        self._interests[slot] = lower.interest
        self._interests = np.append(self._interests, upper.interest)
        self._mean_competences[slot] = lower.MeanCompetence()
        self._mean_competences = np.append(self._mean_competences, upper.MeanCompetence())

    def _PredictionError(self, joint_step: np.ndarray) -> tuple[np.ndarray, float]:
        """Performs joint_step after predicting its tip step with the local model (J = 0 while the
        memory is empty); returns the angles before it and the prediction error."""
        joint_angles = self.arm.joint_angles
        predicted = np.zeros(2)
        if self.memory.size:
            jacobians, _, _ = self.memory.EstimateJacobians(
                joint_angles[None], self.config.low_level.num_neighbours
            )
            predicted = jacobians[0] @ joint_step
        displacement = self.Act(joint_step)
        return joint_angles, float(np.linalg.norm(displacement - predicted))

    def _Loop(self) -> None:
        num_joints = self.config.arm.num_joints
        if self.config.actuator.reading == "set":
            while True:
                point = self.SelectPoint()
                self.arm.SetJointAngles(point[:num_joints])
                _, error = self._PredictionError(point[num_joints:])
                self._Record(point, error)
        period = self.config.ActuatorResetPeriod()
        while True:
            self.arm.Reset()
            for _ in range(period):
                joint_step = self.SelectJointStep()
                joint_angles, error = self._PredictionError(joint_step)
                self.tree.Add(np.concatenate([joint_angles, joint_step]), -error)
