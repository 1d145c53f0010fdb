"""Task-Relevant Roadmaps: the advancing front of Alg. 2-4 (dissertation ch. 3.3).

Each vertex is a pose ``q``, its task-space point ``y`` and an *expansion weight* ``w`` (the
likelihood that the map can still grow around it). Each iteration runs NGIK from the vertex of
largest weight, on the problem's costs plus, for each of the ``n`` (task dimension) vertices
nearest to the candidate in task space, the repulsion ``| |y - y'| - d |`` (eq. 3.6, Alg. 3).
A valid, collision-free candidate that meets the problem's terms and lies outside the covered
region ``R`` becomes a vertex, joined to those neighbours; the simplex they span in task space
joins ``R``. Otherwise the weight of the vertex the search started from decays by ``delta``.
The map is done when every weight is spent (or at a vertex budget).

Where Alg. 4 is silent we chose:

- eq. 3.6's ``|(y - y') - d|`` is read as ``| |y - y'| - d |``: the candidate is pushed to the
  distance ``d`` from each neighbour;
- the decay goes to the vertex the search started from (Alg. 4 decrements the running ``e*``,
  which it then overwrites with that vertex's weight);
- among vertices of equal weight the newest expands, so the front advances from recent poses;
- a candidate closer than ``d / 2`` to an existing vertex is rejected like one inside ``R``
  (near the front, ``R`` does not yet cover the space between neighbours);
- ``R`` is the union of the simplices of ``n + 1`` points (a new vertex and its ``n``
  neighbours), each the convex hull of Alg. 4; lower-dimensional hulls cover nothing.
"""

import dataclasses as dc
import json
import pathlib
import time

import numpy as np

from mobee_drake.array_files import WriteArrays
from mobee_drake.atomic_files import CurrentGeneration, StrictJson, WriteGeneration
from mobee_drake.ngik.nes import Minimize, NesConfig
from mobee_drake.ngik.solver import IkProblem
from mobee_drake.roadmaps.graph_paths import ShortestPath
from mobee_drake.trm.task_space import TaskSpace


@dc.dataclass
class TrmConfig:
    """Parameters of Alg. 4."""

    spacing: float = 0.03  # d of eq. 3.6, in task-space units
    delta: float = 0.25  # decay of a vertex's expansion weight per failed search
    sigma: float = 0.15  # NES's initial spread around the expanding vertex (rad)
    nes: NesConfig = dc.field(
        default_factory=lambda: NesConfig(
            variant="snes", max_evaluations=800, target_cost=-1.0, tolerance=2e-3
        )
    )
    max_vertices: int = 5000

    def __post_init__(self):
        if not self.spacing > 0:
            raise ValueError(f"TRM spacing d must be positive, got {self.spacing}")
        if not 0 < self.delta <= 1:
            raise ValueError(f"TRM delta must be in (0, 1], got {self.delta}")


class CoveredRegion:
    """R: a union of task-space simplices, with a vectorised membership test."""

    def __init__(self, dimension: int):
        self.dimension = dimension
        self.simplices: list[tuple[int, ...]] = []  # vertex indices
        self._origins = np.zeros((0, dimension))
        self._inverses = np.zeros((0, dimension, dimension))

    def Add(self, indices: tuple[int, ...], points: np.ndarray) -> bool:
        """Adds the hull of ``points`` (``n + 1`` of them); False if it is degenerate."""
        if len(points) != self.dimension + 1:
            return False
        edges = (points[1:] - points[0]).T  # columns span the simplex
        if abs(np.linalg.det(edges)) < 1e-12 * max(1.0, np.abs(edges).max()) ** self.dimension:
            return False
        self.simplices.append(tuple(int(i) for i in indices))
        self._origins = np.vstack([self._origins, points[0]])
        self._inverses = np.concatenate([self._inverses, np.linalg.inv(edges)[None]])
        return True

    def Contains(self, y: np.ndarray) -> bool:
        if not len(self.simplices):
            return False
        barycentric = np.einsum("kij,kj->ki", self._inverses, y - self._origins)
        inside = (barycentric >= 0).all(axis=1) & (barycentric.sum(axis=1) <= 1)
        return bool(inside.any())


