"""The command line: help with defaults for every command, one-line mistakes with exit code 2,
``--debug`` for their tracebacks, and the logging level."""

import contextlib
import io
import logging
import math
import pathlib
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import unittest
from unittest import mock

from battery_jobs import DefaultSigint

from mobee_drake import cli
from mobee_drake.experiments.battery import BatteryError

COMMANDS = [
    ["run"],
    ["info"],
    ["experiment", "ch7"],
    ["experiment", "ch8"],
    ["experiment", "saggriac"],
    ["experiment", "trm"],
    ["experiment", "roadmaps"],
    ["bench", "forces"],
    ["bench", "simulation"],
    ["bench", "ik"],
    ["bench", "babbling"],
    ["bench", "safety"],
    ["bench", "objects"],
    ["bench", "values"],
    ["bench", "viewer"],
]


def _Call(*args: str) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    code = 0
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            cli.main(list(args))
        except SystemExit as e:
            code = e.code
    return code, out.getvalue(), err.getvalue()


class TestHelp(unittest.TestCase):
    def test_every_option_of_every_command_has_help_and_its_default(self):
        for command in COMMANDS:
            with self.subTest(" ".join(command)):
                code, text, _ = _Call(*command, "--help")
                self.assertEqual(code, 0)
                options = re.findall(r"^  (--[a-z-]+)", text, flags=re.MULTILINE)
                self.assertTrue(options)
                # An option's default is said where it is worth reading: never "None", a flag
                # that is off or an empty list; and the help is the user's, not the code's.
                for noise in ("(default: None)", "(default: False)", "(default: [])"):
                    self.assertNotIn(noise, text)
                for code_only in (":mod:", ":class:", ":func:", "``", "(issue "):
                    self.assertNotIn(code_only, text)
                self.assertNotIn("args", re.findall(r"^  (\w+)", text, flags=re.MULTILINE))

    def test_required_options_are_listed_as_required(self):
        for command, option in ((["experiment", "ch7"], "--experiment"),
                                (["experiment", "ch8-discounting"], "--model")):  # fmt: skip
            _, text, _ = _Call(*command, "--help")
            required = text.split("required options:")[1]
            self.assertIn(f"  {option}", required)
            self.assertNotIn(f"  {option}", text.split("options:")[1].split("required")[0])

    def test_bare_commands_list_what_they_offer(self):
        code, text, _ = _Call()
        self.assertEqual(code, 2)
        for command in ("bench", "experiment", "info", "run"):
            self.assertRegex(text, rf"\n  {command} +[A-Z]")  # each with what it does
        for group, member in (("bench", "viewer"), ("experiment", "ch8")):
            code, text, _ = _Call(group)
            self.assertEqual(code, 2)
            self.assertRegex(text, rf"\n  {member} +\S")
            code, _, _ = _Call(group, "--help")
            self.assertEqual(code, 0)

    def test_version(self):
        code, text, _ = _Call("--version")
        self.assertEqual(code, 0)
        self.assertRegex(text, r"^mobee-drake \d+\.\d+\.\d+")


