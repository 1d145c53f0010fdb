"""Nothing learned is lost or silently wrong: checkpoint generations that survive a kill at any
step of their write, folders that are ours before we write into them and have one writer at a
time, and checkpoints and battery runs tied to the configuration they were made with."""

import contextlib
import errno
import io
import json
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
import unittest
import zipfile

from battery_jobs import Count, DefaultSigint, StopWalk
import numpy as np

from mobee_drake import cli
from mobee_drake.array_files import WriteArrays
from mobee_drake.atomic_files import (
    CurrentGeneration,
    WriteFileAtomically,
    WriteGeneration,
    WriteJsonAtomically,
)
from mobee_drake.experiments import ch7_command, saggriac_command
from mobee_drake.experiments.battery import InProcess, Job, RunBattery
from mobee_drake.experiments.ch7_model_learning import Stop
from mobee_drake.experiments.exploration import ExplorationScenario, Explore
from mobee_drake.owned_folders import ClaimFolder, FolderError, OwnedFolder
from mobee_drake.planning.supervisor import ExploringAgent
from mobee_drake.robots.icub import RIGHT_SHOULDER_ELBOW_JOINTS
from mobee_drake.scenario import LoadScenario, RunScenario
from mobee_drake.station.checkpoint import SavedWallSeconds

# The steps of a generation's write, as WriteGeneration marks them, and a kill inside the
# caller's write (after its first file).
STEPS = ("inside the write", "staged", "renamed", "pruned one")


def _WriteTwoFiles(text: str):
    def Write(staging: pathlib.Path) -> None:
        (staging / "a.txt").write_text(text)
        (staging / "b.txt").write_text(text)

    return Write


class TemporaryFolder(unittest.TestCase):
    def setUp(self):
        self.folder = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, self.folder, ignore_errors=True)


class TestGenerations(TemporaryFolder):
    def _KilledWrite(self, folder: pathlib.Path, step: str) -> int:
        """Writes generation "new" over "old" in a process killed (os._exit) at ``step``."""
        script = textwrap.dedent(
            f"""
            import os, pathlib
            from mobee_drake import atomic_files

            step = {step!r}
            atomic_files._Step = lambda name: os._exit(9) if name == step else None

            def Write(staging):
                (staging / "a.txt").write_text("new")
                if step == "inside the write":
                    os._exit(9)
                (staging / "b.txt").write_text("new")

            atomic_files.WriteGeneration(pathlib.Path({str(folder)!r}), Write)
            """
        )
        return subprocess.run([sys.executable, "-c", script]).returncode

    def test_a_kill_at_every_step_leaves_a_complete_generation(self):
        for step in STEPS:
            with self.subTest(step):
                folder = self.folder / step.replace(" ", "_")
                WriteGeneration(folder, _WriteTwoFiles("old"))
                WriteGeneration(folder, _WriteTwoFiles("old"))  # two old generations
                self.assertEqual(self._KilledWrite(folder, step), 9)
                current = CurrentGeneration(folder)
                texts = {(current / n).read_text() for n in ("a.txt", "b.txt")}
                # Before the rename the old checkpoint is the newest; from it on, the new one.
                expected = "new" if step in ("renamed", "pruned one") else "old"
                self.assertEqual(texts, {expected})
                # The next write goes on from there and clears what the kill left.
                WriteGeneration(folder, _WriteTwoFiles("next"))
                self.assertEqual(
                    [p.name for p in folder.iterdir()], [CurrentGeneration(folder).name]
                )

    def test_an_empty_folder_holds_no_generation(self):
        self.assertIsNone(CurrentGeneration(self.folder / "none"))
        self.assertIsNone(CurrentGeneration(self.folder))


