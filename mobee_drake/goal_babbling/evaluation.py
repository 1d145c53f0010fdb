"""Evaluation of the learnt inverse and forward models (Baranes & Oudeyer 2010, Sec. IV-B).

Reaching error: distance between test goal and final tip after a test reach that uses the learnt
inverse model only (no exploration, no learning; the memory is frozen); reported as the mean over
the test goals (the paper's), their median and the share of goals reached within
EvaluationConfig.reached_distance. Prediction error: mean distance between the true tip and the
learnt forward model's prediction on test joint configurations, on two sets: the postures that
reach uniformly drawn reachable goals (the main set since issue 23) and configurations near rest
(the earlier set, kept as a sensitivity check). All test sets are fixed by
EvaluationConfig.test_set_seed, so all learners and seeds are measured on the same goals and
configurations.
"""

import dataclasses
import functools
import json

import numpy as np

from mobee_drake.goal_babbling.config import ConfigFromDict, ConfigToDict, GoalBabblingConfig
from mobee_drake.goal_babbling.low_level import (
    DesiredDisplacements,
    ReachingJointSteps,
    SensorimotorMemory,
)
from mobee_drake.goal_babbling.planar_arm import ForwardKinematics, LinkLengths

# The measures of one evaluation, in the order of the reports.
MEASURES = (
    "reaching_error",
    "reaching_error_median",
    "reached_share",
    "prediction_error",
    "prediction_error_near_rest",
)
# Most steps of the true-Jacobian reaches that make the reachable-area postures.
POSTURE_STEPS = 2000


@dataclasses.dataclass
class TestSet:
    """Test goals and test configurations.

    Attributes:
        goals: (N, 2) goals uniform (by area) in the half-disc x >= 0, |x| <= L.
        configurations: (M, n) near-rest joint angles, each uniform in [-test_joint_range,
            test_joint_range].
        positions: (M, 2) their true tips.
        reachable_goals: (M, 2) goals uniform (by area) in the same half-disc, drawn for the main
            prediction-error set.
        reachable_configurations: (M, n) the postures that reach them (see ReachablePostures).
        reachable_positions: (M, 2) their true tips.
    """

    goals: np.ndarray
    configurations: np.ndarray
    positions: np.ndarray
    reachable_goals: np.ndarray
    reachable_configurations: np.ndarray
    reachable_positions: np.ndarray


def UniformHalfDisc(rng: np.random.Generator, radius: float, count: int) -> np.ndarray:
    """Points uniform (by area) in the half-disc x >= 0 of the given radius.

    Args:
        rng: Generator.
        radius: L.
        count: How many.

    Returns:
        (count, 2) points.
    """
    radii = radius * np.sqrt(rng.uniform(0.0, 1.0, count))
    angles = rng.uniform(-np.pi / 2, np.pi / 2, count)
    return np.stack([radii * np.cos(angles), radii * np.sin(angles)], axis=1)


def TrueJacobians(joint_angles: np.ndarray, link_lengths: np.ndarray) -> np.ndarray:
    """The arm's exact Jacobians dx / dtheta (relative angles): column i is the sum over links j >=
    i of l_j (-sin phi_j, cos phi_j), phi_j the absolute angle of link j.

    Args:
        joint_angles: (m, n) joint angles.
        link_lengths: (n,) link lengths.

    Returns:
        (m, 2, n) Jacobians.
    """
    absolute = np.cumsum(joint_angles, axis=-1)
    columns_x = np.cumsum((-np.sin(absolute) * link_lengths)[:, ::-1], axis=-1)[:, ::-1]
    columns_y = np.cumsum((np.cos(absolute) * link_lengths)[:, ::-1], axis=-1)[:, ::-1]
    return np.stack([columns_x, columns_y], axis=1)