class TestMistakes(unittest.TestCase):
    def test_a_mistake_is_one_line_and_exit_code_2(self):
        # A file and a folder of the user's (never the repository's: a test may run anywhere).
        scratch = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, scratch)
        notes, folder = scratch / "notes.md", scratch / "folder"
        notes.write_text("mine")
        folder.mkdir()
        for args, message in (
            (["info", "--model", "iCubMars"], "unknown iCub model 'iCubMars'"),
            (["run", "reach_around_ball", "--duration", "-5"], "--duration: must be a finite"),
            (["run", "reach_around_ball", "--set", "{duration: ["], "invalid YAML"),
            (
                [
                    "run",
                    "reach_around_ball",
                    "--no-meshcat",
                    "--set",
                    "{visualization: {trail_marker: nose}}",
                ],
                "",
            ),  # fmt: skip
            (
                [
                    "run",
                    "reach_around_ball",
                    "--no-meshcat",
                    "--no-log",
                    "--set",
                    "{objects: [{name: ball, shape: !Sphere {radius: 0.04}, "
                    "position: [-0.31, 0.14, 0.0]}]}",
                ],
                "the robot starts in penetration: the robot: 'r_hand'",
            ),  # fmt: skip
            (["bench", "safety", "--report-only"], "--report-only needs --output"),
            # Issue 31, item 11: nonsense that ran silently, or ended in a Python type error.
            (["run", "reach_around_ball", "--set", ""], "overrides '': not a YAML mapping"),
            (["run", "reach_around_ball", "--record", ""], "--record: must be a non-empty path"),
            (["run", "reach_around_ball", "--checkpoint", ""], "--checkpoint: must be a non-empty"),
            (["bench", "forces", "--amplitude", "5"], "--amplitude: must be a number in (0, 1]"),
            (["bench", "values", "--sizes", "81x0"], "'81x0' is not STATESxTRANSITIONS"),
            (["bench", "values", "--sizes", "81"], "'81' is not STATESxTRANSITIONS"),
            (["experiment", "ch8", "--stages", "2", "2"], "--stages must differ from each other"),
            # Issue 31, item 8: bench simulation's values ended in tracebacks.
            (["bench", "simulation", "--seconds", "0.5"], "--seconds: the timing leaves out"),
            (["bench", "simulation", "--scenario", "nonexistent"], "nonexistent: no such file"),
            (["bench", "simulation", "--controls", "bogus"], "--controls: invalid choice"),
            # Issue 31, item 8: ch8-discounting's flags ended in tracebacks.
            (["experiment", "ch8-discounting", "--model", "m", "--gamma", "1.5"], "--gamma: must"),
            (["experiment", "ch8-discounting", "--model", "m", "--units", "0"], "--units: must"),
            (
                ["experiment", "ch8-discounting", "--model", "m", "--misses", "0.3", "0.1"],
                "--misses: the first must be the smaller",
            ),
            (
                ["experiment", "ch8-discounting", "--model", "m", "--runs", "/no/such.json"],
                "--runs: /no/such.json is not a file",
            ),
            (["bench", "forces", "--plot", f"{notes}/x.png"], f"--plot {notes}/x.png: cannot be"),
            (
                ["experiment", "ch8", "--report-only", "--output", "/missing/ch8"],
                "--report-only: /missing/ch8 is not a folder",
            ),
            (
                [
                    "experiment",
                    "saggriac",
                    "--experiments",
                    "1",
                    "--budget-exp1",
                    "100",
                    "--checkpoints",
                    "500",
                ],
                "--checkpoints 500: more evaluations than experiment 1's budget of 100",
            ),  # fmt: skip
            (["experiment", "ch8", "--reach-force", "1e300"], "--reach-force: must be a number in"),
            (["experiment", "ch8", "--distance-unit", "1e-300"], "--distance-unit: must be a num"),
            (["run", str(folder)], f"{folder}: a folder, not a file"),
            (["experiment", "ch8", "--output", str(notes)], f"{notes}: is a file, not a folder"),
            (
                ["experiment", "ch7", "--experiment", "7.1", "--output", str(notes)],
                f"{notes}: is a file, not a folder",
            ),
            # Issue 31, item 8: a bad --ray address hung for minutes.
            (
                ["experiment", "ch8", "--ray", "127.0.0.1:1"],
                "no Ray cluster answers at 127.0.0.1:1",
            ),
            (["experiment", "ch8", "--ray", "bogus"], "--ray: must be auto or [ray://]host:port"),
            (
                [
                    "run",
                    "reach_around_ball",
                    "--no-meshcat",
                    "--no-log",
                    "--set",
                    "{robot: {controlled_joints: [nope]}}",
                ],
                "robot (the iCub model iCubGazeboV2_5): unknown joint 'nope'",
            ),  # fmt: skip
        ):
            with self.subTest(args):
                code, _, err = _Call(*args)
                self.assertEqual(code, 2)
                self.assertEqual(len(err.strip().splitlines()), 1, err)
                self.assertIn(message, err)
                self.assertNotIn("Traceback", err)

    def test_a_doc_without_its_block_is_refused_before_anything_runs(self):
        # Every command that writes a block of a doc reads the doc first: a mistyped --doc would
        # otherwise end a battery of hours in an error at its last line.
        scratch = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, scratch)
        notes = scratch / "notes.md"
        notes.write_text("mine")
        for command, block in (
            (["experiment", "adaptive-space"], "adaptive-space"),
            (["experiment", "adaptive-space", "--part", "reaching"], "adaptive-space-reaching"),
            (["experiment", "ch7", "--experiment", "7.1"], "ch7-7.1"),
            (["experiment", "ch8"], "ch8-claims"),
            (["experiment", "parallel-behaviours"], "parallel-behaviours"),
            (["experiment", "roadmaps", "--scratch-table"], "roadmap-from-scratch"),
            (["experiment", "saggriac"], "saggriac-interest"),
            (["experiment", "trm"], "trm-examples"),
            (["bench", "forces"], "forces"),
            (["bench", "ik"], "ngik-benchmark"),
            (["bench", "objects"], "object count"),
            (["bench", "reactive"], "reactive"),
            (["bench", "safety"], "safety scenes"),
            (["bench", "values"], "value iteration"),
            (["bench", "viewer"], "viewer"),
        ):
            with self.subTest(command):
                code, _, err = _Call(*command, "--doc", str(notes))
                self.assertEqual(code, 2)
                self.assertEqual(len(err.strip().splitlines()), 1, err)
                self.assertIn(f"--doc: {notes}: no generated block '{block}'", err)
        code, _, err = _Call("experiment", "ch8", "--doc", str(scratch / "missing.md"))
        self.assertEqual(code, 2)
        self.assertIn(f"--doc: [Errno 2] No such file or directory: '{scratch}/missing.md'", err)

    def test_a_failed_battery_is_one_line_and_exit_code_1(self):
        """Issue 31, item 7: a killed worker or a full disk ended in a multi-screen traceback."""

        def Failing(args):
            raise BatteryError("2 of 5 jobs failed:\nrandom_seed0: BrokenProcessPool: a worker "
                               "died\ngreedy_seed0: OSError: [Errno 28] no space")  # fmt: skip

        with mock.patch.dict(cli.COMMANDS, {"experiment": Failing}):
            code, _, err = _Call("experiment", "ch8")
        self.assertEqual(code, 1)
        self.assertEqual(
            err,
            "error: 2 of 5 jobs failed: random_seed0: BrokenProcessPool: a worker died (and 1 "
            "more); the others' results are kept: run the same command again to resume\n",
        )

    def test_a_machine_fault_names_the_file(self):
        """Issue 31, item 11: ``[Errno 28]`` without a path."""

        def FullDisk(args):
            raise OSError(28, "No space left on device", "/results/runs/a/result.json")

        with mock.patch.dict(cli.COMMANDS, {"experiment": FullDisk}):
            code, _, err = _Call("experiment", "ch8")
        self.assertEqual((code, err), (1, "error: /results/runs/a/result.json: No space left on "
                                          "device\n"))  # fmt: skip

    def test_a_control_character_is_named_not_a_traceback(self):
        """A review of issue 31: PyYAML's ReaderError is no MarkedYAMLError."""
        with tempfile.TemporaryDirectory() as folder:
            scenario = pathlib.Path(folder) / "bell.yaml"
            scenario.write_text("duration: 1\x07\n")
            for args in ([str(scenario)], ["reach_around_ball", "--set", "{duration: 1\x07}"]):
                with self.subTest(args):
                    code, _, err = _Call("run", *args)
                    self.assertEqual(code, 2)
                    self.assertIn("invalid YAML: character '\\x07' is not allowed", err)
                    self.assertEqual(len(err.splitlines()), 1)

    def test_a_huge_value_is_cut_in_the_error_line(self):
        """Issue 31, item 11: a 10 MB value in a file made a 10 MB error line."""
        with tempfile.TemporaryDirectory() as folder:
            scenario = pathlib.Path(folder) / "huge.yaml"
            scenario.write_text("duration: " + "x" * 2_000_000 + "z\n")
            code, _, err = _Call("run", str(scenario))
        self.assertEqual(code, 2)
        self.assertEqual(len(err.splitlines()), 1)
        self.assertLess(len(err), cli.MAX_ERROR_LINE + 100)
        self.assertIn("huge.yaml:1: could not convert string to float: 'xxx", err)
        self.assertRegex(err, r"\[\.\.\. 1,99\d,\d{3} characters \.\.\.\] x+z'")

    def test_debug_shows_the_traceback(self):
        with self.assertRaisesRegex(ValueError, "unknown iCub model"):
            cli.main(["--debug", "info", "--model", "iCubMars"])

    def test_quiet_and_verbose_set_the_logging_level(self):
        for flag, level in (("-q", logging.WARNING), ("-v", logging.DEBUG)):
            with self.subTest(flag):
                _Call(flag, "info", "--model", "iCubMars")
                self.assertEqual(logging.getLogger("drake").level, level)
        logging.getLogger("drake").setLevel(logging.INFO)


