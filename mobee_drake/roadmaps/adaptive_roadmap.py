"""Adaptive roadmap planning (dissertation ch. 4.2-4.3) on MoBeE 1.0's reflex.

A roadmap's vertices are poses and its edges *commands*: a position move from one vertex to
another, never checked before it is tried. Under MoBeE 1.0 a command either arrives or, when the
reflex fires, returns the robot to where it started, so the graph is an MDP whose edge ``a -> b``
leads to ``b`` or back to ``a`` with probability one each once known. An edge found infeasible is
removed and paths are re-planned on what is left; untried edges are planned through
optimistically. Edges are directed: a move may fail one way and not the other.

:class:`ReflexRobot` runs commands on a station moved by the reflex controller (``!Reflex``) and
reports each one's outcome. A command is a transition of the station's state-action executor
(the building block the reach learner acts through too, :mod:`mobee_drake.station.executor`):
its attractor is the position move command, and it ends when the robot has settled.
:func:`ExploreRoadmap` is the exploration of "roadmap from scratch" (biased to vertices with
untried edges, until the feasible subgraph reachable from the start is known).
"""

import dataclasses as dc
import enum

import numpy as np

from mobee_drake.mobee.reflex import Mode, ReflexController, Status
from mobee_drake.roadmaps.graph_paths import (
    JointSpaceDistances,
    PathFromPredecessors,
    ShortestPath,
)
from mobee_drake.station.builder import Station
from mobee_drake.station.executor import StateActionExecutor
from mobee_drake.station.world_events import MakeSimulator


class EdgeStatus(enum.IntEnum):
    """What is known of a roadmap edge."""

    UNTRIED = 0
    FEASIBLE = 1
    INFEASIBLE = 2


@dc.dataclass
class AdaptiveRoadmap:
    """Vertices (poses) and directed edges (commands) with what is known of each edge."""

    poses: np.ndarray  # (V, n) the controlled joints' positions (rad)
    edges: np.ndarray  # (E, 2) directed (from, to)
    status: np.ndarray = None  # (E,) an EdgeStatus per edge

    def __post_init__(self):
        self.edges = np.asarray(self.edges, dtype=int).reshape(-1, 2)
        if self.status is None:
            self.status = np.full(len(self.edges), EdgeStatus.UNTRIED)

    @staticmethod
    def KNearest(poses: np.ndarray, k: int, both_ways: bool = True) -> "AdaptiveRoadmap":
        """Each pose joined to its ``k`` nearest in joint space (ch. 4.3.1): both ways, or with
        ``both_ways=False`` only from the pose to its nearest (the source's "connected to their
        10 nearest neighbors", the edges read as the commands each vertex sends)."""
        poses = np.asarray(poses, dtype=float)
        distances = np.linalg.norm(poses[:, None] - poses[None], axis=2)
        np.fill_diagonal(distances, np.inf)
        pairs = set()
        for a, row in enumerate(distances):
            for b in np.argsort(row, kind="stable")[:k]:
                pairs |= {(a, int(b)), (int(b), a)} if both_ways else {(a, int(b))}
        return AdaptiveRoadmap(poses, np.array(sorted(pairs)))

    def Edge(self, a: int, b: int) -> int:
        found = np.flatnonzero((self.edges[:, 0] == a) & (self.edges[:, 1] == b))
        if not len(found):
            raise ValueError(f"the roadmap has no edge {a} -> {b}")
        return int(found[0])

    def Record(self, a: int, b: int, arrived: bool) -> None:
        self.status[self.Edge(a, b)] = EdgeStatus.FEASIBLE if arrived else EdgeStatus.INFEASIBLE

    def Distances(self, start: int) -> tuple[np.ndarray, np.ndarray]:
        """Shortest joint-space distances from ``start`` over the edges not known infeasible, and
        the predecessors on those paths."""
        return JointSpaceDistances(
            self.poses, self.edges[self.status != EdgeStatus.INFEASIBLE], start
        )

    def Plan(self, start: int, goal: int) -> list[int]:
        """The shortest path in joint space over the edges not known infeasible ([] if none)."""
        return ShortestPath(
            self.poses, self.edges[self.status != EdgeStatus.INFEASIBLE], start, goal
        )

    def Reachable(self, start: int) -> np.ndarray:
        """Which vertices a path of edges not known infeasible reaches from ``start``."""
        distances, _ = self.Distances(start)
        return np.isfinite(distances)


class ReflexRobot:
    """A robot under MoBeE 1.0 that executes position move commands one at a time, on a built
    station with the ``!Reflex`` mover and a state-action executor as its client (a scenario
    with ``attractor: !StateActionAttractor``)."""

    def __init__(self, station: Station):
        if not isinstance(station.mover, ReflexController) or not isinstance(
            station.client, StateActionExecutor
        ):
            raise ValueError(
                "ReflexRobot needs a station with the !Reflex mover and a "
                "!StateActionAttractor client"
            )
        self.station = station
        self.simulator = MakeSimulator(station)
        self.context = self.simulator.get_mutable_context()
        self.simulator.Initialize()
        self._reflex, self._executor = station.mover, station.client
        self._executor_context = self._executor.GetMyMutableContextFromRoot(self.context)
        self._period = station.config.time_step

    def Status(self) -> np.ndarray:
        return (
            self._reflex.GetOutputPort("status")
            .Eval(self._reflex.GetMyContextFromRoot(self.context))
            .copy()
        )

    def Positions(self) -> np.ndarray:
        n = len(self.station.mobee.joints)
        return self.station.robot_state.Eval(self.context)[:n].copy()

    def Command(self, q: np.ndarray) -> bool:
        """Moves to ``q``; True if it arrived, False if the reflex brought it back.

        Raises:
            RuntimeError: if the robot got stuck (no safe pose left) or the move timed out.
        """
        before = self.Status()
        if np.array_equal(self.station.attractor.Eval(self.context), q):
            raise ValueError(
                "the same command twice in a row is one command to MoBeE 1.0; "
                "command another pose in between"
            )
        self._executor.StartTransition(self._executor_context, q)
        while not self._executor.Done(self._executor_context):
            self.simulator.AdvanceTo(self.context.get_time() + 5 * self._period)
            if self.Status()[Status.MODE] == Mode.STUCK:
                raise RuntimeError("the reflex ran out of history: the robot is stuck")
        status = self.Status()
        if status[Status.MODE] not in (Mode.MOVING, Mode.REWINDING):
            if status[Status.COMPLETED] > before[Status.COMPLETED]:
                return True
            if status[Status.REFLEXES] > before[Status.REFLEXES]:
                return False
        raise RuntimeError("a command did not end within the executor's timeout")

    def SetRole(self, name: str, role: str) -> None:
        """Makes a world object an obstacle, a ghost or a target, now."""
        self.station.world.SetRole(self.context, name, role)


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
        untried = np.flatnonzero(
            (roadmap.edges[:, 0] == here) & (roadmap.status == EdgeStatus.UNTRIED)
        )
        if len(untried):
            goal = int(roadmap.edges[rng.choice(untried), 1])
            step = [here, goal]
        else:
            distances, predecessors = roadmap.Distances(here)
            open_vertices = np.unique(roadmap.edges[roadmap.status == EdgeStatus.UNTRIED, 0])
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
