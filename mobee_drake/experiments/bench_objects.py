"""Benchmark: what a scenario's number of objects costs to build, beside Drake's floor.

For each count N, N boxes (2 cm, on a 5 cm grid behind the iCub, none in reach) are built twice,
each in a fresh process under a cap on its address space:

- *Drake's floor*: the iCub and the boxes in a MultibodyPlant and SceneGraph (each box anchored
  collision geometry), the diagram built, its default Context and one signed-distance query;
- *the station*: ``reach_around_ball`` with the boxes as its objects, loaded (with every check
  of the scenario), built, its default Context and one evaluation of MoBeE's total force.

It prints the wall time and the peak resident memory of each, and their ratios. SceneGraph's
collision filter keeps a state per pair of geometries, so both grow with the square of N; a
scenario of more than ``MAX_OBJECTS`` objects is refused at load (the station's cell says so and
how long the refusal took), and a process that outgrows the cap is reported by how it ended (a
MemoryError, or a death by a signal where an allocation cannot raise).

Run: ``mobee-drake bench objects [--counts 100 1000 10000] [--doc docs/benchmarks.md]``.
"""

import multiprocessing
import os
import resource
import signal
import time

import numpy as np
from pydrake.geometry import Box
from pydrake.math import RigidTransform
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, CoulombFriction
from pydrake.systems.framework import DiagramBuilder

from mobee_drake.experiments.arguments import CommandParser, PositiveFloat, PositiveInt
from mobee_drake.experiments.battery import DieWithParent
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.robots.scenario_robot import AddScenarioRobot
from mobee_drake.scenario import BuildScenario, LoadScenario
from mobee_drake.station.config import MAX_OBJECTS, StationConfig

SCENARIO = "reach_around_ball"
BOX = 0.02  # (m) each box's edge
SPACING = 0.05  # (m) the grid's
DOC_TABLE = "object count"
TIMEOUT_SECONDS = 1800.0  # (s) a build longer than this is reported, not waited for


