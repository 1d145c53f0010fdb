"""Geometry pairs inside their force fields (dissertation ch. 2.3.1, eq. 5.11).

Each robot geometry has a field margin around its solid. A pair is *inside its field* when the
signed distance between the two solids is below the pair's margin, the larger of the two
geometries' margins (an obstacle has none): the field of either one reaches the other's solid.
The field penetration ``margin - distance`` drives MoBeE's collision force.
"""

from collections.abc import Mapping
import dataclasses as dc

import numpy as np
from pydrake.geometry import GeometryId, QueryObject


@dc.dataclass(frozen=True)
class FieldContact:
    """A pair of geometries closer than the field margin of the pair.

    ``geometry_A`` belongs to the robot; ``geometry_B`` is an obstacle or another robot part.
    Moving A along ``nhat_BA_W`` increases the distance; the force on A acts at ``p_WCa``.
    """

    geometry_A: GeometryId
    geometry_B: GeometryId
    name_A: str
    name_B: str
    distance: float  # Signed distance between the solids (m); negative when they penetrate.
    margin: float  # The pair's field margin (m).
    p_WCa: np.ndarray  # Witness point on A, in world.
    p_WCb: np.ndarray  # Witness point on B, in world.
    nhat_BA_W: np.ndarray  # Unit direction from B to A, in world.

    @property
    def penetration(self) -> float:
        """How deep the pair is inside its field (m)."""
        return self.margin - self.distance

    def __deepcopy__(self, memo) -> "FieldContact":
        # Immutable (and GeometryId cannot be copied): Drake's Value<object> copies share it.
        return self


@dc.dataclass(frozen=True)
class FieldPairs:
    """The k pairs inside their fields as arrays; A is always a robot geometry.

    Witness points are kept in their own geometry's frame (``p_ACa`` in A's, ``p_BCb`` in B's), as
    SceneGraph reports them: the forces need them on the robot's bodies, not in world.
    """

    geometry_A: list[GeometryId]
    geometry_B: list[GeometryId]
    distance: np.ndarray  # (k,)
    margin: np.ndarray  # (k,)
    p_ACa: np.ndarray  # (k, 3)
    p_BCb: np.ndarray  # (k, 3)
    nhat_BA_W: np.ndarray  # (k, 3)
    # Whether B is a robot geometry too (a self-collision, which pushes both bodies).
    b_is_robot: np.ndarray  # (k,) bool

    def __len__(self) -> int:
        return len(self.geometry_A)

    def __deepcopy__(self, memo) -> "FieldPairs":
        # Never modified after construction (and GeometryId cannot be copied): copies share it.
        return self


# No pair inside any field (shared: FieldPairs are never modified).
NO_FIELD_PAIRS = FieldPairs(
    [],
    [],
    np.zeros(0),
    np.zeros(0),
    np.zeros((0, 3)),
    np.zeros((0, 3)),
    np.zeros((0, 3)),
    np.zeros(0, dtype=bool),
)


def FindFieldPairs(
    query: QueryObject, margins: Mapping[GeometryId, float], max_margin: float
) -> FieldPairs:
    """Finds every pair with a robot geometry (a key of ``margins``) inside its field.

    ``max_margin`` is the largest of ``margins``: no pair farther apart can be inside its field.
    """
    if max_margin <= 0:
        return NO_FIELD_PAIRS
    rows = []
    for pair in query.ComputeSignedDistancePairwiseClosestPoints(max_margin):
        id_A, id_B = pair.id_A, pair.id_B
        margin_A, margin_B = margins.get(id_A), margins.get(id_B)
        if margin_A is None:
            if margin_B is None:
                continue  # Neither geometry is the robot's.
            margin = margin_B
        else:
            margin = margin_A if margin_B is None or margin_A > margin_B else margin_B
        distance = pair.distance
        if distance >= margin:
            continue
        if margin_A is None:  # Make A the robot's geometry.
            rows.append(
                (id_B, id_A, distance, margin, pair.p_BCb, pair.p_ACa, -pair.nhat_BA_W, False)
            )
        else:
            rows.append(
                (
                    id_A,
                    id_B,
                    distance,
                    margin,
                    pair.p_ACa,
                    pair.p_BCb,
                    pair.nhat_BA_W,
                    margin_B is not None,
                )
            )
    if not rows:
        return NO_FIELD_PAIRS
    ids_A, ids_B, distance, margin, p_ACa, p_BCb, nhat, both = zip(*rows)
    return FieldPairs(
        list(ids_A),
        list(ids_B),
        np.array(distance),
        np.array(margin),
        np.array(p_ACa),
        np.array(p_BCb),
        np.array(nhat),
        np.array(both),
    )


def ToFieldContacts(
    pairs: FieldPairs, query: QueryObject, names: Mapping[GeometryId, str]
) -> list[FieldContact]:
    """The pairs as a list of :class:`FieldContact`, witness points in world."""
    inspector = query.inspector()
    contacts = []
    for i, (a, b) in enumerate(zip(pairs.geometry_A, pairs.geometry_B)):
        contacts.append(
            FieldContact(
                geometry_A=a,
                geometry_B=b,
                name_A=names.get(a) or inspector.GetName(a),
                name_B=names.get(b) or inspector.GetName(b),
                distance=float(pairs.distance[i]),
                margin=float(pairs.margin[i]),
                p_WCa=query.GetPoseInWorld(a).multiply(pairs.p_ACa[i]),
                p_WCb=query.GetPoseInWorld(b).multiply(pairs.p_BCb[i]),
                nhat_BA_W=pairs.nhat_BA_W[i].copy(),
            )
        )
    return contacts
