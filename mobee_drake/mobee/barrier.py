"""MoBeE's safety barrier: the least change of the total force that keeps every pair of solids
inside its field from closing more than a fraction of its gap in the next period.

Our addition to eq. 5.7 (docs/mobee.md, "The safety guarantee"). The forces of eq. 5.7 are each
bounded, so the client's (the spring, f_config, f_work: up to 60 per joint together) can beat the
collision force (40) whatever the maxima are, as soon as several of them push together. The
barrier does not weigh forces against each other: it looks at what the next period will do.

For a pair k of solids inside its field, with signed distance d_k and generalized normal n_k (the
gradient of d_k with respect to the controlled joints: ``d_k' = n_k . v``), the next period
(length h) moves the measured joints by ``dq = offset + G total``, affine in the total with a
diagonal G given by how the period integrates MoBeE's total and how the robot follows it
(:class:`StepModel`). The barrier asks, with ``g_k = d_k - clearance``,

    n_k . dq >= -rate g_k      (for every pair k in a field)

a discrete-time barrier: to first order the next gap is ``g_k+ >= (1 - rate) g_k``. Above the
clearance the gap shrinks at most geometrically towards it; below it (g_k < 0) the row asks the
pair to *open* by the fraction ``rate`` of its deficit. That makes the clearance attracting:
if the first-order prediction errs by at most ``e`` per period (the solids' curvature, a robot
sliding or turning on a surface, another witness point taking over), the gap obeys
``g+ >= (1 - rate) g - e`` and never falls below ``clearance - e / rate``; the solids do not
touch while ``e < rate * clearance`` (1 mm per period with the defaults).
Among the totals that satisfy the rows, the barrier takes the one closest to MoBeE's, in the
metric of the virtual mass (Gauss's least constraint: ``min (dT)^T M^-1 dT``); that is a
least-distance program, solved by non-negative least squares (Lawson and Hanson, ch. 23).
The barrier force ``f_barrier = dT`` is zero whenever MoBeE's own forces keep every gap from
closing that fast, which is every period of ordinary operation.

The rows are first order, so the barrier keeps its change where first order holds: it moves no
joint by more than ``max_step`` in a period, nor beyond the joint's limits, unless MoBeE's other
forces already take it there (the *room* of each joint: the change is free to cancel any motion,
never to add one that leaves the room). A turn of one joint by ``dq`` moves a point at lever L
off its predicted straight path by about ``L dq^2 / 2``: 0.6 mm for half a metre at the default
0.05 rad, within condition 2's ``rate * clearance``; joints turning together add their errors.
Where no change within the room meets every row, the rows of pairs at or beyond the clearance
still hold (standing still meets them), and each row of a pair below it gets as much of what a
least-squares fit of those rows reaches as the others allow.
Before the room, a target appearing deep inside the Katana's forearm led to changes of radians a
period and a joint 100 rad beyond its limits (docs/mobee.md, "The safety guarantee",
condition 4).
"""

import dataclasses as dc

import numpy as np
from scipy.linalg import expm
from scipy.optimize import linprog, lsq_linear, nnls

# A pair whose gap the controlled joints move by less than this (m per rad, the normal's norm)
# cannot be helped by them: its barrier would ask for forces without bound, and is left out.
MIN_LEVER = 1e-3


@dc.dataclass
class BarrierParams:
    """The safety barrier's settings."""

    enabled: bool = True
    # The largest fraction of a pair's gap beyond the clearance the next period may close (and
    # the fraction of its deficit it must open, below the clearance).
    rate: float = 0.2
    # The gap (m) the barrier keeps between solids (less than every field's margin).
    clearance: float = 0.005
    # The most the barrier's change may move a joint in one period (rad), beyond what MoBeE's
    # other forces move it (the rows are first order: see the module).
    max_step: float = 0.05

    def Errors(self) -> list[str]:
        errors = []
        if not (0.0 < self.rate < 1.0):
            errors.append(f"barrier rate must be in (0, 1), got {self.rate}")
        if not (0.0 < self.clearance < 1.0):
            errors.append(f"barrier clearance must be in (0, 1) m, got {self.clearance}")
        if not (0.0 < self.max_step <= 1.0):
            errors.append(f"barrier max_step must be in (0, 1] rad, got {self.max_step}")
        return errors


