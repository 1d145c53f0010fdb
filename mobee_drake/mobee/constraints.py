"""MoBeE's joint-space constraints in conjunctive normal form (dissertation eq. 5.14-5.17).

A *literal* is one linear constraint on joint positions, written ``a . q + b >= 0``. Its
*clearance* is the signed joint-space distance of ``q`` from the constraint's hyperplane,

    g(q) = (a . q + b) / |a|        (positive where the constraint holds),

and its repelling force (eq. 5.15) is a linear spring of length ``delta`` along the unit normal,

    f(q) = f_max (delta - g) / delta * a / |a|     if g < delta,  else 0,

so it is ``f_max`` on the boundary, zero ``delta`` inside, and grows linearly beyond the boundary.

Eq. 5.16-5.17 group literals into clauses. We read the literal ``f_cst,i <-> 0`` as "literal i is
clear of its band" (``g_i >= delta``). A *clause* is a disjunction: it is safe while any of its
literals is clear. **A clause's forces switch on exactly when none of its literals is clear, that
is when every one of its literals is inside its band (or violated); then the forces of all its
literals act together.** The constraint set is the conjunction of its clauses, and the total
constraint force (eq. 5.17) sums **each distinct literal once** over the clauses that are switched
on: a literal written in two clauses (the forearm rule writes the elbow's in both) is one
constraint, which pushes once however many of its clauses are on. A single-literal clause is an
ordinary constraint; the iCub's forearm clause "elbow below 90 deg OR pronation within 45 deg"
stays silent while either holds with margin, and pushes both joints once both are near or beyond
their bounds.

Literals are given in degrees (as IIT and the original MoBeE publish them) and evaluated in
radians: ``a . q_deg + b >= 0`` is ``a . q_rad + b pi/180 >= 0``, so clearances and ``delta`` are in
radians of joint space.
"""

from collections.abc import Mapping, Sequence

import numpy as np

from mobee_drake.robots.couplings import JointCoupling
from mobee_drake.robots.overlay import Clause


