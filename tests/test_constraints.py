"""Joint-space constraints in conjunctive normal form: the three examples of eq. 5.16."""

import unittest

import numpy as np

from mobee_drake.mobee.constraints import ClauseSet
from mobee_drake.robots.couplings import JointCoupling
from mobee_drake.robots.overlay import Clause, Literal

JOINTS = ["a", "b", "c"]
DELTA, F_MAX = np.radians(10.0), 2.0


def _Literal(joint: str, bound_deg: float) -> Literal:
    """The literal joint >= bound (degrees), clearance in radians = q - bound."""
    return Literal(coefficients={joint: 1.0}, offset=-bound_deg)


# Five literals, each "q_j >= 0" on one joint (c carries three).
L1, L2, L3, L4, L5 = (
    _Literal("a", 0),
    _Literal("b", 0),
    _Literal("c", 0),
    _Literal("c", 0),
    _Literal("c", 0),
)


def _Force(clauses, q_deg):
    return ClauseSet(clauses, JOINTS).Force(np.radians(q_deg), DELTA, F_MAX)


def _Spring(clearance_deg):
    """The closed form of eq. 5.15 for a unit normal: f_max (delta - g) / delta."""
    return F_MAX * (DELTA - np.radians(clearance_deg)) / DELTA


class TestClauses(unittest.TestCase):
    def test_single_literal_clause_is_a_linear_spring(self):
        clauses = [Clause("a", [L1])]
        np.testing.assert_allclose(_Force(clauses, [20, 0, 0]), 0.0)  # clear of its band
        np.testing.assert_allclose(_Force(clauses, [4, 0, 0]), [_Spring(4), 0, 0])
        np.testing.assert_allclose(_Force(clauses, [0, 0, 0]), [F_MAX, 0, 0])  # on the boundary
        np.testing.assert_allclose(_Force(clauses, [-5, 0, 0]), [_Spring(-5), 0, 0])  # violated

    def test_normal_is_unit_and_offset_in_degrees(self):
        # 2 a - 2 b + 20 >= 0  <=>  a - b >= -10 deg: clearance (a - b + 10 deg) / sqrt(2).
        literal = Literal(coefficients={"a": 2.0, "b": -2.0}, offset=20.0)
        q = np.radians([-14.0, 0.0, 0.0])
        g = np.radians(-14.0 + 10.0) / np.sqrt(2)
        f = ClauseSet([Clause("x", [literal])], JOINTS).Force(q, DELTA, F_MAX)
        normal = np.array([1, -1, 0]) / np.sqrt(2)
        np.testing.assert_allclose(f, F_MAX * (DELTA - g) / DELTA * normal)

    def test_example_1_conjunction_of_literals(self):
        # f1 <-> 0  AND  f2 <-> 0  AND  f3 <-> 0: each literal acts on its own.
        clauses = [Clause("1", [L1]), Clause("2", [L2]), Clause("3", [L3])]
        np.testing.assert_allclose(_Force(clauses, [5, 20, 3]), [_Spring(5), 0, _Spring(3)])

    def test_example_2_clause_stays_off_while_one_literal_is_clear(self):
        # f1 <-> 0  AND  (f2 <-> 0  OR  f3 <-> 0)
        clauses = [Clause("1", [L1]), Clause("23", [L2, L3])]
        # b inside its band but c clear: the disjunction holds with margin, no force on b.
        np.testing.assert_allclose(_Force(clauses, [30, 2, 30]), 0.0)
        np.testing.assert_allclose(_Force(clauses, [5, 2, 30]), [_Spring(5), 0, 0])
        # Both b and c inside their bands: the clause switches on and pushes both.
        np.testing.assert_allclose(_Force(clauses, [30, 2, 6]), [0, _Spring(2), _Spring(6)])

    def test_example_3_two_disjunctions(self):
        # (f1 <-> 0  OR  f2 <-> 0)  AND  (f3 <-> 0  OR  f4 <-> 0  OR  f5 <-> 0)
        clauses = [Clause("12", [L1, L2]), Clause("345", [L3, _Literal("c", 5), _Literal("c", -5)])]
        # c = 8: literal "c >= 0" (g = 8) and "c >= 5" (g = 3) are inside, "c >= -5" (g = 13) is
        # clear, so the second clause stays off; a and b both inside: the first is on.
        np.testing.assert_allclose(_Force(clauses, [1, 9, 8]), [_Spring(1), _Spring(9), 0])
        # c = 4: all three literals of the second clause inside (g = 4, -1, 9): on, summed.
        np.testing.assert_allclose(
            _Force(clauses, [40, 9, 4]), [0, 0, _Spring(4) + _Spring(-1) + _Spring(9)]
        )
        active = ClauseSet(clauses, JOINTS).ActiveClauses(np.radians([40, 9, 4]), DELTA)
        np.testing.assert_array_equal(active, [False, True])

    def test_a_literal_in_two_clauses_pushes_once(self):
        """Eq. 5.17 sums each constraint once: the forearm rule's shape, (a OR b) AND (a OR c),
        with every literal inside its band pushes a by one spring, not two."""
        clauses = [Clause("ab", [L1, L2]), Clause("ac", [_Literal("a", 0), L3])]
        np.testing.assert_allclose(_Force(clauses, [2, 3, 4]), [_Spring(2), _Spring(3), _Spring(4)])
        # With only the first clause on (c clear), a still pushes once.
        np.testing.assert_allclose(_Force(clauses, [2, 3, 40]), [_Spring(2), _Spring(3), 0])
        self.assertEqual(len(ClauseSet(clauses, JOINTS).Clearances(np.zeros(3))), 3)

    def test_frozen_joints_become_constants(self):
        frozen = {"z": np.radians(30.0)}
        # z >= 0 holds forever with z frozen at 30 deg: the clause can never switch on.
        clause = Clause("holds", [Literal(coefficients={"z": 1.0}, offset=0.0), L1])
        self.assertEqual(ClauseSet([clause], JOINTS, frozen).num_clauses, 0)
        # z <= 0 never holds: the clause reduces to its other literal, a >= 0.
        clause = Clause("fails", [Literal(coefficients={"z": -1.0}, offset=0.0), L1])
        clauses = ClauseSet([clause], JOINTS, frozen)
        np.testing.assert_allclose(
            clauses.Force(np.radians([4, 0, 0]), DELTA, F_MAX), [_Spring(4), 0, 0]
        )
        # a - z >= -20 deg with z = 30: the literal a >= 10 deg.
        mixed = Clause("mixed", [Literal(coefficients={"a": 1.0, "z": -1.0}, offset=20.0)])
        np.testing.assert_allclose(
            ClauseSet([mixed], JOINTS, frozen).Force(np.radians([14, 0, 0]), DELTA, F_MAX),
            [_Spring(4), 0, 0],
        )
        with self.assertRaisesRegex(ValueError, "'mixed'.*'z'"):
            ClauseSet([mixed], JOINTS)

    def test_a_follower_in_a_literal_becomes_its_leader_times_the_ratio_plus_the_offset(self):
        """With f following b as f = -0.5 b + 0.2 rad, the literal a + b + f >= 20 deg is
        a + 0.5 b + 0.2 rad - 20 deg >= 0, of normal (1, 0.5, 0) / sqrt(1.25)."""
        coupling = JointCoupling(follower="f", leader="b", ratio=-0.5, offset=0.2)
        literal = Literal(coefficients={"a": 1.0, "b": 1.0, "f": 1.0}, offset=-20.0)
        clauses = ClauseSet([Clause("x", [literal])], JOINTS, followers=[coupling])
        q = np.radians([10.0, 12.0, 0.0])
        g = (q[0] + 0.5 * q[1] + 0.2 - np.radians(20.0)) / np.sqrt(1.25)
        np.testing.assert_allclose(clauses.Clearances(q), [g])
        normal = np.array([1.0, 0.5, 0.0]) / np.sqrt(1.25)
        np.testing.assert_allclose(
            clauses.Force(q, DELTA, F_MAX), F_MAX * (DELTA - g) / DELTA * normal
        )

    def test_violation_sums_each_violated_clauses_least_violated_literal(self):
        """For a >= 0 AND (b >= 0 OR c >= 0) AND c >= 10 at (-5, -3, -8) deg the clauses miss
        by 5, min(3, 8) and 18 deg; with b at 2 deg the disjunction holds and adds nothing."""
        clauses = ClauseSet(
            [Clause("a", [L1]), Clause("bc", [L2, L3]), Clause("c", [_Literal("c", 10)])], JOINTS
        )
        self.assertAlmostEqual(clauses.Violation(np.radians([-5.0, -3.0, -8.0])), np.radians(26))
        self.assertAlmostEqual(clauses.Violation(np.radians([-5.0, 2.0, -8.0])), np.radians(23))
        self.assertEqual(clauses.Violation(np.radians([1.0, 2.0, 11.0])), 0.0)

    def test_single_literals_are_the_clauses_of_one_literal_as_unit_constraints(self):
        """Of a >= 0, (b >= 0 OR c >= 0) and 2 c >= 20 deg, the first and the last: rows
        (1, 0, 0) and (0, 0, 1), offsets 0 and -10 deg (radians, over the unit normal)."""
        double = Literal(coefficients={"c": 2.0}, offset=-20.0)
        clauses = ClauseSet(
            [Clause("a", [L1]), Clause("bc", [L2, L3]), Clause("c", [double])], JOINTS
        )
        normals, offsets = clauses.SingleLiterals()
        np.testing.assert_allclose(normals, [[1, 0, 0], [0, 0, 1]])
        np.testing.assert_allclose(offsets, [0.0, -np.radians(10.0)])


if __name__ == "__main__":
    unittest.main()
