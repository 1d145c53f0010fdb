"""Experiment: a state-action space that reshapes itself (ch. 9.4.5; docs/adaptive_space.md).

The curious agent of ch. 7 explores the right arm's shoulder and elbow for ``--actions`` actions
on a fixed space and on the same space maintained by the rules of
:mod:`mobee_drake.planning.space_maintenance`, ``--seeds`` runs of each, paired by seed (the same
generator). The spaces (``--spaces``): ch. 7.3's rank-4 lattice at 12.5-87.5 % (256 states; its
corner states beyond the shoulder's cable constraints are never entered), ch. 7.2's rank-3
lattice (81 states, all reachable), and ``trm``: a task-relevant roadmap over the valid
configurations themselves (:mod:`mobee_drake.trm.configuration`; ``--trm-spacing``, at most
``--trm-states`` states, the rank-4 lattice's number by default), built once by the battery's
job ``roadmap``, its vertices the states and its edges the actions both ways.

Per run, at the end:

- *coverage*: the share of a fixed sample of the arm's valid configurations (within the joint
  limits, every constraint clause satisfied, no collision; ``VALID_SAMPLES`` of them, drawn
  uniformly in fractions of each joint's range) within ``--radius`` (fractions of range) of the
  centre of a state the robot arrived in: how much of what the arm can do the agent has been
  near, whatever its space;
- *prediction error*: ``--tests`` state-actions of states the robot arrived in, drawn at random,
  run once each on a fresh robot (put in the state's centre first; skipped if it does not get
  there): one minus the probability the learned model gave the outcome (held out: the model
  does not learn from them);
- *state-actions tried*: the share of the space's state-actions tried at least once (ch. 7.2's
  coverage, of the space as it ended);
- the space's states and state-actions at the end, its changes by rule, the robot's simulated
  time per action, the wall time and the penetrating periods.

Maintained minus fixed is compared paired by seed, Holm-corrected over the spaces and the three
measures.

Run: ``mobee-drake experiment adaptive-space [--seeds 10] [--actions 3000]
[--output results/adaptive_space] [--doc docs/adaptive_space.md]``.
"""

import collections
import dataclasses as dc
import json
import pathlib

import numpy as np

from mobee_drake.atomic_files import CurrentGeneration
from mobee_drake.experiments.arguments import CommandParser, PositiveFloat, PositiveInt
from mobee_drake.experiments.battery import (
    AddBackendArguments,
    BackendOf,
    Job,
    RunBattery,
    RunFolder,
)
from mobee_drake.experiments.ch7_model_learning import RIGHT_ARM, ExploreJob, Stop
from mobee_drake.experiments.ch8_reaching import ReachRobot
from mobee_drake.experiments.doc_tables import GeneratedTable, WriteGeneratedTable
from mobee_drake.experiments.exploration import ExplorationRun
from mobee_drake.experiments.statistics import ComparePaired, Holm
from mobee_drake.ngik.kinematic_model import KinematicModel
from mobee_drake.owned_folders import OwnedFolder
from mobee_drake.planning.explorers import ExplorerConfig, LoadAgentModel, ObservedOutcomes
from mobee_drake.planning.space_maintenance import RULES, MaintenanceConfig
from mobee_drake.planning.supervisor import ExploringAgent
from mobee_drake.robots.icub import IcubConfig
from mobee_drake.trm.configuration import BuildConfigurationRoadmap

# The lattices compared: their levels (fractions of each joint's range); and "trm", a roadmap
# over the valid configurations (mobee_drake.trm.configuration), built once per battery.
LATTICES = {"rank4": [0.125, 0.375, 0.625, 0.875], "rank3": [0.25, 0.5, 0.75]}
SPACES = (*LATTICES, "trm")
ROADMAP_JOB = "roadmap"
CONDITIONS = ("fixed", "maintained")
AGENT = "right_arm"
VALID_SAMPLES = 2000


@dc.dataclass
class AdaptiveSpaceRun:
    """One run: a space, fixed or maintained, a seed (see the module for the measures)."""

    space: str
    condition: str
    seed: int
    actions: int
    coverage: float
    prediction_error: float
    tests: int
    tried_share: float
    states: int
    state_actions: int
    changes: dict[str, int]
    robot_seconds_per_action: float
    wall_seconds: float
    penetrating_steps: int


def ValidConfigurations(count: int = VALID_SAMPLES, seed: int = 0) -> np.ndarray:
    """(k, 4): valid configurations of the right arm's shoulder and elbow, as fractions of each
    joint's range (see the module), from ``count`` uniform draws."""
    model = KinematicModel(IcubConfig(controlled_joints=RIGHT_ARM))
    fractions = np.random.default_rng(seed).random((count, len(RIGHT_ARM)))
    valid = []
    for f in fractions:
        q = model.lower + f * (model.upper - model.lower)
        if model.IsValid(q) and not model.Evaluate(q).collision_pairs:
            valid.append(f)
    return np.array(valid)