class TestGuidance(unittest.TestCase):
    def test_a_misspelt_name_is_met_with_the_closest(self):
        for args, message in (
            (["bench", "viwer"], "no 'viwer' (one of babbling, "),
            (["run", "reach_arund_ball"], "nor a shipped scenario (shipped: explore_hypercube"),
        ):
            with self.subTest(args=args):
                code, _, err = _Call(*args)
                self.assertEqual((code, err.count("\n")), (2, 1))
                self.assertIn(message, err)
                self.assertIn("did you mean", err)

    def test_a_flag_and_its_opposite_are_refused_together(self):
        for pair in (("--meshcat", "--no-meshcat"), ("--record", "x.html", "--no-record")):
            with self.subTest(pair=pair):
                code, _, err = _Call("run", "reach_around_ball", *pair)
                self.assertEqual((code, err.count("\n")), (2, 1))
                self.assertIn("not allowed with argument", err)


class TestDoubts(unittest.TestCase):
    ODD = (
        "{objects: [{name: ball, shape: !Sphere {radius: 3.5}, position: [330, 0, 0]}], "
        "world_events: [{time: 20, object: ball, role: ghost}], "
        "attractor: !FixedAttractor {joints_deg: {r_shoulder_pitch: -0.5, r_shoulder_roll: 0.3}}}"
    )

    def Run(self, *extra: str) -> tuple[int, str]:
        folder = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, folder)
        with contextlib.chdir(folder):
            code, _, err = _Call(
                "run", "reach_around_ball", "--duration", "0.1", "--no-record", "--no-log",
                "--set", self.ODD, *extra,
            )  # fmt: skip
        return code, err

    def test_values_that_look_like_unit_mistakes_are_warned_of_and_run(self):
        code, err = self.Run()
        self.assertEqual(code, 0)
        warnings = [line for line in err.splitlines() if line.startswith("warning: ")]
        for expected in (
            "radius 3.5 m; sizes are in metres (3.5 cm would be 0.035)",
            "330 m from the world's origin",
            "'ball' at 20 s, at or after the run's end (0.1 s): it never happens",
            "r_shoulder_pitch: -0.5 looks like radians; the angles are in degrees (-0.5 rad "
            "would be -28.6)",
            "r_shoulder_roll: 0.3 looks like radians",
        ):
            self.assertEqual(sum(expected in w for w in warnings), 1, expected)
        self.assertEqual(len(warnings), 5)
        code, err = self.Run("--no-warnings")
        self.assertEqual((code, err.count("warning")), (0, 0))


