"""Task-relevant roadmaps: task spaces, the covered region, Alg. 4's invariants on the iCub."""

import tempfile
import unittest

import numpy as np

from mobee_drake.ngik.costs import CollisionCost, HomeCost, MarkerInBox
from mobee_drake.ngik.kinematic_model import KinematicModel, PoseEvaluation
from mobee_drake.ngik.nes import NesConfig
from mobee_drake.ngik.solver import IkProblem
from mobee_drake.planning.supervisor import ExploreAttractor, ExploringAgent
from mobee_drake.robots.icub import IcubConfig
from mobee_drake.scenario import BuildScenario, Scenario
from mobee_drake.station.world_events import MakeSimulator
from mobee_drake.trm.display import PathMotion
from mobee_drake.trm.examples import JOINTS, ReachInto
from mobee_drake.trm.roadmap import BuildTrm, CoveredRegion, TaskRelevantRoadmap, TrmConfig
from mobee_drake.trm.task_space import (
    JointCoordinates,
    MarkerAlong,
    MarkerAngle,
    MarkerCoordinates,
    MarkerHeading,
    TaskSpace,
)

FAST_NES = NesConfig(variant="snes", max_evaluations=300, target_cost=-1.0, tolerance=2e-3)


class TaskSpaceTest(unittest.TestCase):
    def test_table_3_2(self):
        e = PoseEvaluation(
            q=np.array([0.1, 0.2, 0.3]),
            marker_positions=np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]),
            marker_directions=np.zeros((2, 3)),
            collision_pairs=(),
        )
        space = TaskSpace(
            (
                MarkerCoordinates(1),
                MarkerAlong(0, (1.0, 1.0, 1.0)),
                JointCoordinates((2, 0)),
                MarkerCoordinates(0, (2,)),
            )
        )
        self.assertEqual(space.dimension, 7)
        np.testing.assert_allclose(space(e), [4, 5, 6, 6, 0.3, 0.1, 3])

    def test_angles_of_a_marker_direction(self):
        # Marker 0 points along (cos 30, sin 30, 0) in the table plane, marker 1 straight up.
        c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
        e = PoseEvaluation(
            q=np.zeros(1),
            marker_positions=np.zeros((2, 3)),
            marker_directions=np.array([[c, s, 0.0], [0.0, 0.0, 1.0]]),
            collision_pairs=(),
        )
        np.testing.assert_allclose(MarkerAngle(0, (1.0, 0.0, 0.0))(e), [np.radians(30)])
        np.testing.assert_allclose(MarkerAngle(1, (0.0, 0.0, -1.0))(e), [np.pi])
        # Heading about +z from +x: +30 degrees; about -z: -30; from +y: -60.
        np.testing.assert_allclose(MarkerHeading(0, (0, 0, 1.0), (1.0, 0, 0))(e), [np.pi / 6])
        np.testing.assert_allclose(MarkerHeading(0, (0, 0, -1.0), (1.0, 0, 0))(e), [-np.pi / 6])
        np.testing.assert_allclose(MarkerHeading(0, (0, 0, 1.0), (0, 1.0, 0))(e), [-np.pi / 3])
        # A component along the plane's normal does not change the heading.
        e.marker_directions[0] = [c, s, 5.0]
        np.testing.assert_allclose(MarkerHeading(0, (0, 0, 1.0), (1.0, 0, 0))(e), [np.pi / 6])

    def test_opposed_directions(self):
        from mobee_drake.ngik.costs import OpposedDirections

        u = np.array([[0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]])
        e = PoseEvaluation(np.zeros(1), np.zeros((3, 3)), u, ())
        self.assertAlmostEqual(OpposedDirections(0, 1)(e), 0.0)  # facing each other
        self.assertAlmostEqual(OpposedDirections(0, 2, weight=2.0)(e), 2.0)  # at right angles
        self.assertAlmostEqual(OpposedDirections(0, 0)(e), 2.0)  # the same direction