def Coverage(explorer, valid: np.ndarray, radius: float) -> float:
    """The share of ``valid`` within ``radius`` of an arrived-in state's centre."""
    arrived = explorer.space.centres[ObservedOutcomes(explorer).sum(axis=0) > 0]
    if not len(arrived):
        return 0.0
    nearest = np.min(np.linalg.norm(valid[:, None] - arrived[None], axis=2), axis=1)
    return float(np.mean(nearest <= radius))


def PredictionError(explorer, tests: int, seed: int) -> tuple[float, int]:
    """(the mean of one minus the model's probability of each held-out test's outcome, the
    tests run): see the module."""
    space = explorer.space
    arrived = np.flatnonzero(ObservedOutcomes(explorer).sum(axis=0) > 0)
    candidates = np.flatnonzero(np.isin(space.action_state, arrived))
    rng = np.random.default_rng(seed)
    chosen = rng.choice(candidates, size=min(tests, len(candidates)), replace=False)
    robot = ReachRobot(space, target_radius=0.05)
    T = explorer.transitions.Probabilities()
    errors = []
    for sa in chosen:
        state = int(space.action_state[sa])
        if robot.Transition(state) != state:
            continue  # (the robot could not be put there)
        outcome = robot.Transition(int(space.action_goal[sa]))
        errors.append(1.0 - T[sa, outcome])
    return (float(np.mean(errors)) if errors else float("nan")), len(errors)


def RoadmapJob(run: RunFolder, *, spacing: float, max_vertices: int) -> dict:
    """The battery job that builds the "trm" space's roadmap (in ``run.path / "roadmap"``)."""
    roadmap = BuildConfigurationRoadmap(RIGHT_ARM, spacing, max_vertices, progress=run.Progress)
    roadmap.Save(run.path / "roadmap")
    return dict(
        vertices=len(roadmap.q), edges=len(roadmap.edges), build_seconds=roadmap.build_seconds
    )


def AdaptiveSpaceJob(
    run: RunFolder, *, space: str, condition: str, seed: int, actions: int, tests: int,
    radius: float, maintenance: MaintenanceConfig,
) -> dict:  # fmt: skip
    """The battery job: one run (see the module)."""
    agent = ExploringAgent(
        name=AGENT,
        joints=RIGHT_ARM,
        maintenance=maintenance if condition == "maintained" else None,
    )
    if space in LATTICES:
        agent.levels = LATTICES[space]
    else:
        agent.roadmap = str(run.path.parent / ROADMAP_JOB / "roadmap")
    explored = ExplorationRun.FromJson(
        ExploreJob(
            run,
            agents=[agent],
            stop=Stop(actions=actions),
            labels=dict(space=space, condition=condition, seed=seed),
            random_seed=seed,
            chunk=5.0,
            keep_model=True,
        )
    )
    folder = run.path / "model"
    explorer = LoadAgentModel(str(folder), AGENT, ExplorerConfig())
    saved = json.loads(((CurrentGeneration(folder) or folder) / f"{AGENT}.json").read_text())
    changes = collections.Counter(
        c["rule"] for c in saved.get("maintenance", {}).get("changes", [])
    )
    error, tested = PredictionError(explorer, tests, seed)
    done = explored.actions[0]
    return dc.asdict(
        AdaptiveSpaceRun(
            space=space,
            condition=condition,
            seed=seed,
            actions=done,
            coverage=Coverage(explorer, ValidConfigurations(), radius),
            prediction_error=error,
            tests=tested,
            tried_share=float(np.mean(explorer.tries > 0)),
            states=explorer.space.num_states,
            state_actions=explorer.space.num_state_actions,
            changes={rule: changes.get(rule, 0) for rule in RULES},
            robot_seconds_per_action=explored.simulated_seconds / max(done, 1),
            wall_seconds=explored.wall_seconds,
            penetrating_steps=explored.penetrating_steps,
        )
    )


_MEASURES = {
    "coverage": lambda r: r.coverage,
    "prediction error": lambda r: r.prediction_error,
    "state-actions tried": lambda r: r.tried_share,
}


