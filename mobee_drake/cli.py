"""The ``mobee-drake`` command: one subcommand per job a user runs."""

import argparse
import difflib
import hashlib
import importlib
import itertools
import logging
import math
import pathlib
import re
import sys

import numpy as np
from pydrake.geometry import StartMeshcat
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from mobee_drake import __version__
from mobee_drake.atomic_files import WriteJsonAtomically, WriteTextAtomically
from mobee_drake.experiments.arguments import CommandParser, NonEmpty, PositiveFloat
from mobee_drake.experiments.battery import BatteryError, BatteryRefused, TerminationInterrupts
from mobee_drake.mobee.system import Mobee
from mobee_drake.owned_folders import CanWrite, FolderError
from mobee_drake.resources import ResolveScenarioFile, ScenarioNames, UnknownScenario
from mobee_drake.robots.icub import AddIcub, IcubConfig
from mobee_drake.robots.model_cache import IcubModelNames
from mobee_drake.scenario import (
    BuildScenario,
    LoadScenario,
    ResumableConfiguration,
    ScenarioDoubts,
)
from mobee_drake.scenario_reference import ScenarioReference
from mobee_drake.station.attractors import SliderAttractor
from mobee_drake.station.checkpoint import CheckpointError
from mobee_drake.station.runner import RunStation
from mobee_drake.station.safety import StartsInPenetrationError
from mobee_drake.station.viewer import RecordingMeshcat

# Whether a user's mistake shows its traceback (``--debug``).
_debug = False


# The longest error line shown: a message quoting a huge value (a 10 MB key in a file) is cut.
MAX_ERROR_LINE = 1000


def _PrintError(message: str, kind: str = "error") -> None:
    """``kind: message`` on stderr, on one line of at most about :data:`MAX_ERROR_LINE`."""
    message = message.replace("\n", " ")
    if len(message) > MAX_ERROR_LINE:
        cut = len(message) - MAX_ERROR_LINE
        message = f"{message[: MAX_ERROR_LINE - 200]} [... {cut:,} characters ...] {message[-200:]}"
    print(f"{kind}: {message}", file=sys.stderr)


def _Fail(message: str) -> None:
    """Ends the command on a user's mistake: one line on stderr, exit code 2 (with ``--debug``,
    the exception being handled is raised again, with its traceback)."""
    if _debug and sys.exc_info()[1] is not None:
        raise
    _PrintError(message)
    sys.exit(2)


def _RunParser() -> CommandParser:
    """The command line of ``mobee-drake run``."""
    parser = CommandParser(
        prog="mobee-drake run",
        description="Simulate a scenario: a file, or the name of a shipped one ("
        + ", ".join(ScenarioNames())
        + "). Headless by default: the run is recorded to results/<name>.html unless "
        "--record or --no-record says otherwise (Drake's Meshcat records through its server: "
        "that one listens on localhost only, silently), its data log written to "
        "results/<name>.log.parquet and its summary to results/<name>.summary.json, where "
        "<name> is the scenario's, followed by a hash of --set and --duration when they are "
        "given (variants never overwrite each other); --meshcat serves the live view.",
    )
    parser.add_argument("scenario", help="a scenario file or a shipped scenario's name")
    parser.add_argument(
        "--duration", type=PositiveFloat, help="seconds to simulate instead of the scenario's"
    )
    # Each flag and its opposite exclude each other (one line names both).
    record, log, view = (parser.add_mutually_exclusive_group() for _ in range(3))
    record.add_argument(
        "--record", type=NonEmpty, help="save a replayable Meshcat recording to this HTML file"
    )
    record.add_argument(
        "--no-record", action="store_true", help="do not save a recording (opens no port)"
    )
    log.add_argument(
        "--log",
        type=NonEmpty,
        help="write the data log (Parquet) to this file instead of beside the summary; "
        "full force vectors with --set '{data_log: {full_forces: true}}'",
    )
    log.add_argument("--no-log", action="store_true", help="keep no data log")
    view.add_argument(
        "--meshcat", action="store_true", help="serve the live view in Meshcat and run in real time"
    )
    view.add_argument(
        "--no-meshcat", action="store_true", help="no viewer at all (fastest; implies --no-record)"
    )
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        help="YAML overrides of the scenario, applied in order, e.g. "
        "'{mover: !Dynamic {control: force}}'",
    )
    parser.add_argument(
        "--checkpoint",
        type=NonEmpty,
        default=None,
        help="a folder: resume from the checkpoint there, and save one after "
        "every completed action of the exploring agents",
    )
    parser.add_argument(
        "--graphviz", type=NonEmpty, help="write the diagram's Graphviz (dot) text to this file"
    )
    parser.add_argument(
        "--no-warnings",
        action="store_true",
        help="do not warn of values that look like unit mistakes (a 3.5 m ball, an object 330 m "
        "away, attractor angles that look like radians, world events after the run's end)",
    )
    parser.add_argument(
        "--output",
        type=NonEmpty,
        default="results",
        help="the folder of the recording, data log and summary (named after the scenario, "
        "and for a run with --set or --duration the first 8 hex digits of their hash)",
    )
    return parser


