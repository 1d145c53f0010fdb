"""NGIK: NES against closed forms, Table 3.1's costs, the kinematic model and IK on the iCub."""

import math
import unittest

import numpy as np

from mobee_drake.mobee.constraints import ClauseSet
from mobee_drake.ngik.costs import (
    CollisionCost,
    HomeCost,
    MarkerInBox,
    MarkerOrientationCost,
    MarkerPositionCost,
    TwoHandHoldCost,
)
from mobee_drake.ngik.kinematic_model import KinematicModel, PoseEvaluation
from mobee_drake.ngik.nes import DefaultPopulation, Minimize, NesConfig, Utilities
from mobee_drake.ngik.solver import IkProblem, SolveNgik
from mobee_drake.robots.icub import RIGHT_ARM_JOINTS, TORSO_JOINTS, IcubConfig
from mobee_drake.robots.overlay import Clause, Literal
from mobee_drake.world.objects import Box, SceneObject, Sphere


class NesTest(unittest.TestCase):
    def test_utilities(self):
        for n in (4, 10, 17):
            u = Utilities(n)
            self.assertAlmostEqual(u.sum(), 0.0)
            self.assertTrue(np.all(np.diff(u) <= 0))  # best rank first
            # Only the ranks k < n/2 + 1 get more than the baseline -1/n.
            self.assertEqual(
                int(np.sum(u > -1.0 / n + 1e-12)), int(np.sum(np.arange(1, n + 1) < n / 2 + 1))
            )
        self.assertEqual(DefaultPopulation(10), 4 + int(3 * math.log(10)))

    def test_symmetric_exponential(self):
        from scipy.linalg import expm

        from mobee_drake.ngik.nes import _SymmetricExp

        A = np.random.default_rng(0).standard_normal((5, 5))
        S = (A + A.T) / 4
        np.testing.assert_allclose(_SymmetricExp(S), expm(S), atol=1e-12)

    def test_minimises_a_shifted_quadratic(self):
        center = np.array([3.0, -1.0, 0.5, 2.0])
        for variant in ("xnes", "snes"):
            result = Minimize(
                lambda x: float(np.sum((x - center) ** 2)),
                np.zeros(4),
                1.0,
                NesConfig(
                    variant=variant, max_evaluations=20000, target_cost=1e-10, tolerance=1e-12
                ),
                np.random.default_rng(0),
            )
            self.assertEqual(result.reason, "target")
            np.testing.assert_allclose(result.x, center, atol=1e-4)

    def test_full_covariance_solves_rosenbrock(self):
        def rosenbrock(x):
            return float(np.sum(100 * (x[1:] - x[:-1] ** 2) ** 2 + (1 - x[:-1]) ** 2))

        result = Minimize(
            rosenbrock,
            np.zeros(5),
            1.0,
            NesConfig(variant="xnes", max_evaluations=20000, target_cost=1e-8, tolerance=1e-12),
            np.random.default_rng(1),
        )
        self.assertEqual(result.reason, "target")
        np.testing.assert_allclose(result.x, np.ones(5), atol=1e-3)

    def test_stops_at_the_budget_and_on_convergence(self):
        config = NesConfig(max_evaluations=30, target_cost=-1.0)
        result = Minimize(lambda x: float(x @ x), np.ones(3), 1.0, config, np.random.default_rng(0))
        self.assertEqual((result.reason, result.evaluations), ("budget", 30))
        result = Minimize(
            lambda x: float(x @ x),
            np.ones(3),
            1.0,
            NesConfig(max_evaluations=100000, target_cost=-1.0, tolerance=1e-3),
            np.random.default_rng(0),
        )
        self.assertEqual(result.reason, "converged")
        self.assertLess(np.linalg.norm(result.x), 1e-2)

    def test_bad_configuration(self):
        with self.assertRaisesRegex(ValueError, "variant"):
            NesConfig(variant="cma")
        with self.assertRaisesRegex(ValueError, "population"):
            NesConfig(population=1)
        with self.assertRaisesRegex(ValueError, "standard deviations"):
            Minimize(lambda x: 0.0, np.zeros(2), 0.0, NesConfig(), np.random.default_rng(0))


def _Evaluation(
    q=(0.0, 0.0), positions=((0, 0, 0), (0, 0, 0)), directions=((1, 0, 0), (1, 0, 0)), pairs=()
):
    return PoseEvaluation(
        q=np.array(q, dtype=float),
        marker_positions=np.array(positions, dtype=float),
        marker_directions=np.array(directions, dtype=float),
        collision_pairs=tuple(pairs),
    )


