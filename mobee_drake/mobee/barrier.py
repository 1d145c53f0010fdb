"""MoBeE's safety barrier: the least change of the total force that keeps every pair of solids
inside its field from closing more than a fraction of its gap in the next period.

Our addition to eq. 5.7 (docs/mobee.md, "The safety guarantee"). The forces of eq. 5.7 are each
bounded, so the client's (the spring, f_config, f_work: up to 60 per joint together) can beat the
collision force (40) whatever the maxima are, as soon as several of them push together. The
barrier does not weigh forces against each other: it looks at what the next period will do.

For a pair k of solids inside its field, with signed distance d_k and generalized normal n_k (the
gradient of d_k with respect to the controlled joints' velocities: ``d_k' = n_k . v``), the next
period (length h) moves with ``v+ = v + S total`` for a diagonal S given by how the period
integrates MoBeE's total (:class:`StepModel`). The barrier asks

    n_k . v+ >= -rate max(d_k - clearance, 0) / h      (for every pair k in a field)

so that, to first order, the period closes at most the fraction ``rate`` of what is left of each
gap beyond the ``clearance``: the gap shrinks geometrically towards the clearance and never
below it, and a pair closer than that (one that started there) may not close further; MoBeE's
field force opens it. The clearance absorbs what the first-order
prediction misses (the solids' curvature, a robot sliding along a surface): without it, gaps
shrank to micrometres and then closed by a fraction of a millimetre.
Among the totals that satisfy it, the barrier takes the one closest to MoBeE's, in the metric of
the virtual mass (Gauss's least constraint: ``min (dT)^T M^-1 dT``); that is a least-distance
program, solved exactly by non-negative least squares (Lawson and Hanson, ch. 23). The barrier
force ``f_barrier = dT`` is zero whenever MoBeE's own forces keep every gap from closing that
fast, which is every period of ordinary operation.
"""

import dataclasses as dc

import numpy as np
from scipy.optimize import nnls

# A pair whose gap the controlled joints move by less than this (m per rad, the normal's norm)
# cannot be helped by them: its barrier would ask for forces without bound, and is left out.
MIN_LEVER = 1e-3


@dc.dataclass
class BarrierParams:
    """The safety barrier's settings."""

    enabled: bool = True
    # The largest fraction of a pair's gap beyond the clearance the next period may close.
    rate: float = 0.2
    # The gap (m) the barrier keeps between solids (less than every field's margin).
    clearance: float = 0.005

    def Errors(self) -> list[str]:
        errors = []
        if not (0.0 < self.rate < 1.0):
            errors.append(f"barrier rate must be in (0, 1), got {self.rate}")
        if not (0.0 < self.clearance < 1.0):
            errors.append(f"barrier clearance must be in (0, 1) m, got {self.clearance}")
        return errors


@dc.dataclass(frozen=True)
class StepModel:
    """How the next period (``period`` s) integrates MoBeE's total T into the velocity.

    - ``implicit_damping`` (the virtual dynamics of the kinematic robot and of the dynamic
      robot's position and velocity modes): ``v+ = (v + h (T + C v) / M) / (1 + h C / M)``;
    - explicit (the force-controlled plant, which accelerates by T / M for the period):
      ``v+ = v + h T / M``.

    Both are ``v+ = v + S T`` with a diagonal S (for the implicit one because T contains the
    damping term ``-C v``).
    """

    period: float
    implicit_damping: bool = True

    def Gain(self, mass: np.ndarray, damping: np.ndarray) -> np.ndarray:
        """The diagonal of S."""
        h = self.period
        if self.implicit_damping:
            return h / mass / (1.0 + h * damping / mass)
        return h / mass


def BarrierForce(
    normals: np.ndarray,
    distances: np.ndarray,
    velocity: np.ndarray,
    total: np.ndarray,
    mass: np.ndarray,
    gain: np.ndarray,
    period: float,
    params: BarrierParams,
) -> np.ndarray:
    """The barrier force dT (n) for the pairs' ``normals`` (k, n) and ``distances`` (k) at
    ``velocity`` (n), given MoBeE's ``total`` (n) without it, the virtual ``mass`` (n) and the
    step's ``gain`` S (n), with the barrier's ``params`` (see the module).

    Pairs whose normal nearly vanishes (shorter than :data:`MIN_LEVER`: the controlled joints
    hardly move them, e.g. a base link resting in a table) cannot be helped and are left out. If
    the barriers contradict each other (solids pinched from two sides), the least-squares change
    that meets them as nearly as possible is taken instead.
    """
    # Row k: n_k . S (T + dT) >= -rate max(d_k - clearance, 0) / h - n_k . v; with
    # u = dT / sqrt(M): G u >= r.
    root_mass = np.sqrt(mass)
    G = normals * (gain * root_mass)
    closing = params.rate * np.maximum(distances - params.clearance, 0.0) / period
    r = -closing - normals @ velocity - (normals * gain) @ total
    if not np.any(r > 0):  # MoBeE's total already keeps every barrier.
        return np.zeros_like(total)
    # Every barrier takes part (one that holds now may not once another is met), but for those
    # whose pair the joints cannot move.
    movable = np.linalg.norm(normals, axis=1) > MIN_LEVER
    G, r = G[movable], r[movable]
    if not np.any(r > 0):
        return np.zeros_like(total)
    # Least distance: min |u| with G u >= r, as NNLS on E = [G^T; r^T], f = e_last.
    E = np.vstack([G.T, r])
    f = np.zeros(E.shape[0])
    f[-1] = 1.0
    weights, _ = nnls(E, f)
    residual = E @ weights - f
    if residual[-1] < -1e-12:
        u = -residual[:-1] / residual[-1]
    else:  # Infeasible: meet the barriers in the least-squares sense.
        u = np.linalg.lstsq(G, r, rcond=None)[0]
    return u * root_mass