class CatalogueTest(unittest.TestCase):
    def test_every_example_starts_from_a_pose_meeting_its_terms(self):
        from mobee_drake.trm.catalogue import EXAMPLES

        for name, Make in EXAMPLES.items():
            with self.subTest(name):
                example = Make()
                problem = example.problem
                evaluation, _ = problem.Evaluate(problem.SearchVector(example.q_init))
                if name in ("reach_into", "raise_a_glass"):
                    continue  # (these start at home, as Alg. 4 does, and search from there)
                self.assertTrue(problem.IsSolved(evaluation))
                self.assertFalse(evaluation.collision_pairs)

    def test_a_two_hand_roadmap_holds_its_object(self):
        from mobee_drake.trm.bimanual import HOLD, BimanualTwist

        example = BimanualTwist()
        config = TrmConfig(
            max_vertices=4, spacing=example.spacing, sigma=example.sigma, nes=FAST_NES
        )
        roadmap = BuildTrm(
            example.problem, example.task_space, example.q_init, config, np.random.default_rng(0)
        )
        model = example.model
        right, left = model.MarkerIndex("r_palm"), model.MarkerIndex("l_palm")
        headings = []
        for q in roadmap.q:
            e = model.Evaluate(q)
            apart = np.linalg.norm(e.marker_positions[right] - e.marker_positions[left])
            self.assertAlmostEqual(apart, HOLD, delta=0.01)
            self.assertLess(1.0 + e.marker_directions[right] @ e.marker_directions[left], 0.016)
            headings.append(example.task_space(e)[0])
        # The vertices are spread over the palms' heading, at least d apart.
        gaps = np.diff(np.sort(headings))
        self.assertEqual(roadmap.num_vertices, 4)
        self.assertTrue(np.all(gaps >= example.spacing / 2), headings)


class GraphStateSpaceTest(unittest.TestCase):
    def test_edges_become_actions_both_ways(self):
        from mobee_drake.planning.state_space import FromGraph

        space = FromGraph(np.array([[0.1], [0.5], [0.9]]), np.array([[0, 1], [2, 1]]))
        np.testing.assert_array_equal(space.action_state, [0, 1, 1, 2])
        np.testing.assert_array_equal(space.action_goal, [1, 0, 2, 1])
        self.assertEqual(space.StateOf(np.array([0.8])), 2)
        with self.assertRaisesRegex(ValueError, "join states 0..2"):
            FromGraph(np.zeros((3, 1)), np.array([[0, 3]]))


class CoveredRegionTest(unittest.TestCase):
    def test_simplex_membership(self):
        region = CoveredRegion(2)
        self.assertFalse(region.Contains(np.zeros(2)))
        self.assertTrue(region.Add((0, 1, 2), np.array([[0, 0], [1, 0], [0, 1]], dtype=float)))
        self.assertTrue(region.Contains(np.array([0.2, 0.2])))
        self.assertTrue(region.Contains(np.array([0.5, 0.5])))  # on the boundary
        self.assertFalse(region.Contains(np.array([0.6, 0.6])))
        self.assertFalse(region.Contains(np.array([-0.1, 0.5])))
        # Collinear points span no area; too few points make no hull.
        self.assertFalse(region.Add((3, 4, 5), np.array([[0, 0], [1, 1], [2, 2]], dtype=float)))
        self.assertFalse(region.Add((3, 4), np.array([[0, 0], [1, 1]], dtype=float)))
        self.assertTrue(region.Add((1, 2, 3), np.array([[1, 0], [0, 1], [1, 1]], dtype=float)))
        self.assertTrue(region.Contains(np.array([0.9, 0.9])))
        self.assertEqual(region.simplices, [(0, 1, 2), (1, 2, 3)])


class IcubTrmTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.model = KinematicModel(IcubConfig())
        cls.palm = cls.model.MarkerIndex("r_palm")
        palm = cls.model.Evaluate(cls.model.home).marker_positions[cls.palm]
        # A 6 cm cube around the resting palm, vertices 3 cm apart: a small map that ends.
        cls.box = (palm - 0.03, palm + 0.03)
        cls.terms = [
            HomeCost(cls.model.home, weight=0.1),
            CollisionCost(),
            MarkerInBox(cls.palm, *cls.box, weight=10.0),
        ]
        cls.config = TrmConfig(spacing=0.03, delta=0.5, nes=FAST_NES)
        cls.problem = IkProblem(cls.model, cls.terms, joints=JOINTS)
        cls.space = TaskSpace((MarkerCoordinates(cls.palm),))
        cls.roadmap = BuildTrm(
            cls.problem, cls.space, cls.model.home, cls.config, np.random.default_rng(0)
        )

    def test_vertices_are_valid_solutions_spread_in_task_space(self):
        r = self.roadmap
        self.assertGreaterEqual(r.num_vertices, 4)
        for q, y in zip(r.q, r.y):
            e = self.model.Evaluate(q)
            self.assertTrue(self.problem.IsSolved(e))
            self.assertEqual(e.collision_pairs, ())
            np.testing.assert_allclose(self.space(e), y)
            self.assertTrue(np.all(y >= self.box[0] - 1e-9) and np.all(y <= self.box[1] + 1e-9))
        distances = np.linalg.norm(r.y[:, None] - r.y[None], axis=2)
        np.fill_diagonal(distances, np.inf)
        self.assertGreaterEqual(distances.min(), self.config.spacing / 2)

    def test_alg4_bookkeeping(self):
        r = self.roadmap
        # Every weight spent, each by 1/delta failed searches; every other search made a vertex.
        np.testing.assert_array_equal(r.weights, 0.0)
        self.assertEqual(r.searches, r.num_vertices * (1 + round(1 / self.config.delta)))
        # Vertex k joins its min(k, n) nearest earlier vertices.
        n = self.space.dimension
        for k in range(r.num_vertices):
            earlier = r.edges[r.edges[:, 1] == k, 0]
            self.assertEqual(len(earlier), min(k, n))
            self.assertTrue(np.all(earlier < k))
        for simplex in r.simplices:
            self.assertEqual(len(simplex), n + 1)

    def test_paths_and_motion(self):
        r = self.roadmap
        path = r.Path(0, r.num_vertices - 1)
        self.assertEqual((path[0], path[-1]), (0, r.num_vertices - 1))
        edges = {tuple(sorted(e)) for e in r.edges.tolist()}
        for a, b in zip(path[:-1], path[1:]):
            self.assertIn(tuple(sorted((a, b))), edges)
        motion = PathMotion(r, path, steps_per_edge=4)
        self.assertEqual(len(motion), 1 + 4 * (len(path) - 1))
        np.testing.assert_allclose(motion[[0, -1]], r.q[[path[0], path[-1]]])

    def test_save_and_load(self):
        with tempfile.TemporaryDirectory() as folder:
            self.roadmap.Save(folder)
            loaded = TaskRelevantRoadmap.Load(folder)
        np.testing.assert_array_equal(loaded.q, self.roadmap.q)
        np.testing.assert_array_equal(loaded.edges, self.roadmap.edges)
        self.assertEqual(loaded.simplices, self.roadmap.simplices)
        with (
            tempfile.TemporaryDirectory() as folder,
            self.assertRaisesRegex(FileNotFoundError, "roadmap.npz"),
        ):
            TaskRelevantRoadmap.Load(folder)

    def test_a_roadmap_as_the_mdp_state_space(self):
        r = self.roadmap
        with tempfile.TemporaryDirectory() as folder:
            r.Save(folder)
            scenario = Scenario(
                attractor=ExploreAttractor(agents=[ExploringAgent(joints=JOINTS, roadmap=folder)]),
                time_step=0.02,
            )
            simulation = BuildScenario(scenario)
        space = simulation.client.agents[0].space
        self.assertEqual(space.num_states, r.num_vertices)
        self.assertEqual(space.num_state_actions, 2 * len(r.edges))
        simulator = MakeSimulator(simulation)
        simulator.AdvanceTo(2.0)
        # The agent's first action sets the attractor to one of the roadmap's poses.
        q_star = simulation.attractor.Eval(simulator.get_context())
        self.assertLess(np.min(np.abs(r.q - q_star).max(axis=1)), 1e-9)

    def test_unreachable_task_fails_clearly(self):
        far = MarkerInBox(self.palm, np.array([2.0, 2.0, 2.0]), np.array([2.1, 2.1, 2.1]))
        problem = IkProblem(self.model, [far], joints=JOINTS)
        with self.assertRaisesRegex(RuntimeError, "no valid first pose"):
            BuildTrm(problem, self.space, self.model.home, self.config, np.random.default_rng(0))


class ReachIntoTest(unittest.TestCase):
    def test_the_hand_goes_into_the_box_without_touching_it(self):
        example = ReachInto()
        config = TrmConfig(max_vertices=6, nes=FAST_NES)
        roadmap = BuildTrm(
            example.problem, example.task_space, example.q_init, config, np.random.default_rng(1)
        )
        self.assertEqual(roadmap.num_vertices, 6)
        box = example.problem.terms[-1]
        for q in roadmap.q:
            e = example.model.Evaluate(q)
            self.assertEqual(e.collision_pairs, ())
            self.assertEqual(box(e), 0.0)  # the palm inside the box


if __name__ == "__main__":
    unittest.main()