class ClauseSet:
    """The clauses of one robot, vectorised over its controlled joints.

    Args:
        clauses: the overlay's clauses.
        joints: names of the controlled joints, in the order of ``q``.
        frozen_joints: angles (rad) of joints welded in place; their terms become constants.
        source: what to name in error messages (the overlay file).
        followers: joints that follow controlled ones (robots/couplings.py); a term on one
            becomes a term on its leader (times the ratio) and a constant.

    A literal on frozen joints only is a constant: true (the clause can never switch on, so it is
    dropped) or false (it never stops the clause from switching on, so it is left out of it).
    A joint neither controlled nor frozen is an error.
    """

    def __init__(
        self,
        clauses: Sequence[Clause],
        joints: Sequence[str],
        frozen_joints: Mapping[str, float] | None = None,
        source: str = "overlay",
        followers: Sequence[JointCoupling] = (),
    ):
        column = {name: i for i, name in enumerate(joints)}
        frozen = {name: np.degrees(angle) for name, angle in (frozen_joints or {}).items()}
        following = {c.follower: c for c in followers}
        rows, offsets, membership, self.names = [], [], [], []
        index: dict[tuple, int] = {}  # (a, b) of each distinct literal -> its row
        for clause in clauses:
            literals = []  # (a over the controlled joints, b in degrees)
            for literal in clause.literals:
                a, b = np.zeros(len(joints)), literal.offset
                for name, coefficient in literal.coefficients.items():
                    if name in column:
                        a[column[name]] += coefficient
                    elif name in following:  # c q_f = c ratio q_leader + c offset (degrees)
                        coupling = following[name]
                        a[column[coupling.leader]] += coefficient * coupling.ratio
                        b += coefficient * np.degrees(coupling.offset)
                    elif name in frozen:
                        b += coefficient * frozen[name]
                    else:
                        raise ValueError(
                            f"{source}: clause '{clause.name}' names joint '{name}', "
                            "which is neither controlled nor frozen"
                        )
                literals.append((a, b))
            if any(not a.any() and b >= 0 for a, b in literals):
                continue  # A literal that always holds: the clause can never switch on.
            literals = [(a, b) for a, b in literals if a.any()]
            if not literals:
                raise ValueError(
                    f"{source}: clause '{clause.name}' is violated by the frozen "
                    "joints and no controlled joint can satisfy it"
                )
            members = []
            for a, b in literals:
                key = (tuple(a), b)  # A literal already seen in another clause is the same one.
                if key not in index:
                    index[key] = len(rows)
                    rows.append(a)
                    offsets.append(np.radians(b))
                members.append(index[key])
            membership.append(members)
            self.names.append(clause.name)
        n_literals = len(rows)
        A = np.array(rows).reshape(n_literals, len(joints))
        norms = np.linalg.norm(A, axis=1)
        self._normals = A / norms[:, None] if n_literals else A  # a / |a|
        self._offsets = np.array(offsets) / norms if n_literals else np.zeros(0)  # b / |a|
        # C[c, l] = 1 when literal l belongs to clause c.
        self._C = np.zeros((len(membership), n_literals))
        for c, members in enumerate(membership):
            self._C[c, members] = 1.0
        # The same as booleans (a boolean matmul is an OR of ANDs), and the normals' transpose.
        self._member = self._C > 0
        self._member_T = self._member.T.copy()
        self._normals_T = self._normals.T.copy()

    @property
    def num_clauses(self) -> int:
        return self._C.shape[0]

    def Clearances(self, q: np.ndarray) -> np.ndarray:
        """The clearance ``g`` of every distinct literal, in radians (in the order the clauses
        first name them)."""
        return self._normals @ q + self._offsets

    def Bands(self, delta: float) -> tuple[np.ndarray, np.ndarray]:
        """(R, c): the depth ``R q + c = delta - g`` of every literal into its band of width
        ``delta``, positive inside it: a clause can switch on only where one is."""
        return -self._normals, delta - self._offsets

    def ActiveClauses(self, q: np.ndarray, delta: float) -> np.ndarray:
        """Which clauses have their forces switched on: all of their literals within ``delta``."""
        return self._Active(self.Clearances(q) < delta)

    def SingleLiterals(self) -> tuple[np.ndarray, np.ndarray]:
        """The clauses of one literal as linear constraints ``normals @ q + offsets >= 0``."""
        single = self._C.sum(axis=1) == 1
        rows = np.flatnonzero(self._C[single].sum(axis=0))
        return self._normals[rows], self._offsets[rows]

    def Violation(self, q: np.ndarray) -> float:
        """How far (rad) ``q`` is from satisfying every clause: the sum over the violated clauses
        of their least violated literal's depth."""
        depth = np.maximum(-self.Clearances(q), 0.0)
        per_clause = np.where(self._C > 0, depth[None, :], np.inf).min(axis=1, initial=np.inf)
        return float(np.sum(per_clause[np.isfinite(per_clause)]))

    def _Active(self, inside: np.ndarray) -> np.ndarray:
        return ~(self._member @ ~inside)  # no literal of the clause is clear

    def Force(self, q: np.ndarray, delta: float, f_max: float) -> np.ndarray:
        """The total constraint force ``f_cst`` (eq. 5.15-5.17 as described in the module)."""
        return self.ForceAtDepths(delta - self.Clearances(q), delta, f_max)

    def ForceAtDepths(self, depths: np.ndarray, delta: float, f_max: float) -> np.ndarray:
        """``f_cst`` from the literals' depths ``delta - g`` into their bands (:meth:`Bands`)."""
        inside = depths > 0.0
        if not inside.any():  # The common case: every literal clear, no clause can switch on.
            return np.zeros(self._normals.shape[1])
        # Each literal of a switched-on clause, once (eq. 5.17).
        on = self._member_T @ self._Active(inside)
        return self._normals_T @ (f_max / delta * depths * on)