class TestScenarios(unittest.TestCase):
    def test_the_shipped_scenarios_are_listed_and_printed_to_copy(self):
        code, text, _ = _Call("scenarios")
        self.assertEqual(code, 0)
        self.assertIn("  interactive", text)
        self.assertIn("Move the attractor by hand", text)
        folder = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, folder)
        code, text, _ = _Call("scenarios", "reach_around_ball")
        (folder / "mine.yaml").write_text(text)
        with contextlib.chdir(folder):
            code, out, _ = _Call("run", "mine.yaml", "--duration", "0.2", "--no-record")
        self.assertEqual(code, 0)
        self.assertIn("simulated 0.20 s", out)
        code, _, err = _Call("scenarios", "reach_arund")
        self.assertEqual((code, err.count("\n")), (2, 1))
        self.assertIn("did you mean 'reach_around_ball'", err)

    def test_a_mistyped_key_gets_the_closest_key(self):
        """In a file (with its line) and in an override, at the top and nested; a name close
        to nothing gets no guess."""
        folder = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, folder)
        (folder / "typo.yaml").write_text(
            "objects:\n  - name: b\n    shap: !Sphere {radius: 0.1}\n"
        )
        for args, message in [
            ([str(folder / "typo.yaml")], "typo.yaml:3: The fields ['shap'] were unknown to the "
             "schema; 'shap': did you mean 'shape'?"),
            (["reach_around_ball", "--set", "{duraton: 5}"], "'duraton': did you mean 'duration'?"),
            (["reach_around_ball", "--set", "{visualization: {trail_markr: x}}"],
             "did you mean 'trail_marker'?"),
            (["reach_around_ball", "--set", "{attractor: {behaviours: []}}"],
             "'behaviours' belongs to another type: is its !Tag missing?"),
        ]:  # fmt: skip
            with self.subTest(args):
                code, _, err = _Call("run", *args, "--no-record")
                self.assertEqual((code, err.count("\n")), (2, 1))
                self.assertIn(message, err)
        code, _, err = _Call("run", "reach_around_ball", "--set", "{zzzz: 1}", "--no-record")
        self.assertNotIn("did you mean", err)