class TestArrayFiles(TemporaryFolder):
    def test_arrays_are_deflated_and_read_back_as_written(self):
        counts = np.zeros((300, 80))
        counts[::7, ::3] = 5.0
        arrays = dict(counts=counts, tries=np.arange(300), time=3.5, names=np.array(["a", "b"]))
        WriteArrays(self.folder / "model.npz", **arrays)
        with zipfile.ZipFile(self.folder / "model.npz") as saved:
            members = {m.filename: m for m in saved.infolist()}
        self.assertEqual(set(members), {f"{name}.npy" for name in arrays})
        self.assertTrue(all(m.compress_type == zipfile.ZIP_DEFLATED for m in members.values()))
        self.assertLess(members["counts.npy"].compress_size, counts.nbytes / 20)
        with np.load(self.folder / "model.npz") as loaded:
            for name, value in arrays.items():
                np.testing.assert_array_equal(loaded[name], value)
                self.assertEqual(loaded[name].dtype, np.asarray(value).dtype)
        with self.assertRaises(ValueError):
            WriteArrays(self.folder / "objects.npz", mixed=np.array([1, "a", None], dtype=object))


class TestAtomicFiles(TemporaryFolder):
    def test_what_a_killed_write_left_goes_with_the_next_write(self):
        """Issue 31, item 11: a killed worker left ``.progress.json.*.tmp`` files for good."""
        (self.folder / ".progress.json.k1ll3d.tmp").write_text("{")
        (self.folder / ".other.json.k1ll3d.tmp").write_text("{")  # another file's: kept
        WriteJsonAtomically(self.folder / "progress.json", {"done": 3})
        self.assertEqual(
            sorted(p.name for p in self.folder.iterdir()),
            [".other.json.k1ll3d.tmp", "progress.json"],
        )

    def test_a_failed_write_names_the_file_and_leaves_nothing(self):
        """Issue 31, item 11: a full disk's ``[Errno 28]`` named no file."""

        def FullDisk(staging):
            raise OSError(errno.ENOSPC, "No space left on device")

        target, checkpoint = self.folder / "result.json", self.folder / "checkpoint"
        for write, named in ((WriteFileAtomically, target), (WriteGeneration, checkpoint)):
            with self.subTest(write.__name__), self.assertRaises(OSError) as failed:
                write(named, FullDisk)
            self.assertEqual(failed.exception.errno, errno.ENOSPC)
            self.assertEqual(failed.exception.filename, str(named))
        # Nothing staged is left: no file, and a checkpoint folder without a generation.
        self.assertEqual([p.name for p in self.folder.iterdir()], ["checkpoint"])
        self.assertEqual(list(checkpoint.iterdir()), [])
        with self.assertRaisesRegex(ValueError, "not a write of the system's"):
            WriteFileAtomically(target, lambda staging: (_ for _ in ()).throw(
                ValueError("not a write of the system's")))  # fmt: skip


class TestOwnedFolders(TemporaryFolder):
    def test_a_users_folder_or_file_is_refused_and_left_alone(self):
        thesis = self.folder / "thesis.tex"
        thesis.write_text("chapter 1")
        with self.assertRaisesRegex(
            FolderError, "not empty and not a mobee-drake checkpoint .*thesis.tex"
        ):
            ClaimFolder(self.folder, "checkpoint")
        with self.assertRaisesRegex(FolderError, "thesis.tex: is a file"):
            ClaimFolder(thesis, "checkpoint")
        self.assertEqual(thesis.read_text(), "chapter 1")
        self.assertEqual([p.name for p in self.folder.iterdir()], ["thesis.tex"])

    def test_new_empty_and_own_folders_are_taken_other_kinds_refused(self):
        ClaimFolder(self.folder / "new", "checkpoint")
        (self.folder / "empty").mkdir()
        ClaimFolder(self.folder / "empty", "checkpoint")
        ClaimFolder(self.folder / "empty", "checkpoint")  # ours now
        with self.assertRaisesRegex(FolderError, "holds a checkpoint, not a battery"):
            ClaimFolder(self.folder / "empty", "battery")

    def test_a_claim_a_kill_interrupted_is_no_obstacle_and_a_damaged_marker_says_its_fix(self):
        """Issue 31, item 4: the marker is written through a staging file, which a kill may
        leave behind (the claim then simply happens again); a marker that is not ours (empty,
        damaged) is refused with the way out."""
        folder = self.folder / "run"
        folder.mkdir()
        (folder / ".mobee-drake.abc123.tmp").write_text("")  # a claim killed mid-write
        ClaimFolder(folder, "checkpoint")
        self.assertEqual(json.loads((folder / ".mobee-drake").read_text()), {"kind": "checkpoint"})
        (folder / ".mobee-drake").write_text("")
        with self.assertRaisesRegex(
            FolderError, r"not a marker that mobee-drake wrote \(empty or damaged\); .*delete"
        ):
            ClaimFolder(folder, "checkpoint")

    def test_one_writer_at_a_time(self):
        with OwnedFolder(self.folder / "run", "checkpoint"):
            with self.assertRaisesRegex(FolderError, "in use by another run"):
                with OwnedFolder(self.folder / "run", "checkpoint"):
                    pass
        with OwnedFolder(self.folder / "run", "checkpoint"):  # released
            pass

    def test_a_killed_writer_releases_its_folder(self):
        holder = subprocess.Popen(
            [
                sys.executable,
                "-c",
                "import sys, time; from mobee_drake.owned_folders import OwnedFolder\n"
                f"with OwnedFolder({str(self.folder / 'run')!r}, 'checkpoint'):\n"
                "    print('held', flush=True); time.sleep(60)",
            ],
            stdout=subprocess.PIPE,
            text=True,
        )
        self.addCleanup(holder.kill)
        self.assertEqual(holder.stdout.readline().strip(), "held")
        with self.assertRaisesRegex(FolderError, "in use"):
            with OwnedFolder(self.folder / "run", "checkpoint"):
                pass
        holder.kill()
        holder.wait()
        with OwnedFolder(self.folder / "run", "checkpoint"):
            pass