def RunName(scenario: str, changes: list[str]) -> str:
    """The name of a run's outputs: its scenario's, and for a variant (``changes``: its --set
    overrides and --duration, in order) the first 8 hex digits of their SHA-256, so that
    variants never overwrite each other."""
    name = pathlib.Path(scenario).stem
    if not changes:
        return name
    return f"{name}-{hashlib.sha256(chr(10).join(changes).encode()).hexdigest()[:8]}"


def _RunOutputs(known) -> tuple[str | None, str | None, pathlib.Path]:
    """Where ``run`` writes its recording, data log and summary (the summary and the log beside
    the recording, or where it would be), each checked before the run."""
    changes = list(known.set) + ([f"duration: {known.duration}"] if known.duration else [])
    default_record = pathlib.Path(known.output) / (RunName(known.scenario, changes) + ".html")
    record = None
    if not (known.no_record or known.no_meshcat):
        record = known.record or str(default_record)
    summary_file = pathlib.Path(record or default_record).with_suffix(".summary.json")
    data_log = None
    if not known.no_log:
        data_log = known.log or str(
            pathlib.Path(record or default_record).with_suffix(".log.parquet")
        )
    for output in (record, data_log, known.graphviz, summary_file):
        if output and not CanWrite(output):
            _Fail(f"{output}: cannot be written (its folder is missing, read-only or full?)")
    return record, data_log, summary_file


def _ServesUntilCtrlC(known, scenario) -> bool:
    """Whether ``run`` serves a scenario moved by hand (sliders) until Ctrl-C: with --meshcat and
    no --duration. Such a scenario is refused without --meshcat (no one could move it)."""
    if not isinstance(scenario.attractor, SliderAttractor):
        return False
    if not known.meshcat or known.no_meshcat:
        raise ValueError(
            f"{known.scenario}: its attractor is moved by hand in the browser; run it with "
            "--meshcat"
        )
    if known.duration is None and known.record:
        raise ValueError("--record needs --duration here: the live view runs until Ctrl-C")
    return known.duration is None


def _Announce(meshcat) -> None:
    print(f"serving the live view at {meshcat.web_url()} until Ctrl-C", flush=True)


def _Run(args: list[str]) -> None:
    """Runs a scenario and prints its summary."""
    parser = _RunParser()
    known = parser.parse_args(args)

    overrides = list(known.set)
    if known.duration is not None:
        overrides.append(f"{{duration: {known.duration}}}")
    if known.no_log:
        overrides.append("{data_log: {enabled: false}}")
    record, data_log, summary_file = _RunOutputs(known)
    meshcat = None
    if known.meshcat and not known.no_meshcat:
        meshcat = StartMeshcat()
    elif record:  # Only to record: reachable from this machine alone.
        meshcat = RecordingMeshcat()
    # A user's mistakes surface while the scenario is read and built; the run's own errors are
    # bugs, and keep their traceback.
    try:
        scenario = LoadScenario(known.scenario, overrides)
        if not known.no_warnings:
            for doubt in ScenarioDoubts(scenario):
                _PrintError(doubt, "warning")
        serve = _ServesUntilCtrlC(known, scenario)
        if serve:  # (Its data log is still sized by the scenario's duration.)
            record = None
        station = BuildScenario(scenario, meshcat)
    except ValueError as e:  # YamlFileError included
        _Fail(str(e))
    if known.graphviz:
        WriteTextAtomically(known.graphviz, station.diagram.GetGraphvizString())
    try:
        summary = RunStation(
            station,
            math.inf if serve else scenario.duration,
            record=record,
            simulator_config=scenario.simulator_config,
            realtime_rate=1.0 if meshcat is not None and known.meshcat else None,
            progress=True,
            checkpoint=known.checkpoint,
            configuration=ResumableConfiguration(scenario),
            data_log=data_log,
            on_start=(lambda: _Announce(meshcat)) if serve else None,
        )
    except (FolderError, CheckpointError, StartsInPenetrationError) as e:  # Before any step.
        _Fail(str(e))
    if summary.finished_before is not None and summary.finished_before > scenario.duration:
        _Fail(
            f"{known.checkpoint}: the checkpoint is at {summary.finished_before:.2f} s, past "
            f"the duration {scenario.duration:g} s; give a duration of at least that"
        )
    print(summary.Format())
    if summary.finished_before is None:
        WriteJsonAtomically(summary_file, summary.ToJson())
        print(f"summary: {summary_file.resolve()}")


