"""Joint-space constraints in conjunctive normal form: the three examples of eq. 5.16."""

import unittest

import numpy as np

from mobee_drake.mobee.constraints import ClauseSet
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


if __name__ == "__main__":
    unittest.main()