class TestBatteryArguments(TemporaryFolder):
    def test_a_result_is_not_reused_under_other_arguments(self):
        calls = self.folder / "calls"
        jobs = [Job("count", Count, dict(x=2, calls=str(calls)))]
        RunBattery(jobs, self.folder / "out", backend=None, progress=False)
        other = [Job("count", Count, dict(x=3, calls=str(calls)))]
        with self.assertRaisesRegex(ValueError, r"other arguments \(count: x: 2 -> 3\)"):
            RunBattery(other, self.folder / "out", progress=False)
        self.assertEqual(calls.read_text().split(), ["count"])  # nothing ran again

    def test_a_second_battery_on_the_same_folder_is_refused(self):
        jobs = [Job("count", Count, dict(x=2, calls=str(self.folder / "calls")))]
        with OwnedFolder(self.folder / "out", "battery"):
            with self.assertRaisesRegex(FolderError, "in use by another run"):
                RunBattery(jobs, self.folder / "out", progress=False)

    def test_a_users_folder_is_refused(self):
        (self.folder / "notes.txt").write_text("mine")
        jobs = [Job("count", Count, dict(x=2, calls=str(self.folder / "calls")))]
        with self.assertRaisesRegex(FolderError, "not a mobee-drake battery"):
            RunBattery(jobs, self.folder, progress=False)


class TestCommandsClaimTheirFolders(TemporaryFolder):
    def test_trm_never_writes_into_a_users_folder(self):
        """Issue 31, item 1: ``experiment trm --output`` replaced a user's report.md."""
        report = self.folder / "report.md"
        report.write_text("my report")
        err = io.StringIO()
        with contextlib.redirect_stderr(err), self.assertRaises(SystemExit) as exit_:
            cli.main(["experiment", "trm", "--output", str(self.folder), "--max-vertices", "5"])
        self.assertEqual(exit_.exception.code, 2)
        self.assertRegex(err.getvalue(), r"^error: .*not empty and not a mobee-drake trm roadmaps")
        self.assertEqual(report.read_text(), "my report")
        self.assertEqual(sorted(p.name for p in self.folder.iterdir()), ["report.md"])

    def test_saggriac_analyses_only_its_own_battery(self):
        """Issue 31, item 1: ``saggriac --analyse-only`` replaced a user's report.md, and would
        have replaced another battery's (a ch. 8 battery's folder carries the same marker)."""
        report = self.folder / "report.md"
        report.write_text("my report")
        other = self.folder / "ch8"
        ClaimFolder(other, "battery")
        (other / "report.md").write_text("the ch. 8 report")
        for output, message in ((self.folder, "not empty and not a mobee-drake battery"),
                                (other, "holds no SAGG-RIAC run of these arguments")):  # fmt: skip
            with self.subTest(output.name):
                err = io.StringIO()
                with contextlib.redirect_stderr(err), self.assertRaises(SystemExit) as exit_:
                    cli.main(["experiment", "saggriac", "--analyse-only", "--output", str(output)])
                self.assertEqual(exit_.exception.code, 2)
                self.assertIn(message, err.getvalue())
                self.assertEqual(len(err.getvalue().strip().splitlines()), 1)
        self.assertEqual(report.read_text(), "my report")
        self.assertEqual((other / "report.md").read_text(), "the ch. 8 report")


