"""Adaptive roadmap planning (dissertation ch. 4.2-4.3) on MoBeE 1.0's reflex.

A roadmap's vertices are poses and its edges *commands*: a position move from one vertex to
another, never checked before it is tried. Under MoBeE 1.0 a command either arrives or, when the
reflex fires, returns the robot to where it started, so the graph is an MDP whose edge ``a -> b``
leads to ``b`` or back to ``a`` with probability one each once known. An edge found infeasible is
removed and paths are re-planned on what is left; untried edges are planned through
optimistically. Edges are directed: a move may fail one way and not the other.

:class:`ReflexRobot` runs commands on a simulated iCub under the reflex controller and reports
each one's outcome; :func:`ExploreRoadmap` is the exploration of "roadmap from scratch" (biased to
vertices with untried edges, until the feasible subgraph reachable from the start is known).
"""

import dataclasses as dc

import numpy as np
from pydrake.systems.analysis import Simulator

from mobee_drake.planning.graph_paths import (
    JointSpaceDistances,
    PathFromPredecessors,
    ShortestPath,
)
from mobee_drake.reflex.controller import COMPLETED, MODE, MOVING, REFLEXES, REWINDING, STUCK
from mobee_drake.simulation.builder import BuildSimulation
from mobee_drake.simulation.scenario import FixedAttractor, Scenario

UNTRIED, FEASIBLE, INFEASIBLE = 0, 1, 2


@dc.dataclass
class AdaptiveRoadmap:
    """Vertices (poses) and directed edges (commands) with what is known of each edge."""

    poses: np.ndarray  # (V, n) the controlled joints' positions (rad)
    edges: np.ndarray  # (E, 2) directed (from, to)
    status: np.ndarray = None  # (E,) UNTRIED, FEASIBLE or INFEASIBLE

    def __post_init__(self):
        self.edges = np.asarray(self.edges, dtype=int).reshape(-1, 2)
        if self.status is None:
            self.status = np.full(len(self.edges), UNTRIED)

    @staticmethod
    def KNearest(poses: np.ndarray, k: int) -> "AdaptiveRoadmap":
        """Each pose joined both ways to its ``k`` nearest in joint space (ch. 4.3.1)."""
        poses = np.asarray(poses, dtype=float)
        distances = np.linalg.norm(poses[:, None] - poses[None], axis=2)
        np.fill_diagonal(distances, np.inf)
        pairs = set()
        for a, row in enumerate(distances):
            for b in np.argsort(row, kind="stable")[:k]:
                pairs |= {(a, int(b)), (int(b), a)}
        return AdaptiveRoadmap(poses, np.array(sorted(pairs)))

    def Edge(self, a: int, b: int) -> int:
        found = np.flatnonzero((self.edges[:, 0] == a) & (self.edges[:, 1] == b))
        if not len(found):
            raise ValueError(f"the roadmap has no edge {a} -> {b}")
        return int(found[0])

    def Record(self, a: int, b: int, arrived: bool) -> None:
        self.status[self.Edge(a, b)] = FEASIBLE if arrived else INFEASIBLE

    def Distances(self, start: int) -> tuple[np.ndarray, np.ndarray]:
        """Shortest joint-space distances from ``start`` over the edges not known infeasible, and
        the predecessors on those paths."""
        return JointSpaceDistances(self.poses, self.edges[self.status != INFEASIBLE], start)

    def Plan(self, start: int, goal: int) -> list[int]:
        """The shortest path in joint space over the edges not known infeasible ([] if none)."""
        return ShortestPath(self.poses, self.edges[self.status != INFEASIBLE], start, goal)

    def Reachable(self, start: int) -> np.ndarray:
        """Which vertices a path of edges not known infeasible reaches from ``start``."""
        distances, _ = self.Distances(start)
        return np.isfinite(distances)


