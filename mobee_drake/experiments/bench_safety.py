"""Benchmark: can a client push the robot through an obstacle? MoBeE's safety guarantee under
saturated client forces (docs/mobee.md, "The safety guarantee").

A client's channels all push one marker along a direction, far beyond MoBeE's squash maxima:
the attractor (the scenario's), a configuration-space force ``c J^T u`` (eq. 5.9) and a workspace
force ``f u`` on the marker (eq. 5.10), with c = f = 1000.

- ``scenes``: fixed pushes into a table (the hand, a box, slides and turns on the table top), a
  ball (the table close below it) and the robot's own body, for ``--push-seconds`` each, for the
  kinematic robot and the dynamic robot's three control modalities, with MoBeE's safety barrier
  on and off;
- ``babbling``: ``motor_babbling`` (the kinematic robot, random attractors every 4 s above a
  table) with the push's direction drawn anew every second, for ``--babbling-seconds``, beside
  the same run without client forces;

each with MoBeE's constants of every ``--preset``. Each run: the closest approach of the
robot's solids to the obstacle and to itself, and the control periods in which solid geometry
penetrated, with the deepest penetration. The runs are printed as they end; with ``--output``
they are written to ``safety.json`` there (typed rows, :class:`SceneResult` and
:class:`BabblingResult`) with the tables in ``safety.md``, and with ``--doc`` the tables in
docs/mobee.md are rewritten from them (``--report-only``: from an earlier ``--output``).

Run: ``mobee-drake bench safety --output results/safety --doc docs/mobee.md``.
"""

import contextlib
import dataclasses as dc
import json
import pathlib

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from mobee_drake.atomic_files import StrictJson, WriteTextAtomically
from mobee_drake.experiments.arguments import CommandParser, PositiveFloat
from mobee_drake.experiments.doc_tables import CheckDocBlocks, WriteGeneratedTable
from mobee_drake.experiments.platform_record import PlatformRecord
from mobee_drake.owned_folders import OwnedFolder
from mobee_drake.scenario import LoadScenario, Scenario
from mobee_drake.station.builder import MakeMobeeStation
from mobee_drake.station.parts import ClientPorts, StationParts
from mobee_drake.station.runner import RunStation, RunSummary

# Far beyond every squash maximum (20-40): the client's forces are saturated.
PUSH = 1000.0


class SaturatedPush(LeafSystem):
    """Pushes one marker along a unit direction u with a configuration-space force
    ``PUSH J^T u`` and a workspace force ``PUSH u``; with ``every`` > 0 it draws u anew,
    uniformly on the sphere, every ``every`` seconds (u is its discrete state; the k-th draw is
    seeded by ``(seed, k)``, so that every context draws the same directions).

    .. pydrake_system::

        name: SaturatedPush
        input_ports:
        - marker_jacobians
        output_ports:
        - config_force
        - marker_forces
    """

    def __init__(
        self,
        *,
        num_joints: int,
        num_markers: int,
        marker: int,
        direction,
        every: float = 0.0,
        seed: int = 0,
    ):
        super().__init__()
        self._n, self._m, self._marker = num_joints, num_markers, marker
        u = np.asarray(direction, dtype=float)
        self._jacobians = self.DeclareVectorInputPort(
            "marker_jacobians", 3 * num_markers * num_joints
        )
        self._u = self.DeclareDiscreteState(BasicVector(u / np.linalg.norm(u)))
        self.DeclareVectorOutputPort(
            "config_force",
            num_joints,
            self._CalcConfigForce,
            prerequisites_of_calc={self._jacobians.ticket(), self.discrete_state_ticket(self._u)},
        )
        self.DeclareVectorOutputPort(
            "marker_forces",
            3 * num_markers,
            self._CalcMarkerForces,
            prerequisites_of_calc={self.discrete_state_ticket(self._u)},
        )
        self._every, self._seed = every, seed
        if every > 0:
            self.DeclarePeriodicDiscreteUpdateEvent(every, every, self._Draw)

    def _Direction(self, context) -> np.ndarray:
        return context.get_discrete_state(self._u).value()

    def _Draw(self, context, discrete_state) -> None:
        draw = round(context.get_time() / self._every)
        u = np.random.default_rng([self._seed, draw]).normal(size=3)
        discrete_state.get_mutable_vector(self._u).SetFromVector(u / np.linalg.norm(u))

    def _CalcConfigForce(self, context, output) -> None:
        J = self._jacobians.Eval(context).reshape(self._m, 3, self._n)[self._marker]
        output.SetFromVector(PUSH * self._Direction(context) @ J)

    def _CalcMarkerForces(self, context, output) -> None:
        forces = np.zeros((self._m, 3))
        forces[self._marker] = PUSH * self._Direction(context)
        output.SetFromVector(forces.ravel())