class TestExplorationCheckpoints(TemporaryFolder):
    """An exploration (the ch. 8 MDP's training, ch. 7.4.1's) interrupted after a checkpoint
    resumes to the model an uninterrupted one learns, and counts the wall time before."""

    def _Explore(
        self, folder: pathlib.Path, interrupt_at: int | None = None, every: int = 1, seen=None
    ):
        """(the saved model's arrays, the run's wall time); a checkpoint every ``every``
        actions, each chunk's actions done and newest checkpoint appended to ``seen``."""
        agent = ExploringAgent(name="arm", joints=list(RIGHT_SHOULDER_ELBOW_JOINTS))

        def Progress(done: int) -> None:  # Told after the chunk's checkpoint.
            if seen is not None:
                seen.append((done, CurrentGeneration(folder)))
            if interrupt_at is not None and done >= interrupt_at:
                raise KeyboardInterrupt

        run = Explore(
            ExplorationScenario([agent], random_seed=4),
            stop=Stop(actions=12),
            checkpoint=folder,
            progress=Progress,
            checkpoint_every=every,
        )
        return dict(np.load(CurrentGeneration(folder) / "arm.npz")), run.wall_seconds

    def test_a_checkpoint_every_so_many_actions_and_the_last(self):
        """Every 5 actions (a checkpoint costs time), and the final model saved at the end."""
        whole, _ = self._Explore(self.folder / "whole")
        seen = []
        sparse, _ = self._Explore(self.folder / "sparse", every=5, seen=seen)
        np.testing.assert_array_equal(sparse["counts"], whole["counts"])
        self.assertEqual(len(sparse["settled"]), 12)  # (the last one: all 12 actions)
        saved_at, last = 0, None
        for done, generation in seen:
            if generation != last:  # (a checkpoint was written after this chunk)
                self.assertGreaterEqual(done, saved_at + 5)
                saved_at, last = done, generation
            else:
                self.assertLess(done, saved_at + 5)
        self.assertEqual(len({g for _, g in seen if g is not None}), 2)  # (at 5-6 and 10-11)
        # Killed between checkpoints (at 8, the last at 5 or 6): it resumes from the last and
        # ends where the whole run ends.
        with self.assertRaises(KeyboardInterrupt):
            self._Explore(self.folder / "killed", interrupt_at=8, every=5)
        saved = dict(np.load(CurrentGeneration(self.folder / "killed") / "arm.npz"))
        self.assertLess(len(saved["settled"]), 8)
        resumed, _ = self._Explore(self.folder / "killed", every=5)
        for key in ("counts", "rewards", "tries", "settled"):
            np.testing.assert_array_equal(resumed[key], whole[key], key)

    def test_an_interrupted_exploration_resumes_exactly(self):
        whole, _ = self._Explore(self.folder / "whole")
        with self.assertRaises(KeyboardInterrupt):
            self._Explore(self.folder / "interrupted", interrupt_at=4)
        saved = dict(np.load(CurrentGeneration(self.folder / "interrupted") / "arm.npz"))
        self.assertLess(saved["tries"].sum(), whole["tries"].sum())
        before = SavedWallSeconds(self.folder / "interrupted")
        self.assertGreater(before, 0.0)
        resumed, wall_seconds = self._Explore(self.folder / "interrupted")
        for key in ("counts", "rewards", "tries", "settled"):
            np.testing.assert_array_equal(resumed[key], whole[key], key)
        self.assertEqual(len(whole["settled"]), 12)
        self.assertGreater(wall_seconds, before)  # (the time before the interruption counts)
        # Run again, it is done: the model does not change, the wall time is what it was.
        again, wall_seconds = self._Explore(self.folder / "interrupted")
        np.testing.assert_array_equal(again["counts"], whole["counts"])
        self.assertGreaterEqual(wall_seconds, SavedWallSeconds(self.folder / "interrupted"))


