"""Evaluation of the learnt inverse and forward models (Baranes & Oudeyer 2010, Sec. IV-B).

Reaching error: mean distance between test goal and final tip after a test reach that uses the
learnt inverse model only (no exploration, no learning; the memory is frozen). Prediction error:
mean distance between the true tip and the learnt forward model's prediction on test joint
configurations. Both test sets are fixed by EvaluationConfig.test_set_seed, so all learners and
seeds are measured on the same goals and configurations.
"""

import dataclasses

import numpy as np

from mobee_drake.goal_babbling.config import GoalBabblingConfig
from mobee_drake.goal_babbling.low_level import (
    DesiredDisplacements,
    ReachingJointSteps,
    SensorimotorMemory,
)
from mobee_drake.goal_babbling.planar_arm import ForwardKinematics, LinkLengths


@dataclasses.dataclass
class TestSet:
    """Test goals and test configurations.

    Attributes:
        goals: (N, 2) goals uniform (by area) in the half-disc x >= 0, |x| <= L.
        configurations: (M, n) joint angles, each uniform in [-test_joint_range, test_joint_range].
        positions: (M, 2) their true tips.
    """

    goals: np.ndarray
    configurations: np.ndarray
    positions: np.ndarray


def MakeTestSet(config: GoalBabblingConfig) -> TestSet:
    """Draws the test set from its own seed.

    Args:
        config: Arm and evaluation parameters.

    Returns:
        The test set.
    """
    evaluation, arm = config.evaluation, config.arm
    rng = np.random.default_rng(evaluation.test_set_seed)
    radii = arm.total_length * np.sqrt(rng.uniform(0.0, 1.0, evaluation.num_test_goals))
    angles = rng.uniform(-np.pi / 2, np.pi / 2, evaluation.num_test_goals)
    goals = np.stack([radii * np.cos(angles), radii * np.sin(angles)], axis=1)
    configurations = rng.uniform(
        -evaluation.test_joint_range,
        evaluation.test_joint_range,
        (evaluation.num_test_configurations, arm.num_joints),
    )
    return TestSet(
        goals=goals,
        configurations=configurations,
        positions=ForwardKinematics(configurations, LinkLengths(arm)),
    )


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
    test_set: TestSet,
    rest_position: np.ndarray,
) -> np.ndarray:
    """Forward-model errors ||x_predicted - x_true|| on the test configurations.

    Args:
        memory: The learner's memory (read only).
        config: Parameters.
        test_set: Test configurations and their true tips.
        rest_position: Prediction used while the memory is empty (the one tip the robot has seen).

    Returns:
        (M,) errors.
    """
    if memory.size == 0:
        predicted = np.broadcast_to(rest_position, test_set.positions.shape)
    else:
        predicted = memory.PredictPositions(
            test_set.configurations, config.low_level.num_neighbours
        )
    return np.linalg.norm(predicted - test_set.positions, axis=1)


def MakeEvaluator(config: GoalBabblingConfig):
    """The evaluator a Learner calls at its checkpoints.

    Args:
        config: Parameters (the test set is drawn from config.evaluation.test_set_seed).

    Returns:
        callable(memory, rest_position) -> {"reaching_error": mean, "prediction_error": mean}.
    """
    test_set = MakeTestSet(config)

    def Evaluate(memory: SensorimotorMemory, rest_position: np.ndarray) -> dict:
        memory = memory.Snapshot()
        return {
            "reaching_error": float(np.mean(ReachingErrors(memory, config, test_set.goals))),
            "prediction_error": float(
                np.mean(PredictionErrors(memory, config, test_set, rest_position))
            ),
        }

    return Evaluate
