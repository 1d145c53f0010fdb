"""Adaptive roadmap planning: the graph, the exploration against a fake robot, the iCub demos."""

import unittest

import numpy as np

from mobee_drake.experiments.ch4_roadmaps import A, AdaptiveReplanning, B, D, E, RoadmapFromScratch
from mobee_drake.roadmaps.adaptive_roadmap import (
    AdaptiveRoadmap,
    EdgeStatus,
    ExploreRoadmap,
)

# Four poses on a line and one off it: 0 - 1 - 2 - 3, and 4 near 1.
POSES = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0], [1.0, 0.5]])


class FakeRobot:
    """Arrives unless the edge is blocked; a blocked command returns it where it was."""

    def __init__(self, poses, blocked: set):
        self.poses, self.blocked, self.at = poses, blocked, 0
        self.commands = []

    def Command(self, q) -> bool:
        goal = int(np.flatnonzero(np.all(self.poses == q, axis=1))[0])
        self.commands.append((self.at, goal))
        if (self.at, goal) in self.blocked:
            return False
        self.at = goal
        return True


class AdaptiveRoadmapTest(unittest.TestCase):
    def test_k_nearest_is_symmetric(self):
        roadmap = AdaptiveRoadmap.KNearest(POSES, 1)
        pairs = {tuple(e) for e in roadmap.edges.tolist()}
        self.assertEqual(pairs, {(0, 1), (1, 0), (1, 4), (4, 1), (2, 1), (1, 2), (3, 2), (2, 3)})
        np.testing.assert_array_equal(roadmap.status, EdgeStatus.UNTRIED)

    def test_k_nearest_out_only(self):
        # The source's reading: each vertex commands its nearest; 3's nearest is 2, not back.
        roadmap = AdaptiveRoadmap.KNearest(POSES, 1, both_ways=False)
        pairs = {tuple(e) for e in roadmap.edges.tolist()}
        self.assertEqual(pairs, {(0, 1), (1, 4), (2, 1), (3, 2), (4, 1)})

    def test_plans_around_infeasible_edges(self):
        roadmap = AdaptiveRoadmap(POSES, [(0, 1), (1, 2), (0, 4), (4, 2), (2, 3)])
        self.assertEqual(roadmap.Plan(0, 3), [0, 1, 2, 3])
        roadmap.Record(1, 2, arrived=False)
        self.assertEqual(roadmap.Plan(0, 3), [0, 4, 2, 3])
        roadmap.Record(4, 2, arrived=False)
        self.assertEqual(roadmap.Plan(0, 3), [])
        np.testing.assert_array_equal(roadmap.Reachable(0), [True, True, False, False, True])
        # Directed: the way back is not known to fail.
        self.assertEqual(roadmap.Plan(3, 3), [3])
        with self.assertRaisesRegex(ValueError, "no edge 3 -> 0"):
            roadmap.Record(3, 0, arrived=True)

    def test_exploration_learns_the_feasible_subgraph(self):
        roadmap = AdaptiveRoadmap.KNearest(POSES, 2)
        blocked = {(1, 2), (2, 1), (4, 2), (0, 4)}
        robot = FakeRobot(POSES, blocked)
        record = ExploreRoadmap(roadmap, robot, 0, np.random.default_rng(0))
        # Every edge out of a reachable vertex is known, and known rightly.
        reachable = roadmap.Reachable(0)
        for (a, b), status in zip(roadmap.edges.tolist(), roadmap.status):
            if reachable[a]:
                self.assertEqual(
                    status, EdgeStatus.INFEASIBLE if (a, b) in blocked else EdgeStatus.FEASIBLE
                )
            else:
                self.assertEqual(status, EdgeStatus.UNTRIED)
        self.assertEqual(record.reflexes, sum(c in blocked for c in robot.commands))
        self.assertEqual(record.commands, len(robot.commands))
        # Each edge was tried once, and travel used known feasible edges only.
        tried_blocked = [c for c in robot.commands if c in blocked]
        self.assertEqual(len(tried_blocked), len(set(tried_blocked)))


class IcubDemosTest(unittest.TestCase):
    def test_adaptive_replanning_goes_around_the_ball_once_it_is_solid(self):
        result = AdaptiveReplanning(0)
        self.assertEqual(result.ghost_path, [A, B])
        self.assertTrue(result.ghost_arrived)  # the hand went through the ghost
        self.assertEqual(result.first_solid_path, [B, A])
        self.assertFalse(result.direct_arrived)  # the reflex brought it back to B
        self.assertEqual(result.replanned_path, [B, E, D, A])
        self.assertTrue(result.arrived_home)
        self.assertEqual(result.reflexes, 1)

    def test_a_small_roadmap_from_scratch_is_explored_completely(self):
        result, roadmap = RoadmapFromScratch(0, samples=6, k=3)
        self.assertEqual(result.vertices, 7)
        self.assertEqual(result.feasible + result.infeasible + result.untried, result.edges)
        reachable = roadmap.Reachable(0)
        self.assertFalse(
            np.any((roadmap.status == EdgeStatus.UNTRIED) & reachable[roadmap.edges[:, 0]])
        )
        self.assertEqual(result.reflexes, result.infeasible)
        self.assertGreater(result.feasible, 0)
        self.assertEqual(result.forbidden_vertices, 0)  # (drawn free of MoBeE's fields)
        # A dead end is a reachable vertex with no feasible edge out.
        feasible_out = set(roadmap.edges[roadmap.status == EdgeStatus.FEASIBLE][:, 0].tolist())
        self.assertEqual(
            result.dead_ends, sum(1 for v in np.flatnonzero(reachable) if v not in feasible_out)
        )

    def test_the_sources_readings_leave_vertices_out_of_reach(self):
        # Unchecked samples and one-way edges: some samples are forbidden poses, which no
        # command reaches, and the explored graph is no larger than with checked samples.
        result, roadmap = RoadmapFromScratch(
            0, samples=6, k=3, vertex_sampling="uniform", edges="out"
        )
        self.assertEqual(result.edges, 7 * 3)
        self.assertGreater(result.forbidden_vertices, 0)
        self.assertGreaterEqual(result.unreachable_vertices, 1)
        reachable = roadmap.Reachable(0)
        self.assertFalse(
            np.any((roadmap.status == EdgeStatus.UNTRIED) & reachable[roadmap.edges[:, 0]])
        )
        with self.assertRaisesRegex(ValueError, "unknown reading"):
            RoadmapFromScratch(0, vertex_sampling="gaussian")


if __name__ == "__main__":
    unittest.main()