def Report(runs: list[AdaptiveSpaceRun], command: str) -> str:
    """The report's table and the paired comparisons (markdown)."""
    lines = [
        "| space | condition | runs | actions | coverage | prediction error (tests) "
        "| state-actions tried | states | state-actions | changes (prune/drop/shortcut/grow) "
        "| robot s per action | penetrating periods | wall s per run |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|",
    ]
    group = collections.defaultdict(list)
    for r in sorted(runs, key=lambda r: r.seed):
        group[(r.space, r.condition)].append(r)
    for (space, condition), rs in sorted(group.items()):
        changes = "/".join(f"{np.mean([r.changes[rule] for r in rs]):.0f}" for rule in RULES)
        lines.append(
            f"| {space} | {condition} | {len(rs)} | {np.mean([r.actions for r in rs]):.0f} | "
            f"{100 * np.mean([r.coverage for r in rs]):.1f} % | "
            f"{np.nanmean([r.prediction_error for r in rs]):.3f} "
            f"({np.mean([r.tests for r in rs]):.0f}) | "
            f"{100 * np.mean([r.tried_share for r in rs]):.0f} % | "
            f"{np.mean([r.states for r in rs]):.0f} | "
            f"{np.mean([r.state_actions for r in rs]):.0f} | {changes} | "
            f"{np.mean([r.robot_seconds_per_action for r in rs]):.2f} | "
            f"{sum(r.penetrating_steps for r in rs)} | "
            f"{np.mean([r.wall_seconds for r in rs]):.0f} |"
        )
    compared = {}
    for space in sorted({r.space for r in runs}):
        on, off = group[(space, "maintained")], group[(space, "fixed")]
        seeds = sorted({r.seed for r in on} & {r.seed for r in off})
        if len(seeds) < 2:
            continue
        on, off = ([r for r in rs if r.seed in seeds] for rs in (on, off))
        for name, f in _MEASURES.items():
            compared[f"{space}, {name}"] = ComparePaired(
                [f(r) for r in on], [f(r) for r in off], [0] * len(seeds)
            )
    if compared:
        adjusted = Holm([c.t_p for c in compared.values()])
        lines += ["", f"Maintained minus fixed, paired by seed (Holm over the {len(compared)}):"]
        lines += [""] + [f"- {n}: {c.Text(p)}" for (n, c), p in zip(compared.items(), adjusted)]
    return "\n".join(lines) + f"\n\nCommand: `{command}`."


def main(argv: list[str] | None = None) -> None:
    parser = CommandParser(
        prog="mobee-drake experiment adaptive-space", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument("--spaces", nargs="+", choices=SPACES, default=list(SPACES))
    parser.add_argument(
        "--trm-spacing",
        type=PositiveFloat,
        default=0.5,
        help="the trm space: its roadmap's spacing d (fractions of range)",
    )
    parser.add_argument(
        "--trm-states",
        type=PositiveInt,
        default=256,
        help="the trm space: at most this many states (the rank-4 lattice's number, by default)",
    )
    parser.add_argument(
        "--seeds", type=PositiveInt, default=10, help="runs per space and condition"
    )
    parser.add_argument("--actions", type=PositiveInt, default=3000, help="actions per run")
    parser.add_argument("--tests", type=PositiveInt, default=60, help="held-out tests per run")
    parser.add_argument(
        "--radius",
        type=PositiveFloat,
        default=0.125,
        help="coverage: a valid configuration this near (fractions of range) an arrived-in "
        "state's centre counts as covered",
    )
    defaults = MaintenanceConfig()
    parser.add_argument(
        "--every", type=PositiveInt, default=defaults.every, help="actions between rounds"
    )
    parser.add_argument(
        "--rules", nargs="+", choices=RULES, default=list(RULES), help="the maintenance rules"
    )
    parser.add_argument(
        "--prune-after",
        type=PositiveInt,
        default=defaults.prune_after,
        help="tries into a state, none arriving, before it is pruned",
    )
    parser.add_argument(
        "--max-states",
        type=PositiveInt,
        default=None,
        help="the space grows while it has fewer states than this (default: no limit)",
    )
    parser.add_argument("--output", default="results/adaptive_space", help="the battery folder")
    parser.add_argument(
        "--doc", help="a doc whose generated block 'adaptive-space' gets the report"
    )
    AddBackendArguments(parser)
    args = parser.parse_args(argv)
    if args.doc:
        try:
            GeneratedTable(args.doc, "adaptive-space")
        except (OSError, ValueError) as error:
            parser.error(str(error))
    maintenance = MaintenanceConfig(
        every=args.every,
        rules=list(args.rules),
        prune_after=args.prune_after,
        max_states=args.max_states or 0,
    )
    jobs = [
        Job(
            f"{space}_{condition}_seed{seed}",
            AdaptiveSpaceJob,
            dict(
                space=space,
                condition=condition,
                seed=seed,
                actions=args.actions,
                tests=args.tests,
                radius=args.radius,
                maintenance=maintenance,
            ),
            total=args.actions,
        )
        for seed in range(args.seeds)
        for space in args.spaces
        for condition in CONDITIONS
    ]
    output = pathlib.Path(args.output)
    if "trm" in args.spaces:  # (its roadmap first: the trm runs read it)
        roadmap = Job(
            ROADMAP_JOB,
            RoadmapJob,
            dict(spacing=args.trm_spacing, max_vertices=args.trm_states),
            total=args.trm_states,
        )
        RunBattery([roadmap], output, backend=BackendOf(args), description="trm space")
    results = RunBattery(jobs, output, backend=BackendOf(args), description="adaptive space")
    runs = [AdaptiveSpaceRun(**r) for r in results.values()]
    command = "mobee-drake experiment adaptive-space " + " ".join(argv if argv is not None else [])
    report = Report(runs, command.strip())
    with OwnedFolder(output, "battery"):
        (output / "report.md").write_text(report + "\n")
    if args.doc:
        WriteGeneratedTable(args.doc, "adaptive-space", command.strip(), report)
    print(report)


if __name__ == "__main__":
    main()
