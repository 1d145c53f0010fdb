"""Build the example roadmaps (ch. 3.4), measure them and show them.

For each example: the roadmap (``<example>/roadmap.npz|json``), a figure of the palm's positions
over the vertices with the edges (as Fig. 3.1-3.3, 3.8), a Meshcat recording (``<example>.html``:
the marker cloud, the edges and the robot moving along the path between the two vertices
farthest apart in task space) and a report of what was measured: size, build speed, and how
many edges are free of collisions when interpolated (TRM edges are not checked when built).

Each example's task-space spacing ``d`` and NES spread are its own (:mod:`mobee_drake.trm.catalogue`
lists the examples by the source's figures). ``--doc`` writes the table of every example built
into a doc's generated block.

Run: ``mobee-drake experiment trm --output DIR [--examples reach_into raise_a_glass ...]
[--max-vertices N] [--seed S] [--doc docs/roadmaps.md]``.
"""

import dataclasses as dc
import pathlib

import numpy as np

from mobee_drake.atomic_files import WriteTextAtomically
from mobee_drake.experiments.arguments import CommandParser, NonNegativeInt, PositiveInt
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.experiments.plots import Figure, SaveFigure, plt
from mobee_drake.owned_folders import OwnedFolder
from mobee_drake.station.viewer import RecordingMeshcat
from mobee_drake.trm.catalogue import EXAMPLES
from mobee_drake.trm.display import MarkerCloud, PathMotion, RecordMotion, ShowRoadmap
from mobee_drake.trm.examples import OpenBox, TrmExample
from mobee_drake.trm.roadmap import BuildTrm, TaskRelevantRoadmap, TrmConfig

EDGE_SAMPLES = 10  # interpolated poses per edge for the collision check


def EdgeCollisions(example: TrmExample, roadmap: TaskRelevantRoadmap) -> int:
    """How many edges collide somewhere along their joint-space interpolation."""
    colliding = 0
    for a, b in roadmap.edges:
        for s in np.linspace(0.0, 1.0, EDGE_SAMPLES + 1)[1:-1]:
            q = (1 - s) * roadmap.q[a] + s * roadmap.q[b]
            if example.model.Evaluate(q).collision_pairs:
                colliding += 1
                break
    return colliding


def FarthestPair(roadmap: TaskRelevantRoadmap) -> tuple[int, int]:
    y = roadmap.y
    distances = np.linalg.norm(y[:, None, :] - y[None, :, :], axis=2)
    a, b = np.unravel_index(np.argmax(distances), distances.shape)
    return int(a), int(b)


def RoadmapFigure(
    points: np.ndarray, roadmap: TaskRelevantRoadmap, title: str, boxes: bool
) -> Figure:
    """The palm's positions over the roadmap's vertices with its edges (as Fig. 3.1-3.3, 3.8),
    and with ``boxes`` the open box's walls and floor as wireframes."""
    figure = plt.figure(figsize=(7, 5.5))
    axes = figure.add_subplot(projection="3d")
    for i, (a, b) in enumerate(roadmap.edges):
        axes.plot(
            *points[[a, b]].T,
            color="0.75",
            linewidth=0.4,
            label=None if i else f"edge ({len(roadmap.edges)})",
        )
    axes.scatter(*points.T, s=6, color="tab:blue", label=f"palm at a vertex ({len(points)})")
    if boxes:
        signs = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).T.reshape(-1, 3)
        label = "the open box's walls and floor"
        for obj in OpenBox():
            corners = np.array(obj.position) + signs * np.array(obj.shape.size) / 2
            for i, j in zip(*np.triu_indices(8, 1)):
                if np.sum(signs[i] != signs[j]) == 1:
                    axes.plot(*corners[[i, j]].T, color="tab:brown", linewidth=0.6, label=label)
                    label = None
    axes.set(xlabel="x [m] (back)", ylabel="y [m] (right)", zlabel="z [m] (up)", title=title)
    axes.legend(loc="upper left", fontsize="small")
    return figure


DOC_TABLE = "trm-examples"


