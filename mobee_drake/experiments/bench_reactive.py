"""Benchmark: MoBeE 2.0 against Drake's differential inverse kinematics as reactive controllers
(issue 22, point 1; docs/reactive.md).

Both controllers move the same kinematic iCub upper body (20 joints, MoBeE's overlay of
primitives and its collision filters) among the same obstacles at the same control period
(10 ms), from the same start posture, on seeded random reach-past-obstacle tasks:

- ``ball``: a goal posture of the torso and the right arm drawn at random within the joint
  limits (see :func:`DrawGoal`), and a ball of 5-10 cm diameter on the straight path of the
  right palm between start and goal, the robot's solids at least 5 cm clear of it at both ends;
- ``two_balls``: two such balls, one in each half of the path;
- ``shelf``: a ball and a board (a 25 x 25 x 2 cm box) 5-8 cm above it, on a palm path no
  steeper than 30 degrees;
- ``behind_arm``: the left arm held across the chest and a goal of the right arm whose straight
  palm path runs through the left arm (the obstacle is the robot's own body);
- and the shipped ``reach_around_ball``.

MoBeE is given the goal posture as its attractor (the station of the scenario, kinematic
mover); Drake's ``DifferentialInverseKinematicsSystem`` the goal's palm position (its
``LeastSquaresCost`` on the palm's translation), with the goal posture as the nominal posture of
its ``JointCenteringCost``, its ``CollisionConstraint`` on a ``SceneGraphCollisionChecker`` of
the same plant, and its ``JointVelocityLimitConstraint`` at 0.4 rad/s. Its commanded velocities
are integrated every period and the integrated positions fed back. DiffIK runs at two safety
distances: 1 cm, and MoBeE's field margin (equal clearance).

Per controller: the tasks whose palm came within 2 cm of the goal's palm position by 5 s and by
the horizon, the median time to reach, the median final error, the worst clearance (signed
distance of the robot's solids to the obstacles, and to themselves), the control periods in
which solids penetrated, the tasks that broke a joint-space constraint (MoBeE's clauses, or the
joint limits), and the wall time of the controller's own step (median and 95th percentile).

Run: ``mobee-drake bench reactive [--tasks 20] [--seed 0] [--horizon 15] [--controllers ...]
[--mobee-preset defaults] [--detail] [--plot FILE.png] [--doc DOC [--doc-table NAME]]``; with
``--doc`` the tables are also written into the doc's generated block, with the date and the
machine's load (the step costs are wall time, which other work inflates).
"""

import datetime
import os
import time

from mobee_drake.experiments.arguments import CommandParser, NonNegativeInt, PositiveFloat
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.experiments.plots import SaveFigure
from mobee_drake.experiments.reactive_controllers import CONTROLLERS, MOBEE_PRESETS, Controllers
from mobee_drake.experiments.reactive_report import (
    DETAIL_COLUMNS,
    DetailRows,
    KindTable,
    ReactiveFigure,
    Table,
)
from mobee_drake.experiments.reactive_runs import EARLY, HORIZON, RunBenchmark, Summarize
from mobee_drake.experiments.reactive_tasks import PERIOD, SHIPPED, MakeTasks, TaskScene


def main(argv=None) -> None:
    parser = CommandParser(prog="mobee-drake bench reactive", description=__doc__)
    parser.add_argument(
        "--tasks", type=NonNegativeInt, default=20, help="random tasks (after the shipped one)"
    )
    parser.add_argument("--seed", type=NonNegativeInt, default=0, help="the tasks' seed")
    parser.add_argument(
        "--horizon", type=PositiveFloat, default=HORIZON, help="simulated seconds per run"
    )
    parser.add_argument(
        "--controllers",
        nargs="+",
        choices=CONTROLLERS,
        default=CONTROLLERS,
        help="which controllers to run",
    )
    parser.add_argument(
        "--mobee-preset",
        choices=sorted(MOBEE_PRESETS),
        default="defaults",
        help="MoBeE's parameters",
    )
    parser.add_argument("--detail", action="store_true", help="print one CSV row per run")
    parser.add_argument("--plot", default="", help="save the figure to this PNG")
    parser.add_argument("--quiet", action="store_true", help="no line per run while running")
    parser.add_argument("--doc", help="a doc whose generated block (--doc-table) gets the tables")
    parser.add_argument(
        "--doc-table", default="reactive", help="the name of --doc's block (default: reactive)"
    )
    args = parser.parse_args(argv)
    CheckDocBlocks(parser, args.doc, args.doc_table)
    scene = TaskScene()
    tasks = MakeTasks(args.tasks, args.seed, scene)
    available = Controllers(args.mobee_preset)
    controllers = {name: available[name] for name in args.controllers}
    labels = {name: c.label for name, c in controllers.items()}
    begin = time.perf_counter()
    results = RunBenchmark(
        tasks,
        controllers,
        args.horizon,
        scene,
        progress=None if args.quiet else lambda line: print(line, flush=True),
    )
    wall = time.perf_counter() - begin
    early = min(EARLY, args.horizon)
    summaries = [Summarize(labels[name], rows, early) for name, rows in results.items()]
    text = (
        f"{len(tasks)} tasks ({SHIPPED} and {args.tasks} random, seed {args.seed}), "
        f"{args.horizon:g} s each at {1000 * PERIOD:g} ms, in {wall:.0f} s "
        f"({datetime.datetime.now(datetime.UTC):%Y-%m-%d}, {os.cpu_count()} cores at a load "
        f"average of {os.getloadavg()[0]:.1f}):\n\n"
        f"{Table(summaries, args.horizon, early)}\n\n"
        f"{KindTable(results, labels, args.horizon, early)}"
    )
    print(f"\n{text}")
    if args.doc:
        WriteGeneratedTable(args.doc, args.doc_table, _Command(args), text)
    if args.detail:
        print(f"\n{DETAIL_COLUMNS}")
        print("\n".join(DetailRows(results)))
    if args.plot:
        SaveFigure(ReactiveFigure(results, labels, args.horizon, early), args.plot, dpi=90)
        print(f"plot: {args.plot}")


def _Command(args) -> str:
    """The command line that writes ``args.doc``'s block (the options that change the runs)."""
    return (
        f"mobee-drake bench reactive --tasks {args.tasks} --seed {args.seed} --horizon "
        f"{args.horizon:g} --controllers {' '.join(args.controllers)} --mobee-preset "
        f"{args.mobee_preset}"
        + (f" --plot {args.plot}" if args.plot else "")
        + f" --doc {args.doc} --doc-table {args.doc_table}"
    )


if __name__ == "__main__":
    main()
