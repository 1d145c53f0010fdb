"""The points of the robot's solids at which the safety barrier watches a gap besides its witness
point (a box's corners, a capsule's two end caps, a sphere's centre), and how far each solid may
move in the next period.

SceneGraph reports one witness point per pair. Where two flat faces meet (a hand resting on a
table), that point is one of many equally close ones, and a rotation about it swings the far
edge down at first order while the witness point does not move: a barrier on the witness point
alone lets such a turn close the gap by the edge's lever arm times the angle in every period.
The barrier therefore also holds the gap of each support point to the pair's separating plane
(through the other solid's witness point, normal to the pair's direction). For a convex other
solid that plane separates them, so a point's gap to the plane never exceeds its true distance:
the rows are conservative.

Every point of a solid lies within its radius of the convex hull of its support points, so no
point of it moves farther in a period than the joints' largest displacements times the solid's
lever bounds (:mod:`mobee_drake.mobee.levers`, over every configuration): the barrier watches a
pair from that far beyond its field, so that no solid crosses its field in one period unseen
(docs/mobee.md, "The safety guarantee", condition 1).
"""

import numpy as np
from pydrake.multibody.plant import MultibodyPlant

from mobee_drake.mobee.fields import FieldPairs
from mobee_drake.mobee.joint_screws import JointScrews
from mobee_drake.mobee.levers import LeverBounds
from mobee_drake.robots.overlay import Box, Capsule, Primitive

# The most support points of one solid (a box's corners); solids with fewer repeat their last.
_MOST = 8


def _PointsOf(primitive: Primitive) -> tuple[np.ndarray, float]:
    """(points (m, 3) in the geometry's own frame, radius): the solid's support points, each the
    centre of a ball of ``radius`` that bounds the solid there."""
    shape = primitive.shape
    if isinstance(shape, Box):
        half = np.asarray(shape.size, dtype=float) / 2
        signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
        return signs * half, 0.0
    if isinstance(shape, Capsule):  # its frame's z axis along the segment, centred
        length = float(np.linalg.norm(np.subtract(shape.end, shape.start)))
        return np.array([[0.0, 0.0, -length / 2], [0.0, 0.0, length / 2]]), shape.radius
    return np.zeros((1, 3)), shape.radius  # a sphere, centred on its frame


class SupportPoints:
    """The support points of a robot's solids with fields (``primitives`` in the rows of
    :class:`~mobee_drake.mobee.fields.RobotFields`, each fixed at ``X_BG`` (4 x 4) in the body
    ``bodies[g]`` of ``plant``), moved by the joints through ``screws`` along ``field_moves``
    (each row's :meth:`JointScrews.Moves`, then a row of zeros)."""

    def __init__(
        self,
        plant: MultibodyPlant,
        primitives: list[Primitive],
        bodies: list[int],
        X_BG: list[np.ndarray],
        screws: JointScrews,
        field_moves: np.ndarray,
    ):
        solids = [_PointsOf(p) for p in primitives]
        self._counts = np.array([len(points) for points, _ in solids])
        # (G, 8, 3): each solid's points, the last repeated (their rows are left out).
        self._points_G = np.array(
            [np.vstack([points, np.repeat(points[-1:], _MOST - len(points), axis=0)])
             for points, _ in solids]
        )  # fmt: skip
        self._radii = np.array([radius for _, radius in solids])
        self._screws, self._moves = screws, field_moves
        points_B = [points @ X[:3, :3].T + X[:3, 3] for (points, _), X in zip(solids, X_BG)]
        levers = LeverBounds(plant, screws.velocities, bodies, points_B, self._radii)
        # (G, n): a solid's largest displacement per unit displacement of each joint.
        self._levers = levers @ np.abs(screws.to_joints)

    def Lookahead(self, joint_reach: np.ndarray) -> np.ndarray:
        """(G,): how far (m) any point of each solid may move when each joint moves by at most
        ``joint_reach`` (n, rad or m), over every configuration."""
        return self._levers @ joint_reach

    def BarrierRows(self, screws_value, pairs: FieldPairs, lookahead: np.ndarray):
        """(normals (r, n), gaps (r,)) of the support points watched in ``pairs``: those of each
        pair's robot solids (both, for a self-collision) within the pair's margin plus their
        ``lookahead`` (per row of the solids) of the plane through the other solid's witness
        point; (None, None) if there are none."""
        robot_B = np.flatnonzero(pairs.row_B >= 0)
        relative = self._moves[pairs.row_A] - self._moves[pairs.row_B]
        # Each side: A's points against the plane through B's point, and for a self-collision
        # B's against the plane through A's.
        rows = np.concatenate([pairs.row_A, pairs.row_B[robot_B]])
        X_WG = np.concatenate([pairs.X_WA, pairs.X_WB[robot_B]])
        planes = np.concatenate([pairs.p_WCb, pairs.p_WCa[robot_B]])
        normals = np.concatenate([pairs.nhat_BA_W, -pairs.nhat_BA_W[robot_B]])
        moves = np.concatenate([relative, -relative[robot_B]])
        margins = np.concatenate([pairs.margin, pairs.margin[robot_B]])
        p_W = np.einsum("sij,spj->spi", X_WG[:, :, :3], self._points_G[rows]) + X_WG[:, None, :, 3]
        gaps = np.einsum("spi,si->sp", p_W - planes[:, None], normals) - self._radii[rows, None]
        watched = gaps < (margins + lookahead[rows])[:, None]
        watched &= np.arange(_MOST) < self._counts[rows, None]
        side, point = np.nonzero(watched)
        if not len(side):
            return None, None
        rows_n = self._screws.Project(screws_value, moves[side], p_W[side, point], normals[side])
        return rows_n, gaps[side, point]
