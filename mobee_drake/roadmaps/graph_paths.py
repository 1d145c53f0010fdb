"""Shortest paths in joint space over a roadmap's directed edges (TRMs, adaptive roadmaps)."""

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra


def JointSpaceDistances(
    poses: np.ndarray, edges: np.ndarray, start: int
) -> tuple[np.ndarray, np.ndarray]:
    """Shortest distances from ``start`` along directed ``edges`` (pairs of pose indices), each as
    long as the joint-space distance between its poses, and the predecessors on those paths."""
    n = len(poses)
    a, b = np.asarray(edges, dtype=int).reshape(-1, 2).T
    lengths = np.linalg.norm(poses[a] - poses[b], axis=1)
    graph = coo_matrix((lengths, (a, b)), shape=(n, n)).tocsr()
    return dijkstra(graph, indices=start, return_predecessors=True)


def ShortestPath(poses: np.ndarray, edges: np.ndarray, start: int, goal: int) -> list[int]:
    """The vertices of the shortest path from ``start`` to ``goal`` ([] if there is none)."""
    return PathFromPredecessors(JointSpaceDistances(poses, edges, start)[1], start, goal)


def PathFromPredecessors(predecessors: np.ndarray, start: int, goal: int) -> list[int]:
    """The path to ``goal`` in the predecessors of a search from ``start`` ([] if none)."""
    if goal != start and predecessors[goal] < 0:
        return []
    path = [goal]
    while path[-1] != start:
        path.append(int(predecessors[path[-1]]))
    return path[::-1]