def _Listing(title: str, entries: dict[str, str]) -> str:
    """``entries`` (name: what it is) as help lines under ``title``."""
    width = max(map(len, entries)) + 2
    return f"{title}:\n" + "\n".join(f"  {n:{width}s}{what}" for n, what in entries.items())


def _Dispatch(prog: str, args: list[str], modules: dict[str, tuple[str, str]]) -> None:
    """Runs ``main(rest)`` of the module (``modules``: name -> (module, what it does)) named by
    the first argument, its own --help included; without one, or with --help, lists them."""
    if not args or args[0] in ("-h", "--help"):
        print(f"usage: {prog} {{{','.join(sorted(modules))}}} ...  (each has --help)\n")
        print(_Listing("one of", {n: what for n, (_, what) in sorted(modules.items())}))
        sys.exit(0 if args else 2)
    if args[0] not in modules:
        close = difflib.get_close_matches(args[0], modules, n=1)
        hint = f"; did you mean '{close[0]}'?" if close else ""
        _Fail(f"{prog}: no '{args[0]}' (one of {', '.join(sorted(modules))}){hint}")
    try:
        importlib.import_module(modules[args[0]][0]).main(args[1:])
    except (FolderError, BatteryRefused) as e:  # Raised before anything runs.
        _Fail(str(e))


_BENCHMARKS = {
    "babbling": (
        "bench_babbling",
        "MoBeE 1.0's rewinding reflex against MoBeE 2.0 on motor babbling",
    ),
    "forces": ("bench_forces", "MoBeE's force evaluations per second among boxes (Fig. 2.4)"),
    "objects": ("bench_objects", "what a scenario's number of objects costs to build"),
    "ik": ("bench_ik", "NGIK (xNES, SNES) against CMA-ES and Drake's IK (ch. 3.1-3.2)"),
    "reactive": ("bench_reactive", "MoBeE 2.0 against Drake's differential IK as reactive control"),
    "safety": ("bench_safety", "whether a client can push the robot through an obstacle"),
    "simulation": ("bench_simulation", "real-time factor and safety, kinematic and dynamic robot"),
    "values": ("bench_values", "the reach learner's value iteration, T sparse against dense"),
    "viewer": ("bench_viewer", "Meshcat in a real browser: sizes, stream, slider latency"),
}
_EXPERIMENTS = {
    "adaptive-space": (
        "adaptive_space_command",
        "a state-action space that reshapes itself as the curious agent learns (ch. 9.4.5)",
    ),
    "ch7": ("ch7_command", "the model-learning experiments of ch. 7 (the curious agent)"),
    "ch8": ("ch8_command", "learning to reach, ch. 8: strategies, readings, claims"),
    "ch8-discounting": (
        "ch8_discounting",
        "when ch. 8's greedy reach planner moves, in closed form",
    ),
    "parallel-behaviours": (
        "parallel_behaviours",
        "gaze and palm normal beside the curious planner (ch. 9.4.2)",
    ),
    "saggriac": ("saggriac_command", "SAGG-RIAC goal babbling on the 15-joint arm"),
    "torso-reach": (
        "torso_reach",
        "a torso that brings targets into the learned reach (ch. 9.4.2)",
    ),
    "roadmaps": ("ch4_roadmaps", "adaptive roadmap planning on MoBeE 1.0 (ch. 4.3)"),
    "trm": ("trm_roadmaps", "the task-relevant roadmaps of ch. 3.4"),
}


def _Modules(table: dict[str, tuple[str, str]]) -> dict[str, tuple[str, str]]:
    return {n: (f"mobee_drake.experiments.{m}", what) for n, (m, what) in table.items()}


def _Bench(args: list[str]) -> None:
    """Benchmarks that print their figures."""
    _Dispatch("mobee-drake bench", args, _Modules(_BENCHMARKS))


def _Experiment(args: list[str]) -> None:
    """Batteries of experiments that write data, plots and a report."""
    _Dispatch("mobee-drake experiment", args, _Modules(_EXPERIMENTS))