def ReachablePostures(goals: np.ndarray, config: GoalBabblingConfig) -> np.ndarray:
    """Postures that reach ``goals``, found from rest by the low level's controller with the true
    Jacobian: tip steps of v straight at the goal, dtheta = J^+ dx capped at max_joint_step,
    joints clipped to their limits, until within EvaluationConfig.tolerance / 10 or POSTURE_STEPS.

    Args:
        goals: (m, 2) reachable goals.
        config: Arm and low-level parameters.

    Returns:
        (m, n) postures (their tips: ForwardKinematics).
    """
    arm, low_level = config.arm, config.low_level
    link_lengths = LinkLengths(arm)
    angles = np.zeros((len(goals), arm.num_joints))
    for _ in range(POSTURE_STEPS):
        positions = ForwardKinematics(angles, link_lengths)
        active = np.flatnonzero(
            np.linalg.norm(goals - positions, axis=1) > config.evaluation.tolerance / 10
        )
        if active.size == 0:
            break
        desired = DesiredDisplacements(positions[active], goals[active], low_level.velocity)
        steps = ReachingJointSteps(
            TrueJacobians(angles[active], link_lengths), desired, low_level.max_joint_step
        )
        angles[active] = np.clip(angles[active] + steps, -arm.joint_limit, arm.joint_limit)
    return angles


@functools.lru_cache(maxsize=8)
def _CachedTestSet(config_json: str) -> TestSet:
    config = ConfigFromDict(json.loads(config_json))
    evaluation, arm = config.evaluation, config.arm
    rng = np.random.default_rng(evaluation.test_set_seed)
    goals = UniformHalfDisc(rng, arm.total_length, evaluation.num_test_goals)
    configurations = rng.uniform(
        -evaluation.test_joint_range,
        evaluation.test_joint_range,
        (evaluation.num_test_configurations, arm.num_joints),
    )
    # The main prediction set draws from its own stream, so the sets above are those of the
    # earlier evaluation.
    reachable_goals = UniformHalfDisc(
        np.random.default_rng([evaluation.test_set_seed, 1]),
        arm.total_length,
        evaluation.num_test_configurations,
    )
    reachable_configurations = ReachablePostures(reachable_goals, config)
    link_lengths = LinkLengths(arm)
    test_set = TestSet(
        goals=goals,
        configurations=configurations,
        positions=ForwardKinematics(configurations, link_lengths),
        reachable_goals=reachable_goals,
        reachable_configurations=reachable_configurations,
        reachable_positions=ForwardKinematics(reachable_configurations, link_lengths),
    )
    for field in dataclasses.fields(test_set):
        getattr(test_set, field.name).flags.writeable = False
    return test_set


def MakeTestSet(config: GoalBabblingConfig) -> TestSet:
    """Draws the test sets from their own seed (cached: runs of one process share them).

    The test goals and the near-rest configurations come from default_rng(test_set_seed), in
    that order (the sets of the earlier evaluation); the reachable-area goals from
    default_rng([test_set_seed, 1]).

    Args:
        config: Arm, low-level and evaluation parameters.

    Returns:
        The test set (read-only arrays).
    """
    data = ConfigToDict(config)
    relevant = {
        "arm": data["arm"],
        "low_level": {
            "velocity": data["low_level"]["velocity"],
            "max_joint_step": data["low_level"]["max_joint_step"],
        },
        "evaluation": data["evaluation"],
    }
    return _CachedTestSet(json.dumps(relevant, sort_keys=True))


def TestReaches(
    memory: SensorimotorMemory,
    config: GoalBabblingConfig,
    start_angles: np.ndarray,
    goals: np.ndarray,
) -> np.ndarray:
    """Reaches several goals in lockstep with the learnt inverse model (eq. 6), without learning.

    Each reach stops within EvaluationConfig.tolerance of its goal or after ceil(timeout_per_unit D
    / v) steps. With an empty memory the arm does not move.

    Args:
        memory: The learner's memory (read only).
        config: Arm, low-level and evaluation parameters.
        start_angles: (m, n) joint angles at the start.
        goals: (m, 2) goals.

    Returns:
        (m, n) final joint angles.
    """
    low_level, arm = config.low_level, config.arm
    link_lengths = LinkLengths(arm)
    angles = np.array(start_angles, dtype=float)
    positions = ForwardKinematics(angles, link_lengths)
    if memory.size == 0:
        return angles
    distances = np.linalg.norm(goals - positions, axis=1)
    timeouts = np.ceil(low_level.timeout_per_unit * distances / low_level.velocity)
    for step in range(int(timeouts.max(initial=0))):
        active = np.flatnonzero((step < timeouts) & (distances > config.evaluation.tolerance))
        if active.size == 0:
            break
        desired = DesiredDisplacements(positions[active], goals[active], low_level.velocity)
        jacobians, _, _ = memory.EstimateJacobians(angles[active], low_level.num_neighbours)
        steps = ReachingJointSteps(jacobians, desired, low_level.max_joint_step)
        angles[active] = np.clip(angles[active] + steps, -arm.joint_limit, arm.joint_limit)
        positions[active] = ForwardKinematics(angles[active], link_lengths)
        distances[active] = np.linalg.norm(goals[active] - positions[active], axis=1)
    return angles


