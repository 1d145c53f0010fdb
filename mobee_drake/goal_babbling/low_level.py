"""Memory-based local models and the SSA-like low level of SAGG-RIAC (Baranes & Oudeyer 2010).

The robot stores every micro-action as (theta, x, dtheta, dx). The Jacobian at theta is estimated by
least squares (Moore-Penrose pseudo-inverse) on the k stored micro-actions nearest to theta in joint
space (eq. 4-5, Sec. III-B), and inverted with the pseudo-inverse to pick the joint step for a
desired tip step (eq. 6).

Nearest neighbours: a scipy cKDTree over most of the memory (optionally approximate, as the paper's
ANN) plus exact brute force over the newest samples; the tree is rebuilt only when that tail grows
past about 3 sqrt(size) samples, so no step rebuilds it from scratch.
"""

import abc
import math

import numpy as np
from scipy.spatial import cKDTree

from mobee_drake.goal_babbling.competence import Competence, ReachingCost
from mobee_drake.goal_babbling.config import CheckConfig, GoalBabblingConfig
from mobee_drake.goal_babbling.planar_arm import PlanarArm


def PseudoInverseSolve(matrices: np.ndarray, right_hand_sides: np.ndarray) -> np.ndarray:
    """X = A^+ B for a stack of matrices A, A^+ the Moore-Penrose pseudo-inverse (eq. 6).

    Computed through the smaller Gram matrix, A^+ = (A^T A + lambda I)^-1 A^T or A^T (A A^T + lambda
    I)^-1, with lambda = 1e-9 trace / size: the Tikhonov limit of the pseudo-inverse. It differs
    from A^+ B by about lambda / sigma_min^2 relative (1e-7 on random 30 x 15 matrices), gives
    zero null-space components like A^+, and is about ten times faster than numpy's batched SVD
    (our choice, for speed).

    Args:
        matrices: (m, r, c) matrices A.
        right_hand_sides: (m, r, p) matrices B.

    Returns:
        (m, c, p) solutions.
    """
    transposed = np.swapaxes(matrices, 1, 2)
    rows, columns = matrices.shape[1:]
    gram = transposed @ matrices if rows >= columns else matrices @ transposed
    size = gram.shape[1]
    damping = 1e-9 * np.trace(gram, axis1=1, axis2=2)[:, None, None] / size + 1e-30
    regularised = gram + damping * np.eye(size)
    if rows >= columns:
        return np.linalg.solve(regularised, transposed @ right_hand_sides)
    return transposed @ np.linalg.solve(regularised, right_hand_sides)