class ReflexRobot:
    """A simulated robot under MoBeE 1.0 that executes position move commands one at a time."""

    def __init__(self, scenario: Scenario, *, meshcat=None, timeout: float = 60.0):
        if scenario.controller != "reflex" or not isinstance(scenario.attractor, FixedAttractor):
            raise ValueError(
                "ReflexRobot needs a scenario with controller: reflex and a "
                "FixedAttractor (its value becomes the commands)"
            )
        self.simulation = BuildSimulation(scenario, meshcat)
        self.simulator = Simulator(self.simulation.diagram)
        self.context = self.simulator.get_mutable_context()
        self.simulator.Initialize()
        diagram = self.simulation.diagram
        self._source = diagram.GetSubsystemByName("attractor")
        self._reflex = diagram.GetSubsystemByName("reflex")
        self._period, self._timeout = scenario.time_step, timeout

    def Status(self) -> np.ndarray:
        return (
            self._reflex.GetOutputPort("status")
            .Eval(self._reflex.GetMyContextFromRoot(self.context))
            .copy()
        )

    def Positions(self) -> np.ndarray:
        n = len(self.simulation.mobee.joints)
        return self.simulation.robot_state.Eval(self.context)[:n].copy()

    def Command(self, q: np.ndarray) -> bool:
        """Moves to ``q``; True if it arrived, False if the reflex brought it back.

        Raises:
            RuntimeError: if the robot got stuck (no safe pose left) or the move timed out.
        """
        before = self.Status()
        command = self._source.get_mutable_source_value(
            self._source.GetMyMutableContextFromRoot(self.context)
        )
        if np.array_equal(command.value(), q):
            raise ValueError(
                "the same command twice in a row is one command to MoBeE 1.0; "
                "command another pose in between"
            )
        command.set_value(q)
        t_end = self.context.get_time() + self._timeout
        while self.context.get_time() < t_end:
            self.simulator.AdvanceTo(self.context.get_time() + 5 * self._period)
            status = self.Status()
            if status[MODE] == STUCK:
                raise RuntimeError("the reflex ran out of history: the robot is stuck")
            if status[MODE] not in (MOVING, REWINDING):
                if status[COMPLETED] > before[COMPLETED]:
                    return True
                if status[REFLEXES] > before[REFLEXES]:
                    return False
        raise RuntimeError(f"a command did not end within {self._timeout} s")

    def SetRole(self, name: str, role: str) -> None:
        """Makes a world object an obstacle, a ghost or a target, now."""
        self.simulation.world.SetRole(self.context, name, role)


@dc.dataclass
class ExplorationRecord:
    commands: int = 0
    reflexes: int = 0
    path: list = dc.field(default_factory=list)  # the vertices visited, in order


def ExploreRoadmap(
    roadmap: AdaptiveRoadmap,
    robot: ReflexRobot,
    start: int,
    rng: np.random.Generator,
    *,
    max_commands: int = 10000,
) -> ExplorationRecord:
    """Tries edges until every edge out of every vertex reachable from ``start`` is known.

    From the current vertex an untried edge out of it is tried at random; if there is none, the
    robot travels (along the shortest usable path) to the nearest reachable vertex that has one.
    """
    record, here = ExplorationRecord(path=[start]), start
    while record.commands < max_commands:
        untried = np.flatnonzero((roadmap.edges[:, 0] == here) & (roadmap.status == UNTRIED))
        if len(untried):
            goal = int(roadmap.edges[rng.choice(untried), 1])
            step = [here, goal]
        else:
            distances, predecessors = roadmap.Distances(here)
            open_vertices = np.unique(roadmap.edges[roadmap.status == UNTRIED, 0])
            open_vertices = open_vertices[np.isfinite(distances[open_vertices])]
            if not len(open_vertices):
                return record
            nearest_open = int(open_vertices[np.argmin(distances[open_vertices])])
            step = PathFromPredecessors(predecessors, here, nearest_open)
        a, b = step[0], step[1]
        arrived = robot.Command(roadmap.poses[b])
        roadmap.Record(a, b, arrived)
        record.commands += 1
        record.reflexes += not arrived
        if arrived:
            here = b
            record.path.append(b)
    return record