class CostTest(unittest.TestCase):
    def test_table_3_1(self):
        e = _Evaluation(
            q=(0.3, -0.4),
            positions=((1, 2, 2), (1, 2, 5)),
            directions=((0, 1, 0), (1, 0, 0)),
            pairs=(("a", "b"), ("a", "c")),
        )
        self.assertAlmostEqual(HomeCost(np.zeros(2))(e), 0.5)
        self.assertAlmostEqual(HomeCost(np.zeros(2), joints=np.array([1]), weight=2)(e), 0.8)
        self.assertEqual(CollisionCost()(e), 2)
        self.assertAlmostEqual(MarkerPositionCost(0, np.zeros(3))(e), 3.0)
        self.assertAlmostEqual(MarkerOrientationCost(0, np.array([0, 1, 0]))(e), 0.0)
        self.assertAlmostEqual(MarkerOrientationCost(0, np.array([0, -1, 0]))(e), 2.0)
        self.assertAlmostEqual(MarkerOrientationCost(1, np.array([0, 1, 0]))(e), 1.0)
        self.assertAlmostEqual(TwoHandHoldCost(0, 1, 2.5)(e), 0.5)
        box = MarkerInBox(0, np.array([0, 0, 0]), np.array([2, 2, 1]))
        self.assertAlmostEqual(box(e), 1.0)  # 1 m above the box
        self.assertAlmostEqual(MarkerInBox(0, np.zeros(3), np.full(3, 3))(e), 0.0)

    def test_clause_violation(self):
        # q0 >= 10 deg, and (q0 <= 20 deg or q1 <= 0 deg).
        clauses = [
            Clause(name="floor", literals=[Literal(coefficients={"a": 1.0}, offset=-10.0)]),
            Clause(
                name="either",
                literals=[
                    Literal(coefficients={"a": -1.0}, offset=20.0),
                    Literal(coefficients={"b": -1.0}, offset=0.0),
                ],
            ),
        ]
        s = ClauseSet(clauses, ["a", "b"])
        self.assertEqual(s.Violation(np.radians([15.0, 5.0])), 0.0)
        self.assertAlmostEqual(s.Violation(np.radians([5.0, 5.0])), math.radians(5.0))
        # Both of "either"'s literals fail; its least violated one counts: q1 by 3 deg.
        self.assertAlmostEqual(s.Violation(np.radians([30.0, 3.0])), math.radians(3.0))


class IcubIkTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.ball = SceneObject(name="ball", shape=Sphere(radius=0.05), position=[-0.3, 0.25, 0.0])
        cls.model = KinematicModel(IcubConfig(), [cls.ball])
        cls.palm = cls.model.MarkerIndex("r_palm")
        cls.joints = list(TORSO_JOINTS + RIGHT_ARM_JOINTS)

    def test_markers_follow_the_plant(self):
        model, q = self.model, self.model.home.copy()
        q[model.JointIndex("r_elbow")] = 1.2
        e = model.Evaluate(q)
        plant = model.plant
        hand = plant.GetBodyByName("r_hand")
        context = plant.GetMyContextFromRoot(model.context)
        X_WH = plant.EvalBodyPoseInWorld(context, hand)
        marker = model.markers[self.palm]
        np.testing.assert_allclose(e.marker_positions[self.palm], X_WH @ marker.p_BM, atol=1e-12)
        self.assertAlmostEqual(np.linalg.norm(e.marker_directions[self.palm]), 1.0)

    def test_collision_pairs_name_the_obstacle(self):
        model = self.model
        self.assertEqual(model.Evaluate(model.home).collision_pairs, ())
        # Put the palm into the ball: its pose from a known configuration, the ball moved there.
        moved = KinematicModel(
            IcubConfig(),
            [
                SceneObject(
                    name="ball",
                    shape=Sphere(radius=0.05),
                    position=list(model.Evaluate(model.home).marker_positions[self.palm]),
                )
            ],
        )
        pairs = moved.Evaluate(moved.home).collision_pairs
        self.assertTrue(any("ball" in pair for pair in pairs), pairs)

    def test_validity(self):
        model = self.model
        self.assertTrue(model.IsValid(model.home))
        q = model.home.copy()
        q[model.JointIndex("r_elbow")] = model.upper[model.JointIndex("r_elbow")] + 0.01
        self.assertFalse(model.IsValid(q))
        # Elbow at 100 deg and the forearm pronated by 55 deg: the forearm clause is violated.
        q = model.home.copy()
        q[model.JointIndex("r_elbow")] = math.radians(100)
        q[model.JointIndex("r_wrist_prosup")] = math.radians(55)
        self.assertFalse(model.IsValid(q))

    def test_ngik_puts_the_palm_on_reachable_points(self):
        model, rng = self.model, np.random.default_rng(3)
        columns = [model.JointIndex(j) for j in self.joints]
        solved = 0
        for _ in range(4):
            while True:  # a point the palm reaches in a valid pose free of collisions
                q = model.home.copy()
                q[columns] = rng.uniform(model.lower[columns], model.upper[columns])
                e = model.Evaluate(q)
                if model.IsValid(q) and not e.collision_pairs:
                    break
            target = e.marker_positions[self.palm]
            problem = IkProblem(
                model, [MarkerPositionCost(self.palm, target), CollisionCost()], joints=self.joints
            )
            solution = SolveNgik(
                problem, model.home, 0.3, NesConfig(max_evaluations=4000, target_cost=0.005), rng
            )
            found = model.Evaluate(solution.q)
            if solution.solved:
                solved += 1
                self.assertLess(np.linalg.norm(found.marker_positions[self.palm] - target), 0.01)
                self.assertEqual(found.collision_pairs, ())
                self.assertTrue(model.IsValid(solution.q))
            # Only the searched joints moved.
            others = np.setdiff1d(np.arange(len(model.joints)), columns)
            np.testing.assert_array_equal(solution.q[others], model.home[others])
        self.assertGreaterEqual(solved, 3)

    def test_search_outside_the_limits_is_pulled_back(self):
        model = self.model
        problem = IkProblem(model, [], joints=["r_elbow"])
        top = model.upper[model.JointIndex("r_elbow")]
        evaluation, cost = problem.Evaluate(np.array([top + 0.5]))
        self.assertAlmostEqual(evaluation.q[model.JointIndex("r_elbow")], top)
        self.assertAlmostEqual(cost, 0.5)

    def test_a_box_around_the_robot_collides(self):
        box = SceneObject(name="slab", shape=Box(size=[1.0, 1.0, 1.0]), position=[0.0, 0.0, 0.0])
        model = KinematicModel(IcubConfig(), [box])
        self.assertTrue(any("slab" in p for p in model.Evaluate(model.home).collision_pairs))