@dc.dataclass
class TaskRelevantRoadmap:
    """G(V, E) and R: vertex poses, task points, weights, edges and the covered simplices."""

    joints: list[str]
    q: np.ndarray  # (V, n_joints) the model's full poses
    y: np.ndarray  # (V, n) task-space points
    weights: np.ndarray  # (V,)
    edges: np.ndarray  # (E, 2) vertex index pairs
    simplices: list[tuple[int, ...]]
    build_seconds: float = 0.0
    searches: int = 0

    @property
    def num_vertices(self) -> int:
        return len(self.q)

    def Path(self, start: int, goal: int) -> list[int]:
        """The shortest path in configuration space along the edges (empty if none)."""
        return ShortestPath(self.q, np.vstack([self.edges, self.edges[:, ::-1]]), start, goal)

    def Save(self, folder: str | pathlib.Path) -> None:
        """Writes ``roadmap.npz`` and ``roadmap.json`` as the newest generation of ``folder``
        (see :func:`~mobee_drake.atomic_files.WriteGeneration`)."""

        def Write(staging: pathlib.Path) -> None:
            WriteArrays(
                staging / "roadmap.npz",
                q=self.q,
                y=self.y,
                weights=self.weights,
                edges=self.edges,
                simplices=np.array(self.simplices, dtype=int),
            )
            (staging / "roadmap.json").write_text(
                StrictJson(
                    {
                        "joints": self.joints,
                        "build_seconds": self.build_seconds,
                        "searches": self.searches,
                    },
                    indent=1,
                )
            )

        WriteGeneration(folder, Write)

    @staticmethod
    def Load(folder: str | pathlib.Path) -> "TaskRelevantRoadmap":
        """The roadmap saved in ``folder`` (its newest generation)."""
        folder = CurrentGeneration(folder) or pathlib.Path(folder)
        for name in ("roadmap.npz", "roadmap.json"):
            if not (folder / name).is_file():
                raise FileNotFoundError(f"{folder}: no {name}; is this a saved roadmap?")
        arrays = np.load(folder / "roadmap.npz")
        info = json.loads((folder / "roadmap.json").read_text())
        return TaskRelevantRoadmap(
            joints=info["joints"],
            q=arrays["q"],
            y=arrays["y"],
            weights=arrays["weights"],
            edges=arrays["edges"].reshape(-1, 2),
            simplices=[tuple(s) for s in arrays["simplices"].tolist()],
            build_seconds=info["build_seconds"],
            searches=info["searches"],
        )


def BuildTrm(
    problem: IkProblem,
    task_space: TaskSpace,
    q_init: np.ndarray,
    config: TrmConfig,
    rng: np.random.Generator,
    *,
    progress=None,
) -> TaskRelevantRoadmap:
    """Alg. 4: grows the roadmap of ``problem``'s poses over ``task_space`` from ``q_init``.

    ``progress(roadmap_size)``, if given, is called after each search.
    """
    n = task_space.dimension
    model = problem.model
    region = CoveredRegion(n)
    qs, weights, edges = [], [], []
    ys = np.zeros((0, n))  # the vertices' task points, grown once per vertex
    began = time.perf_counter()
    searches = 0

    def Nearest(y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # Alg. 2
        """The (up to) n vertices nearest to y, nearest first, and their distances."""
        distances = np.linalg.norm(ys - y, axis=1)
        nearest = (
            np.argpartition(distances, n)[:n] if len(distances) > n else np.arange(len(distances))
        )
        nearest = nearest[np.argsort(distances[nearest], kind="stable")]
        return nearest, distances[nearest]

    def Cost(x: np.ndarray) -> float:  # Alg. 3
        evaluation, cost = problem.Evaluate(x)
        _, distances = Nearest(task_space(evaluation))
        return cost + float(np.sum(np.abs(distances - config.spacing)))

    start, expanding = np.asarray(q_init, dtype=float), None
    while len(qs) < config.max_vertices:
        searches += 1
        result = Minimize(Cost, problem.SearchVector(start), config.sigma, config.nes, rng)
        evaluation, _ = problem.Evaluate(result.x)
        y = task_space(evaluation)
        neighbours, distances = Nearest(y)
        far_enough = not len(neighbours) or distances[0] >= config.spacing / 2
        if (
            problem.IsSolved(evaluation)
            and not evaluation.collision_pairs
            and far_enough
            and not region.Contains(y)
        ):
            new = len(qs)
            qs.append(evaluation.q)
            ys = np.vstack([ys, y])
            weights.append(1.0)
            edges += [(int(i), new) for i in neighbours]
            region.Add((new, *neighbours), ys[[new, *neighbours]])
        elif expanding is not None:
            weights[expanding] = max(0.0, weights[expanding] - config.delta)
        else:
            raise RuntimeError(
                "TRM: NGIK found no valid first pose from q_init; the problem's "
                "terms cannot be met near it"
            )
        if progress is not None:
            progress(len(qs))
        w = np.asarray(weights)
        if not (w > 0).any():
            break
        expanding = len(w) - 1 - int(np.argmax(w[::-1]))  # the newest of the heaviest
        start = qs[expanding]
    return TaskRelevantRoadmap(
        joints=list(model.joints),
        q=np.asarray(qs),
        y=ys,
        weights=np.asarray(weights),
        edges=np.asarray(edges, dtype=int).reshape(-1, 2),
        simplices=list(region.simplices),
        build_seconds=time.perf_counter() - began,
        searches=searches,
    )
