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

    ``row_A`` and ``row_B`` are the geometries' rows in the robot's :class:`RobotFields` (``row_B``
    is -1 for an obstacle), for looking up what each robot geometry is fixed to.
    """

    geometry_A: list[GeometryId]
    geometry_B: list[GeometryId]
    distance: np.ndarray  # (k,)
    margin: np.ndarray  # (k,)
    p_WCa: np.ndarray  # (k, 3) witness points on A, in world
    nhat_BA_W: np.ndarray  # (k, 3)
    row_A: np.ndarray  # (k,) int
    row_B: np.ndarray  # (k,) int, -1 when B is not the robot's
    # (k, 3, 4): the pose in world of A's geometry frame, and of B's where B is the robot's
    # (zeros for an obstacle).
    X_WA: np.ndarray
    X_WB: np.ndarray

    def __len__(self) -> int:
        return len(self.geometry_A)

    @property
    def b_is_robot(self) -> np.ndarray:
        """(k,) bool: whether B is a robot geometry too (a self-collision, which pushes both)."""
        return self.row_B >= 0

    @property
    def p_WCb(self) -> np.ndarray:
        """(k, 3) witness points on B, in world (SceneGraph's ``p_WCa - p_WCb = d nhat_BA_W``)."""
        return self.p_WCa - self.distance[:, None] * self.nhat_BA_W

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
    np.zeros(0, dtype=int),
    np.zeros(0, dtype=int),
    np.zeros((0, 3, 4)),
    np.zeros((0, 3, 4)),
)


_NO_POSE = np.zeros((3, 4))


class RobotFields:
    """A robot's geometries that have a field: each one's row (their order in ``geometries``)
    and margin (m)."""

    def __init__(self, margins: Mapping[GeometryId, float]):
        self.geometries = list(margins)
        self.max_margin = max(margins.values(), default=0.0)  # no pair farther can be inside
        self.min_margin = min(margins.values(), default=0.0)  # every pair's is at least this
        self._rows = {g: (row, margin) for row, (g, margin) in enumerate(margins.items())}

    def FindPairs(self, query: QueryObject) -> FieldPairs:
        """Every pair with a robot geometry inside its field, at the pose of ``query``."""
        if self.max_margin <= 0:
            return NO_FIELD_PAIRS
        return self._Pairs(query, self.max_margin, lambda d, margin, a, b: d < margin)

    def FindApproaching(self, query: QueryObject, reach: np.ndarray, gap: float) -> FieldPairs:
        """The pairs outside their fields whose distance the robot's geometries could close to
        less than ``gap`` if each moved by its ``reach`` (m, per row)."""
        if self.max_margin <= 0:
            return NO_FIELD_PAIRS

        def Approaching(d, margin, a, b) -> bool:
            return margin <= d < gap + (reach[a[0]] if a else 0.0) + (reach[b[0]] if b else 0.0)

        farthest = np.sort(reach)[-2:].sum()  # two solids close by at most this together
        return self._Pairs(query, gap + farthest, Approaching)

    def _Pairs(self, query: QueryObject, max_distance: float, keep) -> FieldPairs:
        """The pairs with a robot geometry closer than ``max_distance`` that ``keep(distance,
        margin, (row, margin) of A or None, of B or None)``."""
        rows, lookup = [], self._rows.get
        poses = {}  # X_WG of each robot geometry met (several pairs often share one)

        def Pose(row: int, geometry: GeometryId) -> np.ndarray:
            X_WG = poses.get(row)
            if X_WG is None:
                X_WG = poses[row] = query.GetPoseInWorld(geometry).GetAsMatrix34()
            return X_WG

        for pair in query.ComputeSignedDistancePairwiseClosestPoints(max_distance):
            id_A, id_B = pair.id_A, pair.id_B
            a, b = lookup(id_A), lookup(id_B)
            if a is None:
                if b is None:
                    continue  # Neither geometry is the robot's.
                margin = b[1]
            else:
                margin = a[1] if b is None or a[1] > b[1] else b[1]
            distance = pair.distance
            if not keep(distance, margin, a, b):
                continue
            if a is None:  # Make A the robot's geometry.
                id_A, id_B, a, b = id_B, id_A, b, None
                p_ACa, nhat = pair.p_BCb, -pair.nhat_BA_W
            else:
                p_ACa, nhat = pair.p_ACa, pair.nhat_BA_W
            X_WB = _NO_POSE if b is None else Pose(b[0], id_B)
            rows.append(
                (id_A, id_B, distance, margin, Pose(a[0], id_A), X_WB, p_ACa, nhat, a[0],
                 -1 if b is None else b[0])
            )  # fmt: skip
        if not rows:
            return NO_FIELD_PAIRS
        ids_A, ids_B, distance, margin, X_WA, X_WB, p_ACa, nhat, row_A, row_B = zip(*rows)
        X_WA = np.array(X_WA)
        return FieldPairs(
            list(ids_A),
            list(ids_B),
            np.array(distance),
            np.array(margin),
            np.einsum("kij,kj->ki", X_WA[:, :, :3], np.array(p_ACa)) + X_WA[:, :, 3],
            np.array(nhat),
            np.array(row_A),
            np.array(row_B),
            X_WA,
            np.array(X_WB),
        )


def ToFieldContacts(
    pairs: FieldPairs, query: QueryObject, names: Mapping[GeometryId, str]
) -> list[FieldContact]:
    """The pairs as a list of :class:`FieldContact` (``names`` first, then SceneGraph's)."""
    inspector = query.inspector()
    contacts = []
    p_WCb = pairs.p_WCb
    for i, (a, b) in enumerate(zip(pairs.geometry_A, pairs.geometry_B)):
        contacts.append(
            FieldContact(
                geometry_A=a,
                geometry_B=b,
                name_A=names.get(a) or inspector.GetName(a),
                name_B=names.get(b) or inspector.GetName(b),
                distance=float(pairs.distance[i]),
                margin=float(pairs.margin[i]),
                p_WCa=pairs.p_WCa[i].copy(),
                p_WCb=p_WCb[i],
                nhat_BA_W=pairs.nhat_BA_W[i].copy(),
            )
        )
    return contacts