if __name__ == "__main__":
    unittest.main()


def _Rows(evaluations: dict[str, list[int]], solved: dict[str, float] | None = None) -> list:
    """Benchmark rows of one family from each solver's evaluations per problem."""
    return [
        {
            "family": "position",
            "solver": solver,
            "evaluations": float(np.mean(each)),
            "evaluations_each": each,
            "solved": (solved or {}).get(solver, 1.0),
        }
        for solver, each in evaluations.items()
    ]


class OptimiserMarkTest(unittest.TestCase):
    def test_the_claim_follows_the_evaluations_per_problem(self):
        from mobee_drake.experiments.bench_ik import OptimiserMark

        fewer = [100 + k for k in range(12)]
        more = [400 + 3 * k for k in range(12)]
        # NES needs fewer evaluations on every problem: reproduced.
        mark, evidence = OptimiserMark(
            _Rows({"ngik_xnes": fewer, "ngik_snes": more, "cma_es": more})
        )
        self.assertEqual(mark, "reproduced", evidence)
        # CMA-ES's evaluations as a ratio of each variant's means.
        ratio = np.mean(more) / np.mean(fewer)
        self.assertIn(
            f"CMA-ES's evaluations {ratio:.2f} of ngik_xnes's, 1.00 of ngik_snes's", evidence
        )
        # CMA-ES needs fewer: not reproduced.
        mark, _ = OptimiserMark(_Rows({"ngik_xnes": more, "ngik_snes": more, "cma_es": fewer}))
        self.assertEqual(mark, "not reproduced")
        # Fewer evaluations, but fewer problems solved: not reproduced.
        mark, _ = OptimiserMark(
            _Rows({"ngik_xnes": fewer, "ngik_snes": more, "cma_es": more}, {"ngik_xnes": 0.9})
        )
        self.assertEqual(mark, "not reproduced")
        # Fewer on 7 problems by 1, more on 5 by 50: a negative median, not significant.
        mixed = [m - 1 if k < 7 else m + 50 for k, m in enumerate(more)]
        mark, evidence = OptimiserMark(
            _Rows({"ngik_xnes": [m + 100 for m in more], "ngik_snes": mixed, "cma_es": more})
        )
        self.assertEqual(mark, "not reproduced", evidence)
        self.assertIn("ngik_snes minus CMA-ES per problem, median -1", evidence)
        # Two families that disagree: the mark names the one where the claim holds.
        rows = _Rows({"ngik_xnes": fewer, "ngik_snes": more, "cma_es": more})
        for row in _Rows({"ngik_xnes": more, "ngik_snes": more, "cma_es": fewer}):
            rows.append(dict(row, family="all joints"))
        self.assertEqual(OptimiserMark(rows)[0], "reproduced only on: position")
        # Equal on every problem: no difference, not reproduced.
        mark, evidence = OptimiserMark(
            _Rows({"ngik_xnes": more, "ngik_snes": more, "cma_es": more})
        )
        self.assertEqual(mark, "not reproduced", evidence)

    def test_the_benchmark_writes_its_table_and_mark_into_the_doc(self):
        import contextlib
        import io
        import pathlib
        import tempfile

        from mobee_drake.experiments import bench_ik

        with tempfile.TemporaryDirectory() as folder:
            doc = pathlib.Path(folder) / "doc.md"
            doc.write_text(
                "a\n<!-- generated: ngik-benchmark, by x -->\nOLD\n"
                "<!-- end generated: ngik-benchmark -->\nb\n"
            )
            with contextlib.redirect_stdout(io.StringIO()):
                bench_ik.main(["--problems", "1", "--doc", str(doc)])
            text = doc.read_text()
        self.assertNotIn("OLD", text)
        self.assertIn(f"by mobee-drake bench ik --problems 1 --seed 0 --doc {doc} -->", text)
        for family, _, _ in bench_ik.FAMILIES:
            for solver in bench_ik.SOLVERS:
                self.assertIn(f"| {family} | {solver} | ", text)
        self.assertRegex(text, r"NES outperforms the other samplers \(ch. 3.2\): \*\*[a-z]")