def BoxPositions(count: int) -> np.ndarray:
    """(count, 3) centres on a square grid in the plane x = -1 m, behind the robot."""
    side = int(np.ceil(np.sqrt(count)))
    k = np.arange(count)
    return np.column_stack(
        [np.full(count, -1.0), (k % side - side / 2) * SPACING, (k // side) * SPACING]
    )


def _Floor(count: int) -> None:
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    overlay, _ = AddScenarioRobot(plant, scene_graph, StationConfig().robot)
    friction = CoulombFriction(1.0, 1.0)
    for i, p in enumerate(BoxPositions(count)):
        plant.RegisterCollisionGeometry(
            plant.world_body(), RigidTransform(p), Box(BOX, BOX, BOX), f"box{i}", friction
        )
    plant.Finalize()
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    query = scene_graph.get_query_output_port().Eval(scene_graph.GetMyContextFromRoot(context))
    query.ComputeSignedDistancePairwiseClosestPoints(max(overlay.field_margins.values()))


def _Station(count: int) -> None:
    objects = ", ".join(
        f"{{name: box{i}, shape: !Box {{size: [{BOX}, {BOX}, {BOX}]}}, "
        f"position: [{p[0]}, {p[1]}, {p[2]}]}}"
        for i, p in enumerate(BoxPositions(count))
    )
    station = BuildScenario(LoadScenario(SCENARIO, f"{{objects: [{objects}]}}"))
    context = station.diagram.CreateDefaultContext()
    station.mobee.GetOutputPort("total").Eval(station.mobee.GetMyContextFromRoot(context))


def _Measure(kind: str, count: int, cap_bytes: int, parent: int, pipe) -> None:
    """In a fresh process: (seconds, peak bytes, error or "") of building ``kind`` once."""
    DieWithParent(parent)
    resource.setrlimit(resource.RLIMIT_AS, (cap_bytes, cap_bytes))
    start, error = time.perf_counter(), ""
    try:
        (_Floor if kind == "floor" else _Station)(count)
    except MemoryError:
        error = "over the cap"
    except Exception as failed:  # (reported, not hidden: the scenario's refusal named)
        refused = isinstance(failed, ValueError) and f"at most {MAX_OBJECTS}" in str(failed)
        error = "refused at load" if refused else f"failed: {type(failed).__name__}"
    seconds = time.perf_counter() - start
    pipe.send((seconds, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024, error))


def Measure(
    kind: str, count: int, cap_bytes: int, timeout: float = TIMEOUT_SECONDS
) -> tuple[float, float, str]:
    """(seconds, peak bytes, error or "") of ``kind`` ("floor" or "station") with ``count``
    boxes, in a fresh process capped at ``cap_bytes`` of address space. The error says what
    ended it otherwise: "over the cap" (a MemoryError), "refused at load", "failed: <error>", a
    death by a signal (an allocation that fails where it cannot raise aborts the process), or
    "timed out" after ``timeout`` seconds."""
    spawn = multiprocessing.get_context("spawn")
    receiver, sender = spawn.Pipe(duplex=False)
    process = spawn.Process(
        target=_Measure, args=(kind, count, cap_bytes, os.getpid(), sender), daemon=True
    )
    start = time.perf_counter()
    process.start()
    sender.close()
    if not receiver.poll(timeout):
        process.kill()
    try:
        result = receiver.recv()
    except EOFError:  # (the process died, or was killed above)
        process.join()
        seconds = time.perf_counter() - start
        code = process.exitcode
        ended = "timed out" if seconds >= timeout else f"died ({_Ending(code)})"
        result = (seconds, float("nan"), ended)
    process.join()
    return result


def _Ending(code: int | None) -> str:
    if code is not None and code < 0:
        return signal.Signals(-code).name
    return f"exit code {code}"


def _Cell(seconds: float, peak: float, error: str) -> tuple[str, str]:
    if error:
        return f"{error} ({seconds:.1f} s)", "-"
    return f"{seconds:.2f}", f"{peak / 2**30:.2f}"


def Table(counts: list[int], cap_bytes: int) -> str:
    """The markdown table of the module's measurements for each of ``counts``."""
    lines = [
        "| objects | Drake's floor: build (s) | peak (GiB) | station: build (s) | peak (GiB) "
        "| time ratio | memory ratio |",
        "|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for count in counts:
        floor, station = Measure("floor", count, cap_bytes), Measure("station", count, cap_bytes)
        ratios = ("-", "-")
        if not floor[2] and not station[2]:
            ratios = (f"{station[0] / floor[0]:.2f}", f"{station[1] / floor[1]:.2f}")
        lines.append(
            f"| {count:,} | {' | '.join(_Cell(*floor))} | {' | '.join(_Cell(*station))} "
            f"| {' | '.join(ratios)} |"
        )
        print(lines[-1], flush=True)
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = CommandParser(prog="mobee-drake bench objects", description=__doc__)
    parser.add_argument(
        "--counts", type=PositiveInt, nargs="+", default=[100, 1000, 10000], help="object counts"
    )
    parser.add_argument(
        "--cap-gib",
        type=PositiveFloat,
        default=8.0,
        help="each measuring process's address space (GiB)",
    )
    parser.add_argument("--doc", help="a doc whose generated object-count table to rewrite")
    args = parser.parse_args(argv)
    CheckDocBlocks(parser, args.doc, DOC_TABLE)  # Checked before anything runs.
    print(f"each build in a fresh process capped at {args.cap_gib:g} GiB; limit {MAX_OBJECTS:,}")
    table = Table(args.counts, int(args.cap_gib * 2**30))
    if args.doc:
        command = "mobee-drake bench objects --counts " + " ".join(map(str, args.counts))
        WriteGeneratedTable(args.doc, DOC_TABLE, f"{command} --doc {args.doc}", table)


if __name__ == "__main__":
    main()