def RunExample(name: str, output: pathlib.Path, config: TrmConfig, seed: int) -> tuple[str, str]:
    """Builds, saves, draws and records one example; returns its report section and its row of
    the examples' table."""
    meshcat = RecordingMeshcat()
    example = EXAMPLES[name](meshcat)
    config = dc.replace(config, spacing=example.spacing, sigma=example.sigma)
    roadmap = BuildTrm(
        example.problem, example.task_space, example.q_init, config, np.random.default_rng(seed)
    )
    roadmap.Save(output / name)
    points = MarkerCloud(example.model, roadmap, example.marker)
    SaveFigure(
        RoadmapFigure(
            points,
            roadmap,
            f"{name}: the right palm over a task-relevant roadmap of {roadmap.num_vertices} "
            f"vertices\n(spacing d = {config.spacing}, seed {seed}; cf. Fig. 3.1-3.11)",
            boxes=name == "reach_into",
        ),
        output / f"{name}.png",
        dpi=120,
    )
    start, goal = FarthestPair(roadmap)
    path = roadmap.Path(start, goal)
    ShowRoadmap(meshcat, points, roadmap)
    RecordMotion(example.model, PathMotion(roadmap, path))
    WriteTextAtomically(output / f"{name}.html", meshcat.StaticHtml())
    colliding = EdgeCollisions(example, roadmap)
    seconds = roadmap.build_seconds
    extent = roadmap.y.max(axis=0) - roadmap.y.min(axis=0)
    extent_text = np.round(extent, 3).tolist()
    section = "\n".join(
        [
            f"## {name}",
            "",
            f"- {roadmap.num_vertices} vertices, {len(roadmap.edges)} edges, "
            f"{len(roadmap.simplices)} simplices in R; {roadmap.searches} NGIK searches "
            f"({roadmap.searches - roadmap.num_vertices} rejected)",
            f"- built in {seconds:.1f} s: {roadmap.num_vertices / seconds:.2f} vertices/s, "
            f"{roadmap.searches / seconds:.2f} searches/s",
            f"- task-space extent {extent_text}; spacing d = {config.spacing}, NES spread "
            f"{config.sigma} rad",
            f"- edges colliding along their interpolation ({EDGE_SAMPLES} samples): {colliding} of "
            f"{len(roadmap.edges)}",
            f"- path shown: {len(path)} vertices from {start} to {goal}",
            f"- figure `{name}.png`, Meshcat recording `{name}.html`, roadmap `{name}/`",
            "",
        ]
    )
    row = (
        f"| {name} | {example.task_space.dimension} | {config.spacing:g} | {roadmap.num_vertices} "
        f"| {len(roadmap.edges)} | {roadmap.searches} | {seconds:.0f} | {extent_text} | "
        f"{colliding} of {len(roadmap.edges)} |"
    )
    return section, row


TABLE_HEADER = [
    "| roadmap | task dimensions | spacing d | vertices | edges | NGIK searches | build s | "
    "task-space extent | edges colliding when interpolated |",
    "|---|---:|---:|---:|---:|---:|---:|---|---|",
]


def main(argv: list[str] | None = None) -> None:
    parser = CommandParser(
        prog="mobee-drake experiment trm",
        description=__doc__.split("\n")[0],
    )
    parser.add_argument(
        "--output", default="results/trm", help="where the roadmaps, figures and report go"
    )
    parser.add_argument(
        "--examples",
        nargs="+",
        choices=sorted(EXAMPLES),
        default=list(EXAMPLES),
        help="the examples of ch. 3.4 to build",
    )
    parser.add_argument(
        "--max-vertices",
        type=PositiveInt,
        default=TrmConfig.max_vertices,
        help="the largest roadmap built",
    )
    parser.add_argument(
        "--seed", type=NonNegativeInt, default=0, help="seed of the roadmap builder"
    )
    parser.add_argument("--doc", help="a doc whose generated block to rewrite with the table")
    parser.add_argument("--doc-table", default=DOC_TABLE, help="the name of --doc's block")
    args = parser.parse_args(argv)
    CheckDocBlocks(parser, args.doc, args.doc_table)
    output = pathlib.Path(args.output)
    config = TrmConfig(max_vertices=args.max_vertices)
    # (Claimed like every folder a command writes: never a user's, one writer at a time.)
    with OwnedFolder(output, "trm roadmaps"):
        built = [RunExample(name, output, config, args.seed) for name in args.examples]
        table = "\n".join(TABLE_HEADER + [row for _, row in built])
        report = (
            "# Task-relevant roadmaps\n\n"
            + table
            + "\n\n"
            + "\n".join(section for section, _ in built)
        )
        WriteTextAtomically(output / "report.md", report)
    print(report)
    if args.doc:
        command = " ".join(
            ["mobee-drake experiment trm --output", str(output), "--examples", *args.examples,
             "--max-vertices", str(args.max_vertices), "--seed", str(args.seed)]
        )  # fmt: skip
        WriteGeneratedTable(args.doc, args.doc_table, f"{command} --doc {args.doc}", table)


if __name__ == "__main__":
    main()