@dc.dataclass
class Scene:
    """A scenario's overrides and the push: on a marker, along a direction (world)."""

    name: str
    overrides: str
    marker: str
    direction: tuple[float, float, float]
    obstacle: str


# The shipped reach_around_ball (the right palm at (-0.31, 0.14, 0.01), a table whose top is at
# z = -0.15, a ball of 4 cm at (-0.33, 0.08, -0.05)), pushed three ways.
SCENES = (
    Scene("table", "{objects: [{name: table, shape: !Box {size: [0.5, 0.9, 0.04]}, "
          "position: [-0.38, 0.0, -0.17]}]}", "r_palm", (0.0, 0.0, -1.0), "table"),
    Scene("ball", "{}", "r_palm", (-0.02, -0.06, -0.06), "ball"),
    Scene("self", "{objects: []}", "r_palm", (0.5, -1.0, 0.0), "(self)"),
)  # fmt: skip
MOVERS = {
    "kinematic": "!Kinematic {}",
    "position": "!Dynamic {control: position}",
    "velocity": "!Dynamic {control: velocity}",
    "force": "!Dynamic {control: force}",
}


def PushedRun(
    scenario: Scenario,
    *,
    marker: str,
    direction,
    every: float = 0.0,
    push: bool = True,
) -> RunSummary:
    """Runs ``scenario`` with its own client, plus (with ``push``) a :class:`SaturatedPush` on
    ``marker``; returns the run's summary."""

    def ClientAndPush(parts: StationParts) -> ClientPorts:
        client = scenario.attractor.AddToBuilder(parts)
        if not push:
            return client
        mobee = parts.mobee
        adversary = parts.builder.AddNamedSystem(
            "saturated_push",
            SaturatedPush(
                num_joints=len(mobee.joints),
                num_markers=len(mobee.marker_names),
                marker=mobee.marker_index(marker),
                direction=direction,
                every=every,
                seed=parts.random_seed,
            ),
        )
        parts.builder.Connect(
            mobee.GetOutputPort("marker_jacobians"), adversary.GetInputPort("marker_jacobians")
        )
        return dc.replace(
            client,
            config_force=adversary.GetOutputPort("config_force"),
            marker_forces=adversary.GetOutputPort("marker_forces"),
        )

    station = MakeMobeeStation(scenario, prebuild_callback=ClientAndPush)
    return RunStation(station, scenario.duration, simulator_config=scenario.simulator_config)


# MoBeE's constants under test, as a scenario's YAML tags them (mobee_drake/mobee/params.py).
PRESETS = {"defaults": "!MobeeParams", "dissertation": "!Dissertation"}


def _MobeeOverride(preset: str, barrier: bool = True) -> str:
    return f"mobee: {PRESETS[preset]} {{barrier: {{enabled: {str(barrier).lower()}}}}}"


def SceneRun(
    scene: Scene,
    mover: str,
    *,
    barrier: bool = True,
    seconds: float = 4.0,
    preset: str = "defaults",
) -> RunSummary:
    """One fixed push of ``scene`` on the robot ``mover`` (a key of MOVERS), with MoBeE's
    constants ``preset`` (a key of PRESETS)."""
    scenario = LoadScenario(
        "reach_around_ball",
        [
            scene.overrides,
            f"{{mover: {MOVERS[mover]}, duration: {seconds}, data_log: {{enabled: false}}, "
            f"{_MobeeOverride(preset, barrier)}}}",
        ],
    )
    return PushedRun(scenario, marker=scene.marker, direction=scene.direction)


def BabblingRun(*, preset: str, seconds: float, push: bool) -> RunSummary:
    """``motor_babbling`` for ``seconds`` with MoBeE's constants ``preset``, with or without
    random saturated pushes on the right palm (redrawn every second)."""
    scenario = LoadScenario(
        "motor_babbling",
        f"{{duration: {seconds}, data_log: {{enabled: false}}, {_MobeeOverride(preset)}}}",
    )
    return PushedRun(scenario, marker="r_palm", direction=(0, 0, -1), every=1.0, push=push)


