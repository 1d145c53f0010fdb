"""Natural Gradient Inverse Kinematics (dissertation ch. 3.2): NES on a sum of cost terms.

An :class:`IkProblem` searches some of the model's joints (the others stay at a base pose) for a
pose minimising ``h = sum_i h_i(q, B)`` (eq. 3.1). NES samples are unbounded, so the problem makes
every sample valid before it is evaluated, and charges for what it changed:

- a sample outside the joint limits is evaluated at its projection into them, plus the distance
  (rad) it was outside: the search is pulled back inside, and the pose it reports is valid;
- a pose that violates constraint clauses (the iCub's shoulder cables, eq. 5.14-5.17) costs one
  per violated clause plus the violation (rad), like a collision pair of ``h_collision``.

A pose *solves* the problem when it is valid, and every term is met (at most its tolerance).
"""

import dataclasses as dc
import time

import numpy as np

from mobee_drake.ngik.costs import CostTerm
from mobee_drake.ngik.kinematic_model import KinematicModel, PoseEvaluation
from mobee_drake.ngik.nes import Minimize, NesConfig


class IkProblem:
    """Minimise the sum of ``terms`` over ``joints`` of ``model``, the others at ``base``."""

    def __init__(
        self,
        model: KinematicModel,
        terms: list[CostTerm],
        *,
        joints: list[str] | None = None,
        base: np.ndarray | None = None,
    ):
        self.model = model
        self.terms = list(terms)
        self.joints = list(joints) if joints is not None else list(model.joints)
        self.columns = np.array([model.JointIndex(name) for name in self.joints])
        self.base = model.home.copy() if base is None else np.asarray(base, dtype=float).copy()
        self.lower = model.lower[self.columns]
        self.upper = model.upper[self.columns]

    def Pose(self, x: np.ndarray) -> np.ndarray:
        """The model's full pose for search vector ``x``, projected into the joint limits."""
        q = self.base.copy()
        q[self.columns] = np.clip(x, self.lower, self.upper)
        return q

    def SearchVector(self, q: np.ndarray) -> np.ndarray:
        return np.asarray(q, dtype=float)[self.columns].copy()

    def Evaluate(self, x: np.ndarray) -> tuple[PoseEvaluation, float]:
        """The evaluation of ``x``'s (valid) pose and its cost: eq. 3.1 plus the validity terms."""
        q = self.Pose(x)
        evaluation = self.model.Evaluate(q)
        cost = float(np.sum(np.abs(x - q[self.columns])))
        cost += self._ClauseViolation(q)
        cost += sum(term(evaluation) for term in self.terms)
        return evaluation, cost

    def Cost(self, x: np.ndarray) -> float:
        return self.Evaluate(x)[1]

    def _ClauseViolation(self, q: np.ndarray) -> float:
        clauses = self.model.clauses
        violated = clauses.ActiveClauses(q, 0.0)
        if not violated.any():
            return 0.0
        return float(violated.sum()) + clauses.Violation(q)

    def IsSolved(self, evaluation: PoseEvaluation) -> bool:
        """Valid and every term met."""
        return self.model.IsValid(evaluation.q) and all(
            term(evaluation) <= term.tolerance for term in self.terms
        )


@dc.dataclass(frozen=True)
class IkSolution:
    q: np.ndarray  # the full pose found
    cost: float
    solved: bool
    evaluations: int
    seconds: float


def SolveNgik(
    problem: IkProblem,
    start: np.ndarray,
    sigma: float | np.ndarray,
    config: NesConfig,
    rng: np.random.Generator,
) -> IkSolution:
    """NGIK: NES from N(start, sigma^2) over the problem's joints (``start``: a full pose)."""
    began = time.perf_counter()
    result = Minimize(problem.Cost, problem.SearchVector(start), sigma, config, rng)
    seconds = time.perf_counter() - began
    evaluation, cost = problem.Evaluate(result.x)
    return IkSolution(
        q=evaluation.q,
        cost=cost,
        solved=problem.IsSolved(evaluation),
        evaluations=result.evaluations,
        seconds=seconds,
    )