def _Info(args: list[str]) -> None:
    """Prints the iCub model, its controlled joints, overlay geometry, markers and clauses."""
    parser = CommandParser(prog="mobee-drake info", description=_Info.__doc__)
    parser.add_argument("--model", default=IcubConfig().model, help="an icub-models robot name")
    known = parser.parse_args(args)
    config = IcubConfig(model=known.model)
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    try:
        robot = AddIcub(plant, scene_graph, config)
    except ValueError as e:
        _Fail(str(e))
    plant.Finalize()
    mobee = Mobee(plant, robot, joints=config.controlled_joints)
    print(f"model: {config.model} (available: {', '.join(IcubModelNames())})")
    print(f"bodies: {plant.num_bodies()}, controlled joints: {len(mobee.joints)}")
    lower, upper = mobee.position_limits
    for name, lo, hi, home in zip(
        mobee.joints, np.degrees(lower), np.degrees(upper), np.degrees(mobee.home)
    ):
        print(f"  {name:18s} [{lo:7.1f}, {hi:7.1f}] deg, home {home:6.1f}")
    print(
        "overlay primitives (field margin, m): "
        + ", ".join(f"{robot.geometry_names[g]} ({m:.3f})" for g, m in robot.field_margins.items())
    )
    print("markers: " + ", ".join(mobee.marker_names))
    print("constraint clauses: " + ", ".join(mobee.clauses.names))


def _Scenarios(args: list[str]) -> None:
    """Lists the shipped scenarios, or prints one to copy and change."""
    parser = CommandParser(
        prog="mobee-drake scenarios",
        description="Without a name, lists the shipped scenarios with what each does; with one, "
        "prints that scenario's file, e.g. `mobee-drake scenarios reach_around_ball > mine.yaml`, "
        "then `mobee-drake run mine.yaml`.",
    )
    parser.add_argument("name", nargs="?", help="a shipped scenario's name")
    parser.add_argument(
        "--reference",
        action="store_true",
        help="print the reference of every key a scenario file may hold (markdown)",
    )
    known = parser.parse_args(args)
    if known.reference:
        print(ScenarioReference(), end="")
        return
    if known.name is None:
        print(_Listing("shipped scenarios", {n: _Purpose(n) for n in ScenarioNames()}))
        return
    if known.name not in ScenarioNames():
        _Fail(UnknownScenario(known.name))
    print(ResolveScenarioFile(known.name).read_text(), end="")


def _Purpose(name: str) -> str:
    """The opening clause of a shipped scenario's first comment."""
    lines = ResolveScenarioFile(name).read_text().splitlines()
    comment = " ".join(line.lstrip("# ") for line in itertools.takewhile(
        lambda line: line.startswith("#"), lines))  # fmt: skip
    return re.split(r";|: | \(|\. ", comment)[0].rstrip(".")


COMMANDS = {
    "bench": _Bench,
    "experiment": _Experiment,
    "info": _Info,
    "run": _Run,
    "scenarios": _Scenarios,
}


def main(argv: list[str] | None = None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    parser = CommandParser(
        prog="mobee-drake",
        description="MoBeE 2.0 on Drake for the iCub.\n\n"
        + _Listing(
            "commands",
            {n: (f.__doc__ or "").split("\n")[0].rstrip(".") for n, f in COMMANDS.items()},
        ),
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument(
        "--debug", action="store_true", help="show the traceback of a user's mistake too"
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log details (DEBUG)")
    parser.add_argument("-q", "--quiet", action="store_true", help="log warnings and errors only")
    parser.add_argument("command", choices=sorted(COMMANDS), help="what to do (each has --help)")
    parser.add_argument("args", nargs=argparse.REMAINDER, help=argparse.SUPPRESS)
    if not argv:
        parser.print_help()
        sys.exit(2)
    known = parser.parse_args(argv)
    global _debug
    _debug = known.debug
    level = logging.DEBUG if known.verbose else logging.WARNING if known.quiet else logging.INFO
    logging.basicConfig(level=level, format="%(levelname)s:%(name)s:%(message)s")
    logging.getLogger("drake").setLevel(level)
    try:
        with TerminationInterrupts():  # SIGTERM: one line and exit code 130, as Ctrl-C
            COMMANDS[known.command](known.args)
    except KeyboardInterrupt:
        # The workers are gone with the battery; runs resume from their last checkpoint.
        print(
            "interrupted: run the same command again to go on from the last checkpoints",
            file=sys.stderr,
        )
        sys.exit(130)
    except OSError as e:  # A full disk, a folder gone: the machine's, not the run's, fault.
        _PrintError(f"{e.filename}: {e.strerror}" if e.filename and e.strerror else str(e))
        sys.exit(1)
    except BatteryError as e:  # (--debug: the traceback) One line: how many, the first, resume.
        if _debug:
            raise
        count, *failures = str(e).splitlines()
        more = f" (and {len(failures) - 1} more)" if len(failures) > 1 else ""
        _PrintError(
            f"{count} {failures[0] if failures else ''}{more}; the others' results are "
            "kept: run the same command again to resume"
        )
        sys.exit(1)


if __name__ == "__main__":
    main()