@dc.dataclass
class Safety:
    """What one run did to safety (m; the closest approaches are signed distances, None where
    the pair never came inside a field)."""

    closest_to_obstacle: float | None
    closest_to_itself: float | None
    penetrating_periods: int
    deepest_penetration: float

    @staticmethod
    def Of(summary: RunSummary, obstacle: str) -> "Safety":
        report = summary.safety
        return Safety(
            report.closest_approach.get(obstacle),
            report.closest_approach.get("(self)"),
            report.penetrating_steps,
            report.deepest_penetration,
        )


@dc.dataclass
class SceneResult:
    """One fixed push (a row of the scenes' table: a scene, preset, length and barrier; a
    column: the mover)."""

    scene: str
    preset: str
    seconds: float
    barrier: bool
    mover: str
    safety: Safety


@dc.dataclass
class BabblingResult:
    """One run of motor babbling."""

    preset: str
    seconds: float
    pushed: bool
    safety: Safety


def _Millimetres(value: float | None) -> str:
    return "-" if value is None else f"{1000 * value:+.1f}"


def ScenesTable(results: list[SceneResult]) -> str:
    """The scenes as a table: per scene, preset, push length and barrier, each mover's closest
    approach to the obstacle (mm, negative: inside it) and its penetrating periods."""
    rows: dict[tuple, dict[str, SceneResult]] = {}
    for r in results:
        rows.setdefault((r.scene, r.preset, r.seconds, r.barrier), {})[r.mover] = r
    lines = [
        "| push into | MoBeE | s | barrier | " + " | ".join(MOVERS) + " |",
        "|---|---|---:|---|" + "---:|" * len(MOVERS),
    ]
    for (scene, preset, seconds, barrier), by_mover in rows.items():
        cells = [
            "n/a"
            if mover not in by_mover
            else f"{_Millimetres(by_mover[mover].safety.closest_to_obstacle)} "
            f"({by_mover[mover].safety.penetrating_periods})"
            for mover in MOVERS
        ]
        lines.append(
            f"| {scene} | {preset} | {seconds:g} | {'on' if barrier else 'off'} | "
            + " | ".join(cells)
            + " |"
        )
    return "\n".join(lines) + "\n"


def BabblingTable(results: list[BabblingResult]) -> str:
    lines = [
        "| MoBeE | s | client | closest to the table (mm) | closest to itself (mm) | "
        "penetrating periods | deepest (mm) |",
        "|---|---:|---|---:|---:|---:|---:|",
    ]
    for r in results:
        s = r.safety
        lines.append(
            f"| {r.preset} | {r.seconds:g} | "
            f"{'random saturated pushes' if r.pushed else 'none'} | "
            f"{_Millimetres(s.closest_to_obstacle)} | {_Millimetres(s.closest_to_itself)} | "
            f"{s.penetrating_periods} | {1000 * s.deepest_penetration:.1f} |"
        )
    return "\n".join(lines) + "\n"


def _RunScenes(args, record) -> None:
    print(f"Saturated pushes (c = f = {PUSH:g}), barrier off and on:", flush=True)
    for preset in args.preset:
        for seconds in args.push_seconds:
            for scene in SCENES:
                for barrier in (False, True):
                    for mover in MOVERS:
                        summary = SceneRun(
                            scene, mover, barrier=barrier, seconds=seconds, preset=preset
                        )
                        result = SceneResult(
                            scene.name, preset, seconds, barrier, mover,
                            Safety.Of(summary, scene.obstacle),
                        )  # fmt: skip
                        record(result)
                        print(f"  {_Label(result)}: {_Line(result.safety)}", flush=True)


def _RunBabbling(args, record) -> None:
    print("motor_babbling (kinematic robot, barrier on):", flush=True)
    for preset in args.preset:
        for push in (False, True):
            summary = BabblingRun(preset=preset, seconds=args.babbling_seconds, push=push)
            result = BabblingResult(
                preset, args.babbling_seconds, push, Safety.Of(summary, "table")
            )
            record(result)
            print(f"  {preset}, pushed {push}: {_Line(result.safety)}", flush=True)


def _Label(r: SceneResult) -> str:
    barrier = "on" if r.barrier else "off"
    return f"{r.scene}, {r.preset}, {r.seconds:g} s, barrier {barrier}, {r.mover}"