class TestScenarioReference(unittest.TestCase):
    def test_the_reference_is_the_config_and_up_to_date(self):
        code, text, _ = _Call("scenarios", "--reference")
        self.assertEqual(code, 0)
        doc = pathlib.Path(__file__).parents[1] / "docs" / "scenario_reference.md"
        self.assertEqual(
            doc.read_text(), text, "run: mobee-drake scenarios --reference > " + str(doc)
        )
        # Each key with its type, default and the comment above it in the source.
        self.assertIn("| `duration` | float | `10.0` | Seconds to simulate. |", text)
        self.assertRegex(text, r"\| `mover` \| one of `!Kinematic`, `!Dynamic`, `!Reflex` \|")
        # Every key the shipped scenarios use is in it.
        for name in ("reach_around_ball", "interactive", "three_agents_table", "katana"):
            _, scenario, _ = _Call("scenarios", name)
            for key in re.findall(r"^\s*(\w+):", scenario, flags=re.MULTILINE):
                with self.subTest(scenario=name, key=key):
                    self.assertIn(f"| `{key}` |", text)


class TestProgressInLogs(unittest.TestCase):
    def test_a_log_file_gets_plain_lines_not_bars(self):
        done = subprocess.run(
            [sys.executable, "-m", "mobee_drake.cli", "-q", "run", "reach_around_ball",
             "--duration", "2", "--no-meshcat"],
            capture_output=True,
            text=True,
            check=True,
        )  # fmt: skip
        self.assertNotIn("\r", done.stderr)
        self.assertNotIn("\x1b", done.stderr)
        self.assertIn("simulated: 2/2 s", done.stderr)