@dc.dataclass(frozen=True)
class JointTracking:
    """The dynamic robot's joint controller in the position and velocity modes: inertia and
    gravity compensated, the joints accelerate as ``q'' = kp (q_r - q) + kd (v_r - v)`` towards
    the reference (q_r, v_r), MoBeE's virtual trajectory, held over each period."""

    position_gain: float  # kp (1/s^2; 0 in the velocity mode)
    velocity_gain: float  # kd (1/s)

    def Response(self, period: float) -> tuple[float, float, float]:
        """(a, b, c) with the period's displacement ``dq = a (q_r - q) + b v + c v_r`` of a
        joint starting at (q, v) and tracking a held reference (q_r, v_r): the exact solution
        of the linear closed loop (a matrix exponential, with the inputs' integral by Van
        Loan's block)."""
        kp, kd = self.position_gain, self.velocity_gain
        block = np.zeros((4, 4))
        block[:2, :2] = [[0.0, 1.0], [-kp, -kd]]
        block[1, 2:] = [kp, kd]  # how q_r and v_r drive the acceleration
        flow = expm(block * period)
        # dq = (Phi_qq - 1) q + Phi_qv v + Gamma_r q_r + Gamma_v v_r, and Phi_qq - 1 = -Gamma_r.
        return flow[0, 2], flow[0, 1], flow[0, 3]


@dc.dataclass(frozen=True)
class Displacement:
    """The next period's displacement of the measured joints, affine in MoBeE's total T:
    ``dq = gain T + velocity v + reference_velocity v_r + lag (q_r - q)`` (each an n-vector or
    a scalar), where (q, v) is the measured state and (q_r, v_r) the reference the robot follows
    (its own state where it is its own reference)."""

    gain: np.ndarray
    velocity: np.ndarray | float
    reference_velocity: np.ndarray | float = 0.0
    lag: float = 0.0

    def Offset(self, q, v, q_r, v_r) -> np.ndarray:
        """The part of dq that does not depend on T."""
        return self.velocity * v + self.reference_velocity * v_r + self.lag * (q_r - q)


@dc.dataclass(frozen=True)
class StepModel:
    """How the next period (``period`` s) moves the measured joints under MoBeE's total T.

    - The kinematic robot (``implicit_damping``, no ``tracking``): the virtual dynamics integrate
      ``v+ = (v + h (T + C v) / M) / (1 + h C / M)`` and move by ``dq = h v+``.
    - The force-controlled plant (explicit): it accelerates by T / M for the period. The rows
      hold the period's end velocity, ``dq = h (v + h T / M)``, which bounds the period's mean
      velocity too, since the velocity it starts with was held by the period before.
    - The position and velocity modes (``tracking``): the virtual dynamics move the reference as
      they move the kinematic robot (with the damping of the measured velocity v), and the plant
      follows it through the joint controller's lag (:class:`JointTracking`).

    Each is affine in T with a diagonal gain, because T contains the damping term ``-C v``.
    """

    period: float
    implicit_damping: bool = True
    tracking: JointTracking | None = None

    def Displacement(self, mass: np.ndarray, damping: np.ndarray) -> Displacement:
        h = self.period
        if not self.implicit_damping:
            return Displacement(gain=h * h / mass, velocity=h)
        keep = 1.0 / (1.0 + h * damping / mass)
        velocity_gain = h * keep / mass  # S of v+ = keep v + S (T + C v)
        if self.tracking is None:  # keep v + S C v = v
            return Displacement(gain=h * velocity_gain, velocity=h)
        a, b, c = self.tracking.Response(h)
        # dq = a (q_r+ - q) + b v + c v_r+ with q_r+ = q_r + h v_r+, v_r+ = keep v_r + S (T + C v).
        reference_gain = a * h + c
        return Displacement(
            gain=reference_gain * velocity_gain,
            velocity=b + reference_gain * velocity_gain * damping,
            reference_velocity=reference_gain * keep,
            lag=a,
        )