class TestInterrupts(TemporaryFolder):
    def test_ctrl_c_on_a_battery_ends_in_one_line_and_code_130(self):
        output = self.folder / "out"
        battery = subprocess.Popen(
            [sys.executable, "-m", "mobee_drake.cli", "experiment", "saggriac", "--experiments",
             "2", "--seeds", "1", "--methods", "SAGG-RIAC", "--budget-exp2", "100000000",
             "--workers", "1", "--output", str(output)],
            stderr=subprocess.PIPE,
            text=True,
            preexec_fn=DefaultSigint,
        )  # fmt: skip
        self.addCleanup(battery.kill)
        deadline = time.monotonic() + 60
        while not list(output.glob("runs/*/progress.json")) and time.monotonic() < deadline:
            time.sleep(0.2)
        self.AssertInterruptedInOneLine(battery, signal.SIGINT)

    def test_sigterm_on_a_run_ends_in_one_line_and_code_130(self):
        """Issue 31, item 7: ``run`` ended silently with -15."""
        run = subprocess.Popen(
            [sys.executable, "-m", "mobee_drake.cli", "run", "reach_around_ball", "--duration",
             "1000", "--no-meshcat", "--no-log", "--checkpoint", "run"],
            stderr=subprocess.PIPE,
            text=True,
            cwd=self.folder,
        )  # fmt: skip
        self.addCleanup(run.kill)
        deadline = time.monotonic() + 60
        while not (self.folder / "run" / ".mobee-drake").exists() and time.monotonic() < deadline:
            time.sleep(0.1)  # until the run has claimed its folder: it is under way
        self.AssertInterruptedInOneLine(run, signal.SIGTERM)

    def AssertInterruptedInOneLine(self, process: subprocess.Popen, signum: int) -> None:
        """``signum`` ends ``process`` (a command) with one line and exit code 130."""
        process.send_signal(signum)
        _, err = process.communicate(timeout=60)
        self.assertEqual(process.returncode, 130)
        self.assertEqual(
            err.strip().splitlines()[-1],
            "interrupted: run the same command again to go on from the last checkpoints",
        )
        self.assertNotIn("Traceback", err)


class TestGracefulStop(TemporaryFolder):
    def test_ctrl_c_lets_a_running_job_save_and_stop(self):
        output = self.folder / "out"
        jobs = "[Job('walk', StopWalk, dict(steps=150, seed=1, pause=0.02))]"
        battery = subprocess.Popen(
            [
                sys.executable,
                "-c",
                "from battery_jobs import StopWalk\n"
                "from mobee_drake.experiments.battery import Job, LocalProcesses, RunBattery\n"
                f"RunBattery({jobs}, {str(output)!r}, backend=LocalProcesses(1), progress=False)",
            ],
            env={**os.environ, "PYTHONPATH": str(pathlib.Path(__file__).parent)},
            stderr=subprocess.DEVNULL,
            preexec_fn=DefaultSigint,
        )
        self.addCleanup(battery.kill)
        progress = output / "runs" / "walk" / "progress.json"
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            with contextlib.suppress(OSError, ValueError):
                if json.loads(progress.read_text())["done"] >= 10:
                    break
            time.sleep(0.05)
        battery.send_signal(signal.SIGINT)
        self.assertNotEqual(battery.wait(timeout=60), 0)
        saved = json.loads((output / "runs" / "walk" / "checkpoint.json").read_text())
        self.assertGreaterEqual(saved["step"], 10)  # It saved when asked, not at the start.
        self.assertFalse((output / "runs" / "walk" / "result.json").exists())
        whole = RunBattery(
            [Job("walk", StopWalk, dict(steps=150, seed=1, pause=0.0))],
            self.folder / "whole",
            backend=InProcess(),
            progress=False,
        )
        resumed = RunBattery(
            [Job("walk", StopWalk, dict(steps=150, seed=1, pause=0.02))],
            output,
            backend=InProcess(),
            progress=False,
        )
        self.assertEqual(resumed["walk"]["position"], whole["walk"]["position"])