def ReachingErrors(
    memory: SensorimotorMemory, config: GoalBabblingConfig, goals: np.ndarray
) -> np.ndarray:
    """Final distances to the test goals; goal 2i starts at rest, goal 2i+1 where goal 2i ended.

    Args:
        memory: The learner's memory (read only).
        config: Parameters.
        goals: (N, 2) test goals.

    Returns:
        (N,) final goal-tip distances.
    """
    link_lengths = LinkLengths(config.arm)
    first, second = goals[0::2], goals[1::2]
    first_final = TestReaches(memory, config, np.zeros((len(first), config.arm.num_joints)), first)
    second_final = TestReaches(memory, config, first_final[: len(second)], second)
    errors = np.empty(len(goals))
    errors[0::2] = np.linalg.norm(ForwardKinematics(first_final, link_lengths) - first, axis=1)
    errors[1::2] = np.linalg.norm(ForwardKinematics(second_final, link_lengths) - second, axis=1)
    return errors


def PredictionErrors(
    memory: SensorimotorMemory,
    config: GoalBabblingConfig,
    configurations: np.ndarray,
    positions: np.ndarray,
    rest_position: np.ndarray,
) -> np.ndarray:
    """Forward-model errors ||x_predicted - x_true|| on test configurations.

    Args:
        memory: The learner's memory (read only).
        config: Parameters.
        configurations: (M, n) test joint angles.
        positions: (M, 2) their true tips.
        rest_position: Prediction used while the memory is empty (the one tip the robot has seen).

    Returns:
        (M,) errors.
    """
    if memory.size == 0:
        predicted = np.broadcast_to(rest_position, positions.shape)
    else:
        predicted = memory.PredictPositions(configurations, config.low_level.num_neighbours)
    return np.linalg.norm(predicted - positions, axis=1)


class Evaluator:
    """The evaluation a Learner calls at its checkpoints.

    Attributes:
        config: Parameters (the test sets are drawn from config.evaluation.test_set_seed).
        test_set: The test sets.
        reaching_errors: (N,) the final distances of the last evaluation's test reaches (None
            before the first).
    """

    def __init__(self, config: GoalBabblingConfig):
        self.config = config
        self.test_set = MakeTestSet(config)
        self.reaching_errors = None

    def __call__(self, memory: SensorimotorMemory, rest_position: np.ndarray) -> dict:
        """Evaluates a memory (a frozen snapshot of it).

        Returns:
            {measure: value} for every name in MEASURES.
        """
        memory, test_set = memory.Snapshot(), self.test_set
        errors = ReachingErrors(memory, self.config, test_set.goals)
        self.reaching_errors = errors
        reachable = PredictionErrors(
            memory,
            self.config,
            test_set.reachable_configurations,
            test_set.reachable_positions,
            rest_position,
        )
        near_rest = PredictionErrors(
            memory, self.config, test_set.configurations, test_set.positions, rest_position
        )
        return {
            "reaching_error": float(np.mean(errors)),
            "reaching_error_median": float(np.median(errors)),
            "reached_share": float(np.mean(errors <= self.config.evaluation.reached_distance)),
            "prediction_error": float(np.mean(reachable)),
            "prediction_error_near_rest": float(np.mean(near_rest)),
        }


def MakeEvaluator(config: GoalBabblingConfig) -> Evaluator:
    """The evaluator a Learner calls at its checkpoints.

    Args:
        config: Parameters (the test sets are drawn from config.evaluation.test_set_seed).

    Returns:
        callable(memory, rest_position) -> {measure: value} for every name in MEASURES.
    """
    return Evaluator(config)