class SensorimotorMemory:
    """Every micro-action performed: joint angles and tip before it, joint step and tip step."""

    def __init__(self, num_joints: int, capacity: int, search_eps: float = 0.0):
        """Preallocates the memory.

        Args:
            num_joints: n.
            capacity: Most samples it will hold (the run's budget).
            search_eps: Approximation of the tree search (cKDTree eps): each returned neighbour from
                the tree is within (1 + eps) times the distance of the true one of the same rank; 0
                is exact.
        """
        self.search_eps = search_eps
        self.joint_angles = np.empty((capacity, num_joints))
        self.positions = np.empty((capacity, 2))
        self.joint_steps = np.empty((capacity, num_joints))
        self.displacements = np.empty((capacity, 2))
        self.size = 0
        self._tree = None
        self._tree_size = 0

    def Add(self, joint_angles, position, joint_step, displacement) -> None:
        """Stores one micro-action (theta, x) -> (dtheta, dx)."""
        index = self.size
        self.joint_angles[index] = joint_angles
        self.positions[index] = position
        self.joint_steps[index] = joint_step
        self.displacements[index] = displacement
        self.size += 1
        if self.size - self._tree_size > max(256, 3 * int(math.sqrt(self.size))):
            self._tree = cKDTree(self.joint_angles[: self.size])
            self._tree_size = self.size

    def Neighbours(self, queries: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
        """The k stored samples nearest to each query in joint space (exact when search_eps = 0).

        Args:
            queries: (m, n) joint angles.
            k: Neighbourhood size (fewer if the memory holds fewer samples).

        Returns:
            (indices, squared distances), each (m, min(k, size)), unsorted.
        """
        queries = np.atleast_2d(queries)
        k = min(k, self.size)
        tail = self.joint_angles[self._tree_size : self.size]
        tail_distances = np.einsum(
            "mkn,mkn->mk", tail[None] - queries[:, None], tail[None] - queries[:, None]
        )
        tail_indices = np.broadcast_to(np.arange(self._tree_size, self.size), tail_distances.shape)
        if self._tree_size > 0:
            k_tree = min(k, self._tree_size)
            distances, indices = self._tree.query(queries, k=k_tree, eps=self.search_eps)
            distances = np.concatenate(
                [np.reshape(distances, (-1, k_tree)) ** 2, tail_distances], axis=1
            )
            indices = np.concatenate([np.reshape(indices, (-1, k_tree)), tail_indices], axis=1)
        else:
            distances, indices = tail_distances, tail_indices
        if distances.shape[1] > k:
            keep = np.argpartition(distances, k - 1, axis=1)[:, :k]
            distances = np.take_along_axis(distances, keep, axis=1)
            indices = np.take_along_axis(indices, keep, axis=1)
        # A canonical order makes every estimate independent of how the samples are split between
        # tree and tail.
        order = np.argsort(indices, axis=1)
        return np.take_along_axis(indices, order, axis=1), np.take_along_axis(
            distances, order, axis=1
        )

    def Snapshot(self) -> "SensorimotorMemory":
        """A read-only view of the samples with one tree over all of them (for batch queries).

        Returns:
            A memory sharing this one's arrays; adding to it is not allowed.
        """
        snapshot = SensorimotorMemory.__new__(SensorimotorMemory)
        snapshot.search_eps = self.search_eps
        snapshot.joint_angles = self.joint_angles[: self.size]
        snapshot.positions = self.positions[: self.size]
        snapshot.joint_steps = self.joint_steps[: self.size]
        snapshot.displacements = self.displacements[: self.size]
        snapshot.size = self.size
        snapshot._tree = cKDTree(snapshot.joint_angles) if self.size else None
        snapshot._tree_size = self.size
        return snapshot

    def EstimateJacobians(
        self, queries: np.ndarray, k: int
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Local Jacobians J(theta) = dx / dtheta from the k nearest micro-actions (eq. 4-5).

        Solves dx_j = J dtheta_j over the neighbours j in the least-squares sense with the
        pseudo-inverse: J^T = pinv([dtheta_j]) [dx_j] (see PseudoInverseSolve).

        Args:
            queries: (m, n) joint angles (the memory must not be empty).
            k: Neighbourhood size.

        Returns:
            (jacobians (m, 2, n), neighbour indices, squared distances).
        """
        indices, distances = self.Neighbours(queries, k)
        transposed = PseudoInverseSolve(self.joint_steps[indices], self.displacements[indices])
        return np.swapaxes(transposed, 1, 2), indices, distances

    def PredictPositions(self, queries: np.ndarray, k: int) -> np.ndarray:
        """Forward model x(theta): nearest stored x plus J (theta - theta_nearest).

        Args:
            queries: (m, n) joint angles (the memory must not be empty).
            k: Neighbourhood size for J.

        Returns:
            (m, 2) predicted tip positions.
        """
        queries = np.atleast_2d(queries)
        jacobians, indices, distances = self.EstimateJacobians(queries, k)
        nearest = indices[np.arange(len(indices)), np.argmin(distances, axis=1)]
        offsets = queries - self.joint_angles[nearest]
        return self.positions[nearest] + np.einsum("mdn,mn->md", jacobians, offsets)


def DesiredDisplacements(positions: np.ndarray, goals: np.ndarray, velocity: float) -> np.ndarray:
    """dx_next = min(v, D) (x_g - x_c) / ||x_g - x_c|| (Sec. III-D-1), pointing at the goal.

    The paper prints (x_c - x_g); the step must point towards the goal, so we use (x_g - x_c). The
    last step is shortened to the remaining distance D so the tip can stop on the goal (our choice).

    Args:
        positions: (m, 2) current tips x_c.
        goals: (m, 2) goals x_g.
        velocity: v.

    Returns:
        (m, 2) desired tip steps (0 where the tip is on the goal).
    """
    offsets = goals - positions
    distances = np.linalg.norm(offsets, axis=-1, keepdims=True)
    scale = np.divide(
        np.minimum(velocity, distances),
        distances,
        out=np.zeros_like(distances),
        where=distances > 0,
    )
    return offsets * scale


def ReachingJointSteps(
    jacobians: np.ndarray, desired: np.ndarray, max_joint_step: float
) -> np.ndarray:
    """Dtheta = J^+ dx (eq. 6), scaled down so no joint moves more than max_joint_step (our choice).

    Args:
        jacobians: (m, 2, n) estimated Jacobians.
        desired: (m, 2) desired tip steps.
        max_joint_step: Largest joint change of one micro-action.

    Returns:
        (m, n) joint steps.
    """
    steps = PseudoInverseSolve(jacobians, desired[:, :, None])[:, :, 0]
    largest = np.max(np.abs(steps), axis=1, keepdims=True)
    return steps / np.maximum(1.0, largest / max_joint_step)


class BudgetExhausted(Exception):
    """Raised by Learner.Act once the run's budget of micro-actions is spent."""


class Learner(abc.ABC):
    """Owns the arm, the memory and a seeded Generator; acts, and evaluates at checkpoints.

    Subclasses implement _Loop, which acts forever; Run stops it when the budget is spent.
    """

    name = "learner"

    def __init__(self, config: GoalBabblingConfig, evaluator=None):
        """Builds a learner.

        Args:
            config: The run's configuration (its seed seeds the learner's Generator).
            evaluator: Optional callable(memory, rest_position) -> dict of measures, run at step 0
                and at config.evaluation.num_checkpoints equally spaced steps up to the budget.
        """
        CheckConfig(config)
        self.config = config
        self.rng = np.random.default_rng(config.seed)
        self.arm = PlanarArm(config.arm, self.rng)
        self.rest_position = self.arm.position.copy()
        self.memory = SensorimotorMemory(
            config.arm.num_joints, config.budget, config.low_level.neighbour_search_eps
        )
        self.time_steps = 0
        self.evaluator = evaluator
        self.checkpoints = np.unique(
            np.linspace(0, config.budget, config.evaluation.num_checkpoints + 1).round().astype(int)
        )
        self._next_checkpoint = 0
        self.curve = []
        # Diagnostics (issue 23): micro-actions spent in exploration phases, reaching attempts
        # made and those ended by the stall option.
        self.exploration_steps = 0
        self.num_attempts = 0
        self.stalled_attempts = 0

    def _Evaluate(self) -> None:
        if self.evaluator is not None:
            self.curve.append(
                {"time_step": self.time_steps, **self.evaluator(self.memory, self.rest_position)}
            )
        self._next_checkpoint += 1

    def Act(self, joint_step: np.ndarray) -> np.ndarray:
        """Performs and memorises one micro-action, evaluating at checkpoints.

        Args:
            joint_step: (n,) desired joint change.

        Returns:
            (2,) the observed tip displacement.

        Raises:
            BudgetExhausted: After the last micro-action of the budget.
        """
        if self.time_steps >= self.config.budget:
            raise BudgetExhausted
        joint_angles, position = self.arm.joint_angles, self.arm.position
        performed = self.arm.Move(joint_step)
        displacement = self.arm.position - position
        self.memory.Add(joint_angles, position, performed, displacement)
        self.time_steps += 1
        if self.time_steps == self.checkpoints[self._next_checkpoint]:
            self._Evaluate()
        if self.time_steps >= self.config.budget:
            raise BudgetExhausted
        return displacement

    def RandomJointStep(self) -> np.ndarray:
        """A small random micro-action, uniform in the exploration box."""
        step = self.config.low_level.exploration_joint_step
        return self.rng.uniform(-step, step, self.config.arm.num_joints)

    def Explore(self) -> None:
        """Exploration phase: q small random micro-actions around the current theta (Sec. III-D-2).

        Each action moves the joints to a new point drawn uniformly in the box of half-width
        exploration_joint_step around the theta where the phase began (our choice): the arm stays
            near theta
        instead of drifting as a random walk would, and the joint steps are random and small.
        """
        centre = self.arm.joint_angles.copy()
        for _ in range(self.config.low_level.exploration_actions):
            self.exploration_steps += 1
            self.Act(centre + self.RandomJointStep() - self.arm.joint_angles)

    def ReachGoal(self, goal: np.ndarray) -> float:
        """One reaching attempt with the SSA-like low level (Algorithm 1, Sec. III-D), learning.

        Reaching phase: dtheta = J^+ dx_next. An exploration phase follows a reaching micro-action
        whose error exceeds eps_max (LowLevelConfig.exploration_trigger: the task error
        ||dx_performed - dx_next||, the paper's, or the model error ||dx_performed - J
        dtheta_performed||), and runs while the memory holds fewer than k samples. Stops when C >
        eps_C (eq. 7), after the timeout (see LowLevelConfig.timeout_per_unit), or, with
        LowLevelConfig.stall_steps > 0, once that many reaching micro-actions in a row have made no
        progress.

        Args:
            goal: (2,) x_g.

        Returns:
            The competence gamma of the attempt (Sec. II-D-1 with eq. 7).
        """
        low_level, interest = self.config.low_level, self.config.interest
        model_trigger = low_level.exploration_trigger == "model"
        start = self.arm.position.copy()
        distance = float(np.linalg.norm(goal - start))
        timeout = (
            math.ceil(low_level.timeout_per_unit * distance / low_level.velocity)
            + low_level.timeout_explorations * low_level.exploration_actions
        )
        started_at = self.time_steps
        self.num_attempts += 1
        closest, idle_steps = distance, 0
        while (
            ReachingCost(goal, self.arm.position, start, interest.min_competence)
            <= interest.competence_tolerance
            and self.time_steps - started_at < timeout
        ):
            if self.memory.size < low_level.num_neighbours:
                self.Explore()
                continue
            desired = DesiredDisplacements(self.arm.position[None], goal[None], low_level.velocity)
            jacobians, _, _ = self.memory.EstimateJacobians(
                self.arm.joint_angles[None], low_level.num_neighbours
            )
            joint_step = ReachingJointSteps(jacobians, desired, low_level.max_joint_step)[0]
            performed = self.Act(joint_step)
            if model_trigger:
                # What the local model predicted for the joint change actually made.
                expected = jacobians[0] @ self.memory.joint_steps[self.memory.size - 1]
            else:
                expected = desired[0]
            if low_level.stall_steps:
                remaining = float(np.linalg.norm(goal - self.arm.position))
                if remaining < closest - low_level.stall_progress:
                    closest, idle_steps = remaining, 0
                else:
                    idle_steps += 1
                    if idle_steps >= low_level.stall_steps:
                        self.stalled_attempts += 1
                        break
            if np.linalg.norm(performed - expected) > low_level.error_threshold:
                self.Explore()
        cost = ReachingCost(goal, self.arm.position, start, interest.min_competence)
        return Competence(cost, interest.competence_tolerance, interest.min_competence)

    @abc.abstractmethod
    def _Loop(self) -> None:
        """The learner's own loop of micro-actions; it ends when the budget is spent."""

    def Run(self) -> "Learner":
        """Learns until the budget of micro-actions is spent.

        Returns:
            self, with curve filled by the evaluator.
        """
        self._Evaluate()
        try:
            self._Loop()
        except BudgetExhausted:
            pass
        return self