def _NoConstant(name: str):
    raise ValueError(f"{name} is not JSON")


class TestStrictJson(TemporaryFolder):
    def test_every_json_file_of_runs_and_batteries_is_strict(self):
        RunScenario(
            LoadScenario("explore_hypercube", "{duration: 3}"), checkpoint=str(self.folder / "run")
        )
        with contextlib.redirect_stdout(io.StringIO()):
            saggriac_command.main(
                [
                    "--smoke",
                    "--experiments",
                    "1",
                    "--seeds",
                    "2",
                    "--output",
                    str(self.folder / "s"),
                ]
            )
            ch7_command.main(
                ["--experiment", "7.4.1", "--transitions", "3", "--runs", "1", "--output",
                 str(self.folder / "c7")]
            )  # fmt: skip
        files = sorted(self.folder.rglob("*.json"))
        kinds = {path.name for path in files}
        for expected in ("right_arm.json", "world.json", "job.json", "result.json"):
            self.assertIn(expected, kinds)
        self.assertIn("statistics.json", kinds)  # with p-values that could not be computed
        for path in files:
            with self.subTest(str(path.relative_to(self.folder))):
                json.loads(path.read_text(), parse_constant=_NoConstant)


class TestRunCheckpoints(TemporaryFolder):
    def _Run(self, *args: str) -> tuple[int, str, str]:
        out, err = io.StringIO(), io.StringIO()
        code = 0
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                cli.main(["run", "explore_hypercube", "--no-meshcat", *args])
            except SystemExit as e:
                code = e.code
        return code, out.getvalue(), err.getvalue()

    def test_a_users_folder_or_file_is_never_a_checkpoint(self):
        thesis = self.folder / "thesis.tex"
        thesis.write_text("chapter 1")
        for target in (self.folder, thesis):
            code, _, err = self._Run("--duration", "1", "--checkpoint", str(target))
            self.assertEqual(code, 2)
            self.assertRegex(err, rf"^error: {target}: .*\n$")
        self.assertEqual(thesis.read_text(), "chapter 1")
        self.assertEqual([p.name for p in self.folder.iterdir()], ["thesis.tex"])

    def test_resume_only_under_the_same_configuration_and_finished_runs_stay_finished(self):
        checkpoint = str(self.folder / "run")
        code, out, _ = self._Run("--duration", "3", "--checkpoint", checkpoint)
        self.assertEqual(code, 0, out)
        generation = CurrentGeneration(checkpoint)
        saved = (generation / "simulation.npz").read_bytes()
        code, out, _ = self._Run("--duration", "3", "--checkpoint", checkpoint)
        self.assertEqual(code, 0)
        self.assertIn("nothing to do: the checkpoint is at 3.00 s", out)
        code, _, err = self._Run("--duration", "2", "--checkpoint", checkpoint)
        self.assertEqual(code, 2)  # A shorter run than its checkpoint is a mistake.
        self.assertIn("the checkpoint is at 3.00 s, past the duration 2 s", err)
        self.assertEqual(CurrentGeneration(checkpoint), generation)
        self.assertEqual((generation / "simulation.npz").read_bytes(), saved)
        code, _, err = self._Run(
            "--duration", "4", "--checkpoint", checkpoint, "--set", "{random_seed: 5}"
        )
        self.assertEqual(code, 2)
        self.assertIn("another configuration (random_seed: 0 -> 5)", err)
        code, out, _ = self._Run("--duration", "4", "--checkpoint", checkpoint)
        self.assertEqual(code, 0)
        self.assertIn("resumed at 3.00 s", out)
        self.assertIn("simulated 1.00 s", out)


if __name__ == "__main__":
    unittest.main()
