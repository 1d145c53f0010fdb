"""Natural Evolution Strategies, the optimisers behind NGIK (dissertation ch. 3.2).

Both variants keep a Gaussian search distribution and follow the natural gradient of the expected
fitness, with rank-based fitness shaping (Glasmachers et al. 2010; Schaul et al. 2011):

- **xNES** (exponential NES): a full covariance ``A A^T`` with ``A = sigma B``, ``det B = 1``;
  the update of ``B`` is a matrix exponential, so the covariance stays positive definite.
- **SNES** (separable NES): one standard deviation per coordinate; cheap in many dimensions.

Learning rates and population sizes are the published defaults. NES minimises here: rank 1 is
the lowest cost. The best sample seen (not the final mean) is the result.
"""

from collections.abc import Callable
import dataclasses as dc
import math

import numpy as np

NES_VARIANTS = ("xnes", "snes")


@dc.dataclass
class NesConfig:
    """How NES searches and when it stops."""

    variant: str = "xnes"
    # Samples per generation; 0: the default 4 + floor(3 ln d).
    population: int = 0
    # Stop after this many cost evaluations,
    max_evaluations: int = 4000
    # or as soon as a sample costs at most this,
    target_cost: float = 0.0
    # or when the search distribution's largest standard deviation falls below this.
    tolerance: float = 1e-4

    def __post_init__(self):
        if self.variant not in NES_VARIANTS:
            raise ValueError(f"NES variant must be one of {NES_VARIANTS}, got '{self.variant}'")
        if self.population < 0 or self.population == 1:
            raise ValueError(
                f"NES population must be 0 (default) or at least 2, got {self.population}"
            )
        if self.max_evaluations < 1:
            raise ValueError(f"NES max_evaluations must be positive, got {self.max_evaluations}")


@dc.dataclass(frozen=True)
class NesResult:
    x: np.ndarray  # the best sample
    cost: float  # its cost
    evaluations: int
    generations: int
    # Why the search stopped: "target", "converged" or "budget".
    reason: str


def Utilities(population: int) -> np.ndarray:
    """Rank-based fitness shaping: the utility of ranks 1..population (best first), summing to 0."""
    ranks = np.arange(1, population + 1)
    raw = np.maximum(0.0, math.log(population / 2 + 1) - np.log(ranks))
    return raw / raw.sum() - 1.0 / population


def DefaultPopulation(dimension: int) -> int:
    return 4 + int(math.floor(3 * math.log(dimension)))


def _SymmetricExp(S: np.ndarray) -> np.ndarray:
    """The matrix exponential of a symmetric matrix, by its eigendecomposition."""
    values, vectors = np.linalg.eigh(S)
    return (vectors * np.exp(values)) @ vectors.T


def Minimize(
    cost: Callable[[np.ndarray], float],
    mean: np.ndarray,
    sigma: float | np.ndarray,
    config: NesConfig,
    rng: np.random.Generator,
) -> NesResult:
    """Minimises ``cost`` from the distribution N(mean, sigma^2 I) (``sigma`` scalar or per
    coordinate)."""
    mu = np.array(mean, dtype=float)
    d = len(mu)
    sigmas = np.broadcast_to(np.asarray(sigma, dtype=float), (d,)).copy()
    if not np.all(sigmas > 0):
        raise ValueError(f"NES initial standard deviations must be positive, got {sigmas}")
    lam = config.population or DefaultPopulation(d)
    utilities = Utilities(lam)
    xnes = config.variant == "xnes"
    if xnes:
        # A = scale * B with det(B) = 1; a per-coordinate start goes into B.
        scale = float(np.exp(np.mean(np.log(sigmas))))
        B = np.diag(sigmas / scale)
        eta_sigma = eta_B = 3 * (3 + math.log(d)) / (5 * d * math.sqrt(d))
    else:
        eta_sigma = (3 + math.log(d)) / (5 * math.sqrt(d))
    best_x, best_cost = mu.copy(), math.inf
    evaluations = generations = 0
    while True:
        z = rng.standard_normal((lam, d))
        x = mu + (scale * z @ B.T if xnes else z * sigmas)
        costs = np.empty(lam)
        for k in range(lam):
            costs[k] = cost(x[k])
            evaluations += 1
            if costs[k] < best_cost:
                best_x, best_cost = x[k].copy(), float(costs[k])
            if best_cost <= config.target_cost:
                return NesResult(best_x, best_cost, evaluations, generations, "target")
            if evaluations >= config.max_evaluations:
                return NesResult(best_x, best_cost, evaluations, generations, "budget")
        generations += 1
        order = np.argsort(costs, kind="stable")
        u, z = utilities, z[order]
        grad_delta = u @ z
        if xnes:
            grad_M = (z.T * u) @ z  # sum_k u_k (z_k z_k^T - I); the utilities sum to 0
            grad_sigma = np.trace(grad_M) / d
            grad_B = grad_M - grad_sigma * np.eye(d)
            mu = mu + scale * B @ grad_delta  # eta_mu = 1
            scale *= math.exp(eta_sigma / 2 * grad_sigma)
            B = B @ _SymmetricExp(eta_B / 2 * grad_B)
            spread = scale * np.sqrt(np.max(np.sum(B * B, axis=1)))
        else:
            mu = mu + sigmas * grad_delta
            sigmas = sigmas * np.exp(eta_sigma / 2 * (u @ (z * z - 1.0)))
            spread = float(np.max(sigmas))
        if spread < config.tolerance:
            return NesResult(best_x, best_cost, evaluations, generations, "converged")