class TestHeadlessRun(unittest.TestCase):
    def test_a_recorded_run_says_nothing_of_meshcat_and_leaves_its_three_files(self):
        folder = pathlib.Path(tempfile.mkdtemp())
        done = subprocess.run(
            [sys.executable, "-m", "mobee_drake.cli", "run", "reach_around_ball",
             "--duration", "0.5"],
            capture_output=True,
            text=True,
            check=True,
            cwd=folder,
        )  # fmt: skip
        for stream in (done.stdout, done.stderr):
            self.assertNotIn("Meshcat", stream)
            self.assertNotIn("http", stream)
        name = cli.RunName("reach_around_ball", ["duration: 0.5"])
        for file in (f"{name}.html", f"{name}.log.parquet"):
            self.assertIn(file, done.stdout)
            self.assertGreater((folder / "results" / file).stat().st_size, 0)
        self.assertTrue((folder / "results" / f"{name}.summary.json").exists())

    def test_variants_never_overwrite_each_other(self):
        folder = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, folder)
        variants = (
            [],
            ["--duration", "0.2"],
            ["--duration", "0.2", "--set", "{objects: []}"],
            ["--set", "{objects: []}", "--duration", "0.2"],  # (the same changes)
        )
        with contextlib.chdir(folder):
            for variant in variants:
                code, _, _ = _Call("run", "reach_around_ball", "--no-record", *variant)
                self.assertEqual(code, 0)
            _Call("run", "reach_around_ball", "--no-record", "--output", "elsewhere")
        summaries = sorted(p.name for p in (folder / "results").glob("*.summary.json"))
        self.assertEqual(len(summaries), 3, summaries)
        self.assertIn("reach_around_ball.summary.json", summaries)
        self.assertTrue((folder / "elsewhere" / "reach_around_ball.summary.json").exists())


class TestLiveRun(unittest.TestCase):
    def test_a_scenario_moved_by_hand_needs_the_live_view(self):
        code, _, err = _Call("run", "interactive", "--no-log")
        self.assertEqual(code, 2)
        self.assertIn("moved by hand in the browser; run it with --meshcat", err)
        code, _, err = _Call("run", "interactive", "--meshcat", "--record", "x.html")
        self.assertEqual((code, err.count("\n")), (2, 1))
        self.assertIn("--record needs --duration", err)

    def test_a_run_until_ctrl_c_is_not_recorded(self):
        from mobee_drake.scenario import BuildScenario, LoadScenario
        from mobee_drake.station.runner import RunStation
        from mobee_drake.station.viewer import RecordingMeshcat

        station = BuildScenario(LoadScenario("reach_around_ball"), RecordingMeshcat())
        with self.assertRaisesRegex(ValueError, "cannot be recorded; give it a duration"):
            RunStation(station, math.inf, record="x.html")

    def test_the_live_view_is_served_until_ctrl_c(self):
        folder = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, folder)
        live = subprocess.Popen(
            [sys.executable, "-m", "mobee_drake.cli", "run", "interactive", "--meshcat"],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, cwd=folder,
            preexec_fn=DefaultSigint,  # (Ctrl-C as in a terminal, also in a background job.)
        )  # fmt: skip
        self.addCleanup(live.kill)
        lines = []
        while not any("until Ctrl-C" in line for line in lines):
            lines.append(live.stdout.readline())
            self.assertNotEqual(lines[-1], "", "the run ended before serving")
        # The address comes first; the run goes on until it is interrupted.
        self.assertRegex(lines[0] + lines[-1], r"http://localhost:\d+")
        self.assertIsNone(live.poll())
        live.send_signal(signal.SIGINT)
        out, _ = live.communicate(timeout=60)
        self.assertEqual(live.returncode, 0)
        self.assertRegex(out, r"simulated \d+\.\d+ s")
        self.assertNotIn("Traceback", out)
        self.assertFalse((folder / "results" / "interactive.html").exists())  # no recording


if __name__ == "__main__":
    unittest.main()