def _Line(s: Safety) -> str:
    return (
        f"closest {_Millimetres(s.closest_to_obstacle)} mm (itself "
        f"{_Millimetres(s.closest_to_itself)}), {s.penetrating_periods} penetrating periods, "
        f"deepest {1000 * s.deepest_penetration:.1f} mm"
    )


@dc.dataclass
class SafetyResults:
    """The benchmark's results file: the command that ran it, the platform it ran on
    (:func:`~mobee_drake.experiments.platform_record.PlatformRecord`; empty in files from before
    it was kept) and every run."""

    command: str
    scenes: list[SceneResult] = dc.field(default_factory=list)
    babbling: list[BabblingResult] = dc.field(default_factory=list)
    platform: dict = dc.field(default_factory=dict)

    def Record(self, result: SceneResult | BabblingResult) -> None:
        (self.scenes if isinstance(result, SceneResult) else self.babbling).append(result)

    def Save(self, path: pathlib.Path) -> None:
        WriteTextAtomically(path, StrictJson(dc.asdict(self), indent=1))

    @staticmethod
    def Load(path: pathlib.Path) -> "SafetyResults":
        data = json.loads(path.read_text())
        return SafetyResults(
            command=data["command"],
            scenes=[SceneResult(**{**r, "safety": Safety(**r["safety"])}) for r in data["scenes"]],
            babbling=[
                BabblingResult(**{**r, "safety": Safety(**r["safety"])}) for r in data["babbling"]
            ],
            platform=data.get("platform", {}),
        )

    def Tables(self) -> dict[str, str]:
        """The generated tables by name (those with results)."""
        tables = {}
        if self.scenes:
            tables["safety scenes"] = ScenesTable(self.scenes)
        if self.babbling:
            tables["safety babbling"] = BabblingTable(self.babbling)
        return tables


def _Parser() -> CommandParser:
    parser = CommandParser(prog="mobee-drake bench safety", description=__doc__)
    parser.add_argument(
        "--part",
        nargs="+",
        choices=["scenes", "babbling"],
        default=["scenes", "babbling"],
        help="which parts to run",
    )
    parser.add_argument(
        "--preset", nargs="+", choices=sorted(PRESETS), default=sorted(PRESETS),
        help="MoBeE's constants",
    )  # fmt: skip
    parser.add_argument(
        "--push-seconds", nargs="+", type=PositiveFloat, default=[4.0, 30.0],
        help="simulated time of each fixed push (scenes)",
    )  # fmt: skip
    parser.add_argument(
        "--babbling-seconds", type=PositiveFloat, default=1800.0,
        help="simulated time of each babbling run",
    )  # fmt: skip
    parser.add_argument(
        "--output", help="a folder (new, empty or an earlier output) for safety.json and .md"
    )
    parser.add_argument("--doc", help="a doc whose generated safety tables to rewrite")
    parser.add_argument(
        "--report-only", action="store_true",
        help="run nothing: write the tables (and --doc) from --output's safety.json",
    )  # fmt: skip
    return parser


def main(argv=None) -> None:
    parser = _Parser()
    args = parser.parse_args(argv)
    if args.report_only and not args.output:
        parser.error("--report-only needs --output, the folder of an earlier run")
    command = "mobee-drake bench safety " + " ".join(argv if argv is not None else [])
    CheckDocBlocks(parser, args.doc, "safety scenes", "safety babbling")
    folder = pathlib.Path(args.output) if args.output else None
    with OwnedFolder(folder, "safety benchmark") if folder else contextlib.nullcontext():
        if args.report_only:
            path = folder / "safety.json"
            if not path.is_file():
                parser.error(f"--output {folder}: holds no safety.json to report")
            results = SafetyResults.Load(path)
        else:
            results = SafetyResults(command.strip(), platform=PlatformRecord())

            def Record(result) -> None:  # Saved after every run: an interrupt loses one run.
                results.Record(result)
                if folder:
                    results.Save(folder / "safety.json")

            if "scenes" in args.part:
                _RunScenes(args, Record)
            if "babbling" in args.part:
                _RunBabbling(args, Record)
        tables = results.Tables()
        text = "\n".join(tables.values())
        print("\n" + text)
        if folder:
            WriteTextAtomically(folder / "safety.md", text)
    if args.doc:
        for name, table in tables.items():
            WriteGeneratedTable(args.doc, name, results.command, table)


if __name__ == "__main__":
    main()