def Room(
    q: np.ndarray, lower: np.ndarray, upper: np.ndarray, max_step: float
) -> tuple[np.ndarray, np.ndarray]:
    """The room of joints at ``q`` with limits (``lower``, ``upper``) in the next period: the
    displacement (lower and upper, rad) a step of ``max_step`` allows within the limits, and
    never less than standing still (a joint beyond a limit may stay where it is)."""
    return (
        np.minimum(0.0, np.maximum(-max_step, lower - q)),
        np.maximum(0.0, np.minimum(max_step, upper - q)),
    )


def BarrierForce(
    normals: np.ndarray,
    distances: np.ndarray,
    offset: np.ndarray,
    total: np.ndarray,
    mass: np.ndarray,
    gain: np.ndarray,
    params: BarrierParams,
    room: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    """The barrier force dT (n) for the pairs' ``normals`` (k, n) and ``distances`` (k), given
    MoBeE's ``total`` (n) without it and the next period's displacement ``offset + gain T``
    (:class:`Displacement`, ``gain`` > 0), in the metric of the virtual ``mass`` (n), with the
    barrier's ``params`` (see the module), keeping the period's displacement within ``room``
    (:func:`Room`: lower and upper, n each, containing 0) or within what the other forces make
    it already.

    Pairs whose normal nearly vanishes (shorter than :data:`MIN_LEVER`: the controlled joints
    hardly move them, e.g. a base link resting in a table) cannot be helped and are left out. If
    no change within the room meets every barrier (solids pinched from two sides, or a pair too
    deep to open within a step), the pairs at or beyond the clearance are still held and those
    below it open by as much of their least-squares fit as the others allow
    (:func:`_Compromise`).
    """
    # Row k: n_k . (offset + gain (T + dT)) >= -rate g_k; with u = dT / sqrt(M): G u >= r.
    root_mass = np.sqrt(mass)
    G = normals * (gain * root_mass)
    # (A penetrating pair is asked to open by at most rate * clearance a period.)
    gaps = np.maximum(distances - params.clearance, -params.clearance)
    moved = offset + gain * total  # the period's displacement without the barrier
    r = -params.rate * gaps - normals @ moved
    if not np.any(r > 0):  # MoBeE's total already keeps every barrier.
        return np.zeros_like(total)
    # Every barrier takes part (one that holds now may not once another is met), but for those
    # whose pair the joints cannot move.
    movable = np.linalg.norm(normals, axis=1) > MIN_LEVER
    G, r, gaps = G[movable], r[movable], gaps[movable]
    if not np.any(r > 0):
        return np.zeros_like(total)
    # The room, as bounds on u (each contains the full stop, and 0: the other forces' motion is
    # never cut).
    step = gain * root_mass  # a joint's displacement per unit of u
    bounds = (np.full_like(total, -np.inf), np.full_like(total, np.inf))
    if room is not None:
        if np.any(room[0] > 0.0) or np.any(room[1] < 0.0):
            raise ValueError(f"the barrier's room must contain standing still (0), got {room}")
        bounds = (np.minimum(room[0] - moved, 0.0) / step, np.maximum(room[1] - moved, 0.0) / step)
    u = _LeastDistance(G, r, bounds)
    if u is None:
        u = _Compromise(G, r, gaps < 0.0, bounds, stop=-moved / step)
    return u * root_mass


# A row counts as met within this (m): the least-distance solution is exact up to rounding.
ROW_TOLERANCE = 1e-10


def _LeastDistance(G: np.ndarray, r: np.ndarray, bounds) -> np.ndarray | None:
    """The least |u| with G u >= r and u within ``bounds``, or None if no u meets them: NNLS
    on E = [A^T; b^T], f = e_last (Lawson and Hanson, ch. 23), the bounds as rows of A u >= b,
    with u in units of the largest change one row alone asks (the answer's precision falls with
    the square of its size), and checked against the rows."""
    asking = r > 0
    unit = np.max(r[asking] / np.linalg.norm(G[asking], axis=1)) if asking.any() else 1.0
    eye = np.eye(G.shape[1])
    finite = [np.isfinite(bounds[0]), np.isfinite(bounds[1])]
    A = np.vstack([G * unit, eye[finite[0]], -eye[finite[1]]])
    b = np.concatenate([r, bounds[0][finite[0]] / unit, -bounds[1][finite[1]] / unit])
    E = np.vstack([A.T, b])
    f = np.zeros(E.shape[0])
    f[-1] = 1.0
    # (scipy's nnls can fail unannounced on nearly degenerate programs: BVLS is asked again.)
    for Solve in (
        lambda: nnls(E, f)[0],
        lambda: lsq_linear(E, f, bounds=(0.0, np.inf), method="bvls").x,
    ):
        residual = E @ Solve() - f
        if residual[-1] < 0.0:
            u = np.clip(-unit * residual[:-1] / residual[-1], *bounds)
            if np.all(G @ u >= r - ROW_TOLERANCE):
                return u
    return None


def _Compromise(G: np.ndarray, r: np.ndarray, opening: np.ndarray, bounds, stop) -> np.ndarray:
    """The change when no u within ``bounds`` meets every row: the rows of pairs at or beyond
    the clearance hold (the full stop ``stop``, within the bounds, meets them all), and each of
    the ``opening`` rows (pairs below the clearance) is asked a fraction of the way from the
    lesser of what the full stop and their bounded least-squares fit give it to what the fit
    gives it (:func:`_Fractions`). A row that the fit closes (one of two nearly opposite rows
    of a pair deep inside) may close by that much."""
    if not opening.any():  # (the full stop meets every row: only rounding gets here)
        return stop
    reached = np.minimum(G[opening] @ _LeastShortfall(G[opening], r[opening], bounds), r[opening])
    held = np.minimum(G[opening] @ stop, reached)
    fractions = _Fractions(G, r, opening, held, reached - held, bounds)
    asked = r.copy()
    for shrink in (1.0, 1.0 - 1e-6, 0.0):  # (the linear programs' tolerance, then the least)
        asked[opening] = held + shrink * fractions * (reached - held)
        u = _LeastDistance(G, asked, bounds)
        if u is not None:
            return u
    return stop


def _Fractions(G, r, opening, held, span, bounds) -> np.ndarray:
    """The fraction t_i of each opening row's ``span`` beyond ``held`` that the change can give
    it with the other rows held, within ``bounds``: the largest common fraction first, then
    each row as far beyond it as the others allow (the largest sum). Two linear programs in
    (u, t)."""
    n, k = G.shape[1], int(opening.sum())
    hard = ~opening
    # -G_o u + span_i t_i <= -held_i, and -G_h u <= -r_h.
    A = np.block([[-G[opening], np.diag(span)], [-G[hard], np.zeros((hard.sum(), k))]])
    b = np.concatenate([-held, -r[hard]])
    box = [(None if np.isinf(lo) else lo, None if np.isinf(hi) else hi) for lo, hi in zip(*bounds)]
    common = linprog(
        np.r_[np.zeros(n), -1.0],
        A_ub=np.hstack([A[:, :n], A[:, n:].sum(axis=1, keepdims=True)]),
        b_ub=b,
        bounds=[*box, (0.0, 1.0)],
        method="highs",
    )
    least = common.x[-1] if common.status == 0 else 0.0
    each = linprog(
        np.r_[np.zeros(n), -np.ones(k)],
        A_ub=A,
        b_ub=b,
        bounds=[*box, *[(least, 1.0)] * k],
        method="highs",
    )
    return each.x[n:] if each.status == 0 else np.full(k, least)


def _LeastShortfall(G: np.ndarray, r: np.ndarray, bounds) -> np.ndarray:
    """The u within ``bounds`` that leaves the least squared shortfall ``max(0, r - G u)``:
    the bounded least squares of ``G u - s = r`` with a surplus ``s >= 0`` (a joint without
    room stays put)."""
    free = bounds[1] > bounds[0]
    u = np.zeros(G.shape[1])
    if free.any():
        k = len(r)
        fit = lsq_linear(
            np.hstack([G[:, free], -np.eye(k)]),
            r,
            bounds=(
                np.concatenate([bounds[0][free], np.zeros(k)]),
                np.concatenate([bounds[1][free], np.full(k, np.inf)]),
            ),
            method="bvls",
        )
        u[free] = fit.x[: free.sum()]
    return u
