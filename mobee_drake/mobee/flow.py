"""Obstacle-aware flow: the goal-directed forces bent around the fields they push into.

Our addition to eq. 5.7, after the dissertation's own future work (ch. 9.4.3: dynamical systems
richer than point attractors). MoBeE mixes an attractor's pull with the fields' push; where the
pull points straight into an obstacle the two cancel and the robot stalls on a field (a local
minimum of the mixed forces), or crawls around it as slowly as the pull's small tangential part
allows. The remedy is the *modulation* of a dynamical system around obstacles (Khansari-Zadeh and
Billard, "A dynamical system approach to realtime obstacle avoidance", Autonomous Robots 32, 2012):
near an obstacle, the flow's component towards it is damped and its component along the
obstacle's surface amplified, so the flow slides around the obstacle instead of pushing into it.

In MoBeE's joint space, a pair k inside its field has the generalized normal ``n_k`` (the gradient
of its signed distance over the joints, :meth:`Mobee._FieldNormals`) and a *proximity*

    w_k = clip((margin_k - d_k) / (margin_k - clearance), 0, 1),

0 at the field's edge and 1 at the barrier's clearance (mobee/barrier.py) or closer. The goal-
directed force ``f`` (the attractor spring and the client's forces, eq. 5.7, 5.9, 5.10) is
modulated pair by pair, nearest last, only where it points into the pair (``f . n_k < 0``):

    f <- (1 - w_k) f_n + (1 + w_k) f_t,     f_n = (f . n^_k) n^_k,   f_t = f - f_n,

the eigenvalues ``1 -+ 1/Gamma`` of the paper's modulation with ``1/Gamma = w_k``; the result is
then scaled back to the length of ``f``: the modulation turns the flow, it does not strengthen
it, so the goal-directed forces stay within their squashed maxima (eq. 5.8) and below the
fields' (docs/mobee.md, "Presets"). Properties (tested): far from every obstacle (no pair in a
field) the flow is MoBeE's own, so the attractor stays its only equilibrium in free space; at
the clearance the flow is tangent to the obstacle (``f . n_k = 0``); for one pair the modulation
never lengthens the component towards it nor shortens the one along it. With several pairs the
nearest one's surface is followed exactly and the others' only as nearly as the order allows
(turning the flow along the nearest surface may lengthen its part towards a farther pair); the
safety barrier, which comes after, keeps every gap whatever the flow. A pull exactly opposite a
normal has no tangential part to turn to (the paper's saddle on the obstacle's far side, a set
of measure zero); the fields' own push still keeps it clear. The force term ``f_flow`` is the
modulated force less the original, so each term keeps its meaning.
"""

import dataclasses as dc

import numpy as np


@dc.dataclass
class FlowParams:
    """The obstacle-aware flow's settings."""

    enabled: bool = True


def ModulatedFlow(
    force: np.ndarray,
    normals: np.ndarray,
    distances: np.ndarray,
    margins: np.ndarray,
    clearance: float,
) -> np.ndarray:
    """The goal-directed ``force`` (n) modulated around the k pairs inside their fields (their
    generalized ``normals`` (k, n), signed ``distances`` and field ``margins``) and scaled back
    to its length, as the module says; ``clearance`` (m) is where a pair's proximity reaches 1."""
    proximity = np.clip((margins - distances) / (margins - clearance), 0.0, 1.0)
    lengths = np.linalg.norm(normals, axis=1)
    acting = np.flatnonzero((proximity > 0.0) & (lengths > 0.0))
    if not acting.size:
        return force
    # The nearest pair last: its surface is the one to follow.
    acting = acting[np.argsort(-distances[acting], kind="stable")]
    units = normals[acting] / lengths[acting, None]
    flow = force
    for unit, w in zip(units, proximity[acting].tolist()):
        into = float(flow @ unit)
        if into >= 0.0:
            continue  # The flow already points away from the pair (or along it).
        # (1 - w) f_n + (1 + w) f_t = (1 + w) f - 2 w f_n
        flow = (1.0 + w) * flow - (2.0 * w * into) * unit
    length = np.linalg.norm(flow)
    if flow is force or length == 0.0:  # (zero: a pull straight into a pair at its clearance)
        return flow
    return flow * (np.linalg.norm(force) / length)
