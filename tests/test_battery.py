"""The battery runner: run-if-missing, exact resume after a kill, the same results on local
processes and on Ray (and across them), strict JSON, the display, and no worker outliving its
battery when the parent is interrupted or killed."""

import argparse
import contextlib
import importlib.util
import io
import json
import os
import pathlib
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest
from unittest import mock
import zipfile

from battery_jobs import BlasThreads, Count, DefaultSigint, FullDisk, Nan, Walk
import numpy as np

from mobee_drake import __version__
from mobee_drake.experiments import battery, saggriac
from mobee_drake.experiments.battery import (
    RAY_MISSING,
    BatteryError,
    BatteryRefused,
    FinishedResults,
    InProcess,
    Job,
    LocalProcesses,
    Ray,
    RunBattery,
    RunFolder,
)
from mobee_drake.experiments.platform_record import PlatformRecord

TESTS = str(pathlib.Path(__file__).parent)
ROOT = pathlib.Path(__file__).resolve().parents[1]
HAVE_RAY = importlib.util.find_spec("ray") is not None


def Walks(die_at: int | None = None, pause: float = 0.0) -> list[Job]:
    """Three random walks; the first dies at step ``die_at`` on its first attempt."""
    return [
        Job(
            f"walk{i}",
            Walk,
            dict(steps=8, seed=i, die_at=die_at if i == 0 else None, pause=pause),
            total=8,
        )
        for i in range(3)
    ]


def Counts(calls: pathlib.Path, n: int = 3) -> list[Job]:
    return [Job(f"count{x}", Count, dict(x=x, calls=str(calls))) for x in range(n)]


def ResultFiles(output: pathlib.Path) -> dict[str, bytes]:
    return {path.parent.name: path.read_bytes() for path in output.glob("runs/*/result.json")}


def Calls(calls: pathlib.Path) -> list[str]:
    return calls.read_text().split() if calls.exists() else []


class TemporaryFolder(unittest.TestCase):
    def setUp(self):
        self.folder = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, self.folder, ignore_errors=True)


class LocalBatteryTest(TemporaryFolder):
    def test_results_are_stored_and_not_recomputed(self):
        output, calls = self.folder / "out", self.folder / "calls"
        results = RunBattery(Counts(calls), output, workers=2, progress=False)
        self.assertEqual(list(results), ["count0", "count1", "count2"])
        self.assertEqual(results["count2"], dict(square=4, third=2 / 3))
        self.assertEqual(sorted(Calls(calls)), ["count0", "count1", "count2"])
        self.assertEqual(RunBattery(Counts(calls), output, progress=False), results)
        self.assertEqual(len(Calls(calls)), 3)
        RunBattery(Counts(calls, 4), output, backend=InProcess(), progress=False)
        self.assertEqual(sorted(Calls(calls)), ["count0", "count1", "count2", "count3"])

    def test_each_sitting_that_runs_jobs_records_its_code_and_backend(self):
        output, calls = self.folder / "out", self.folder / "calls"
        with mock.patch.dict(os.environ, OMP_NUM_THREADS="3"):
            RunBattery(Counts(calls, 2), output, workers=2, progress=False)
        RunBattery(Counts(calls, 2), output, progress=False)  # (nothing to run: no sitting)
        RunBattery(Counts(calls, 3), output, backend=InProcess(), progress=False)
        sittings = [json.loads(line) for line in (output / battery.SESSIONS).open()]
        self.assertEqual(len(sittings), 2)
        git = ["git", "-C", str(ROOT), "rev-parse", "HEAD"]
        head = subprocess.run(git, capture_output=True, text=True, check=True).stdout.strip()
        for sitting in sittings:
            self.assertEqual((sitting["version"], sitting["commit"]), (__version__, head))
            self.assertIsInstance(sitting["changed"], bool)
            self.assertRegex(sitting["began"], r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ$")
        self.assertEqual(sittings[0]["backend"], "LocalProcesses(workers=2)")
        self.assertEqual(sittings[0]["blas_environment"]["OMP_NUM_THREADS"], "3")
        self.assertEqual(sittings[0]["platform"], PlatformRecord())
        self.assertEqual(sittings[0]["platform"]["numpy"], np.__version__)
        self.assertEqual(sittings[1]["backend"], "InProcess()")
        # Files that are not a checkout's (an installed copy, even inside a repository, as a
        # venv's may be): no commit claimed.
        repository = self.folder / "repository"
        copy = repository / "venv" / "mobee_drake" / "experiments"
        copy.mkdir(parents=True)
        (repository / "README").write_text("a repository of other files\n")
        for command in (["init", "-q"], ["add", "README"], ["commit", "-q", "-m", "other"]):
            subprocess.run(["git", "-C", str(repository), "-c", "user.name=t", "-c",
                            "user.email=t@t", *command], check=True)  # fmt: skip
        with mock.patch.object(battery, "__file__", str(copy / "battery.py")):
            self.assertEqual(battery._SourceCommit(), dict(commit=None, changed=None))

    def test_finished_results_run_nothing_and_refuse_other_arguments(self):
        output, calls = self.folder / "out", self.folder / "calls"
        ran = RunBattery(Counts(calls, 2), output, backend=InProcess(), progress=False)
        before = sorted(str(p.relative_to(output)) for p in output.rglob("*"))
        self.assertEqual(FinishedResults(Counts(calls, 4), output), ran)
        self.assertEqual(len(Calls(calls)), 2)  # Nothing ran, and nothing was written:
        self.assertEqual(sorted(str(p.relative_to(output)) for p in output.rglob("*")), before)
        other = [Job("count1", Count, dict(x=5, calls=str(calls)))]
        with self.assertRaisesRegex(BatteryRefused, "count1: .*x"):
            FinishedResults(other, output)

    def test_shared_results_may_differ_in_an_unused_argument_alone(self):
        """Another battery reads the finished runs it shares (their recorded arguments theirs
        but for the one named unused), runs nothing there, and is refused by name where they
        differ in another; copied, the runs are read where they were copied, not run again,
        and a run of the battery's own is not overwritten."""
        source, output, calls = self.folder / "source", self.folder / "out", self.folder / "calls"
        RunBattery(Counts(calls, 2), source, backend=InProcess(), progress=False)
        tagged = [Job(j.name, Count, dict(j.kwargs, tag="other")) for j in Counts(calls, 3)]
        self.assertEqual(
            battery.SharedResults(tagged, source, "tag"), FinishedResults(Counts(calls), source)
        )
        with self.assertRaisesRegex(BatteryRefused, r"count0: tag: - -> other"):
            battery.SharedResults(tagged, source)
        mine = [Job("count1", Count, dict(x=7, calls=str(calls)))]
        RunBattery(mine, output, backend=InProcess(), progress=False)
        self.assertEqual(battery.CopySharedRuns(Counts(calls, 3), source, output), ["count0"])
        self.assertEqual(len(Calls(calls)), 3)
        RunBattery(Counts(calls, 1), output, backend=InProcess(), progress=False)
        self.assertEqual(len(Calls(calls)), 3)  # (count0 read where it was copied)
        with self.assertRaisesRegex(BatteryRefused, "count1: x: 7 -> 1"):
            RunBattery(Counts(calls, 2), output, backend=InProcess(), progress=False)

    def test_killed_job_resumes_exactly(self):
        reference = RunBattery(Walks(), self.folder / "ref", backend=InProcess(), progress=False)
        output = self.folder / "out"
        with self.assertRaisesRegex(BatteryError, "walk0"):
            RunBattery(Walks(die_at=4), output, workers=2, progress=False)
        self.assertTrue((output / "runs/walk0/checkpoint.json").is_file())
        self.assertFalse((output / "runs/walk0/result.json").exists())
        self.assertEqual(RunBattery(Walks(die_at=4), output, workers=2, progress=False), reference)
        self.assertEqual(ResultFiles(output), ResultFiles(self.folder / "ref"))

    def test_nan_is_refused_naming_the_job(self):
        jobs = [Job("fine", Count, dict(x=1, calls=str(self.folder / "calls"))), Job("bad", Nan)]
        output = self.folder / "out"
        with self.assertRaisesRegex(
            BatteryError, "job 'bad' returned a result that is not strict JSON"
        ):
            RunBattery(jobs, output, workers=2, progress=False)
        self.assertTrue((output / "runs/fine/result.json").is_file())
        self.assertFalse((output / "runs/bad/result.json").exists())

    def test_a_full_disk_stops_the_queue_at_the_first_failed_write(self):
        """Issue 31, item 7: on a full disk every queued run was still computed, then lost."""
        calls = self.folder / "calls"
        jobs = [Job(f"run{i}", FullDisk, dict(calls=str(calls))) for i in range(6)]
        for backend in (InProcess(), LocalProcesses(2)):
            with self.subTest(backend), self.assertRaises(BatteryError) as failed:
                RunBattery(jobs, self.folder / str(backend), backend=backend, progress=False)
            # The first failure stops the queue; with two workers, one other may be running.
            started = Calls(calls)
            calls.unlink()
            self.assertLessEqual(len(started), backend.capacity)
            message = str(failed.exception)
            self.assertTrue(message.startswith("6 of 6 jobs failed:\n"), message)
            self.assertRegex(message, r"OSError: \[Errno 28\] No space left on device: '.*"
                                      r"result.json'")  # fmt: skip
            self.assertEqual(message.count("NotStarted: not started: [Errno 28]"), 6 - len(started))

    def test_a_failed_job_is_said_when_it_fails(self):
        """A battery of hours names a failed job at once, not only when it ends."""
        printed, output = io.StringIO(), self.folder / "out"
        jobs = [Job("bad", Nan), Job("fine", Walk, dict(steps=8, seed=9, pause=0.3))]
        with contextlib.redirect_stderr(printed), self.assertRaises(BatteryError):
            RunBattery(jobs, output, workers=2, progress=True)
        lines = printed.getvalue().splitlines()
        said = [i for i, line in enumerate(lines) if line.startswith("bad failed: ValueError")]
        self.assertEqual(len(said), 1, printed.getvalue())
        # (before the battery's own last line, which it writes when its runs have ended)
        self.assertTrue(lines[-1].startswith("battery: 2/2 run"), printed.getvalue())
        self.assertLess(said[0], len(lines) - 1)

    def test_plain_progress_lines_end_at_each_runs_count(self):
        """In a log (not a terminal), a run's last line gives its final count, not the count
        last seen while it ran (issue 36: '0/600 it')."""
        printed = io.StringIO()
        uncounted = Job("uncounted", Walk, dict(steps=8, seed=9, pause=0.3))  # no total
        with contextlib.redirect_stderr(printed):
            RunBattery(Walks(pause=0.3) + [uncounted], self.folder, workers=2, progress=True)
        lines = [line for line in printed.getvalue().splitlines() if line.startswith("walk")]
        self.assertTrue(lines, printed.getvalue())
        for line in lines:
            self.assertRegex(line, r"^walk\d: 8/8 it \(\d+ s\)$")
        # A job that does not count its units has no line of its own ("0 it" said nothing).
        self.assertNotIn("uncounted", printed.getvalue())

    def test_the_progress_record_is_written_at_most_once_a_second(self):
        """Issue 32: a ch. 7 run rewrote it about 1,000 times, 13 % of the run's time."""
        run = RunFolder(self.folder)
        with mock.patch.object(battery, "WriteJsonAtomically") as write:
            for done in range(1000):
                run.Progress(done)
            self.assertEqual([c.args[1] for c in write.call_args_list], [{"done": 0}])
            with mock.patch.object(battery.time, "monotonic", return_value=time.monotonic() + 1):
                run.Progress(1000)
            self.assertEqual(write.call_args.args[1], {"done": 1000})

    def test_local_workers_get_one_blas_thread_unless_the_environment_says(self):
        """The OpenBLAS of numpy in a worker uses one thread, or the count the environment names in
        any of the variables (here OMP_NUM_THREADS, which OpenBLAS falls back on); the parent's
        environment is left as it was."""
        names = battery.BLAS_THREADS
        jobs = [Job("threads", BlasThreads, {})]
        with mock.patch.dict(os.environ):
            for name in names:
                os.environ.pop(name, None)
            ran = RunBattery(jobs, self.folder / "one", workers=1, progress=False)["threads"]
            self.assertEqual(ran, dict(dict.fromkeys(names, "1"), openblas=1))
            self.assertFalse(set(names) & set(os.environ))
            os.environ["OMP_NUM_THREADS"] = "2"
            ran = RunBattery(jobs, self.folder / "two", workers=1, progress=False)["threads"]
            self.assertEqual(ran, dict(dict.fromkeys(names), OMP_NUM_THREADS="2", openblas=2))
            self.assertEqual(os.environ["OMP_NUM_THREADS"], "2")

    def test_a_later_field_at_its_value_is_not_recorded(self):
        """A kept battery's recorded arguments still match after a field is added to a
        settings dataclass, as long as it keeps the value the battery ran with."""
        from mobee_drake.planning.space_maintenance import MaintenanceConfig

        def Recorded(config):
            return json.loads(battery._ArgumentsText(Job("j", Count, dict(m=config))))["m"]

        self.assertNotIn("join_within", Recorded(MaintenanceConfig())["MaintenanceConfig"])
        local = Recorded(MaintenanceConfig(join_within=0.5))["MaintenanceConfig"]
        self.assertEqual(local["join_within"], 0.5)

    def test_bad_jobs_are_refused(self):
        with self.assertRaisesRegex(TypeError, "job 'local'"):
            Job("local", lambda run: {})
        with self.assertRaisesRegex(ValueError, "names a folder"):
            Job("a/b", Nan)
        with self.assertRaisesRegex(ValueError, "repeat: \\['a'\\]"):
            RunBattery([Job("a", Nan), Job("a", Nan)], self.folder, progress=False)

    def test_display_shows_the_battery_and_the_running_jobs(self):
        stream = io.StringIO()
        with contextlib.redirect_stderr(stream):
            RunBattery(Walks(pause=0.2)[:2], self.folder, workers=2, description="walks")
        # Standard error is not a terminal here: plain lines, the battery's and the runs'.
        self.assertIn("walks: 2/2 run", stream.getvalue())
        self.assertRegex(stream.getvalue(), r"walk0: \d+/8 it")

    def test_the_ray_flag_bare_auto_or_an_address_that_answers(self):
        """Issue 31: an address nobody answers was waited on for minutes; the bare flag (a
        local Ray instance) and ``auto`` need no address."""
        parser = argparse.ArgumentParser()
        battery.AddBackendArguments(parser)
        for argv, expected in (
            ([], LocalProcesses(1)),
            (["--ray"], Ray(address=None)),
            (["--ray", "auto"], Ray(address="auto")),
        ):
            with self.subTest(argv):
                self.assertEqual(battery.BackendOf(parser.parse_args(argv)), expected)
        with socket.socket() as listening:  # an address that answers
            listening.bind(("127.0.0.1", 0))
            listening.listen()
            address = f"127.0.0.1:{listening.getsockname()[1]}"
            self.assertEqual(battery.BackendOf(parser.parse_args(["--ray", address])).address,
                             address)  # fmt: skip
        for bad in ("127.0.0.1:1", "bogus", "host:99999"):
            with self.subTest(bad), self.assertRaises(argparse.ArgumentTypeError):
                battery.RayAddress(bad)

    def test_without_ray_the_error_says_how_to_install_it(self):
        with mock.patch.dict(sys.modules, {"ray": None}):
            with self.assertRaisesRegex(ImportError, re.escape(RAY_MISSING)):
                RunBattery([Job("a", Nan)], self.folder, backend=Ray(), progress=False)


@unittest.skipUnless(HAVE_RAY, "needs ray")
class RayBatteryTest(TemporaryFolder):
    @classmethod
    def setUpClass(cls):
        import ray

        ray.init(
            num_cpus=2,
            include_dashboard=False,
            log_to_driver=False,
            runtime_env={"env_vars": {"PYTHONPATH": TESTS}},
        )

    @classmethod
    def tearDownClass(cls):
        import ray

        ray.shutdown()

    def test_same_results_as_local_processes(self):
        on_ray = RunBattery(Walks(), self.folder / "ray", backend=Ray(), progress=False)
        local = RunBattery(Walks(), self.folder / "local", workers=2, progress=False)
        self.assertEqual(on_ray, local)
        self.assertEqual(ResultFiles(self.folder / "ray"), ResultFiles(self.folder / "local"))

    def test_an_experiment_battery_gives_the_same_runs_on_both_backends(self):
        # SAGG-RIAC's runs, tiny: everything but the wall time is the same on both backends.
        specs = [
            saggriac.RunSpec(1, method, 0, 300, 1) for method in ("SAGG-RIAC", "ACTUATOR-RIAC")
        ]
        results = {
            name: saggriac.RunAll(specs, self.folder / name, backend)
            for name, backend in (("ray", Ray()), ("local", LocalProcesses(2)))
        }
        for run in (*results["ray"], *results["local"]):
            self.assertGreater(run.wall_time_s, 0.0)
            run.wall_time_s = 0.0
        self.assertEqual(
            [run.ToJson() for run in results["ray"]], [run.ToJson() for run in results["local"]]
        )
        self.assertEqual(len(results["ray"][0].curve), 2)

    def test_half_done_battery_finishes_on_the_other_backend(self):
        reference = RunBattery(
            Counts(self.folder / "calls"), self.folder / "ref", backend=InProcess(), progress=False
        )
        for first, second in ((LocalProcesses(2), Ray()), (Ray(), LocalProcesses(2))):
            with self.subTest(first=type(first).__name__):
                output, calls = self.folder / type(first).__name__, self.folder / "calls"
                calls.unlink(missing_ok=True)
                RunBattery(Counts(calls)[:2], output, backend=first, progress=False)
                results = RunBattery(Counts(calls), output, backend=second, progress=False)
                self.assertEqual(results, reference)
                self.assertEqual(ResultFiles(output), ResultFiles(self.folder / "ref"))
                self.assertEqual(sorted(Calls(calls)), ["count0", "count1", "count2"])

    def test_job_killed_on_local_processes_resumes_on_ray(self):
        reference = RunBattery(Walks(), self.folder / "ref", backend=InProcess(), progress=False)
        output = self.folder / "out"
        with self.assertRaises(BatteryError):
            RunBattery(Walks(die_at=4), output, workers=2, progress=False)
        self.assertEqual(
            RunBattery(Walks(die_at=4), output, backend=Ray(), progress=False), reference
        )
        self.assertEqual(ResultFiles(output), ResultFiles(self.folder / "ref"))

    def test_ray_retries_a_killed_job_from_its_checkpoint(self):
        reference = RunBattery(Walks(), self.folder / "ref", backend=InProcess(), progress=False)
        output = self.folder / "out"
        self.assertEqual(
            RunBattery(Walks(die_at=4), output, backend=Ray(), progress=False), reference
        )
        self.assertTrue((output / "runs/walk0/died").exists())

    def test_nan_is_refused_naming_the_job(self):
        with self.assertRaisesRegex(
            BatteryError, "job 'bad' returned a result that is not strict JSON"
        ):
            RunBattery([Job("bad", Nan)], self.folder, backend=Ray(), progress=False)


def Processes() -> dict[int, tuple[int, str]]:
    """Pid -> (parent pid, state) of every process, from /proc."""
    table = {}
    for stat in pathlib.Path("/proc").glob("[0-9]*/stat"):
        with contextlib.suppress(OSError):
            fields = stat.read_text().rsplit(")", 1)[1].split()
            table[int(stat.parent.name)] = (int(fields[1]), fields[0])
    return table


def Descendants(pid: int) -> set[int]:
    table, found, stack = Processes(), set(), [pid]
    while stack:
        parent = stack.pop()
        children = [p for p, (pp, _) in table.items() if pp == parent]
        found.update(children)
        stack.extend(children)
    return found


def Alive(pids: set[int]) -> set[int]:
    """Those of ``pids`` that run (zombies are dead: nobody may reap orphans here)."""
    table = Processes()
    return {pid for pid in pids if pid in table and table[pid][1] not in "ZX"}


def Kill(pids: set[int]) -> None:
    for pid in Alive(pids):
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)


def WaitFor(condition, seconds: float) -> bool:
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.1)
    return True


@unittest.skipUnless(sys.platform.startswith("linux"), "PR_SET_PDEATHSIG and /proc are Linux's")
class NoOrphansTest(TemporaryFolder):
    """A battery of a quick job and two sleepers (:func:`battery_jobs.Main`) in a process of its
    own, interrupted or killed once the sleepers run."""

    def Start(self, backend: str) -> tuple[subprocess.Popen, set[int]]:
        """The battery's process and its descendants once the sleepers run."""
        self.output, pids = self.folder / "out", self.folder / "pids"
        pids.mkdir()
        environment = dict(os.environ, PYTHONPATH=TESTS)
        log = (self.folder / "parent.log").open("w")
        self.addCleanup(log.close)
        code = "import sys, battery_jobs; battery_jobs.Main(*sys.argv[1:])"
        parent = subprocess.Popen(
            [sys.executable, "-c", code, backend, self.output, pids],
            env=environment,
            stdout=log,
            stderr=log,
            preexec_fn=DefaultSigint,
        )
        self.addCleanup(parent.kill)
        ready = WaitFor(
            lambda: (
                {"sleeper0", "sleeper1"} <= {p.name for p in pids.iterdir()}
                and (self.output / "runs/quick/result.json").exists()
            ),
            60,
        )
        self.assertTrue(ready, (self.folder / "parent.log").read_text())
        processes = Descendants(parent.pid)
        sleepers = {int((pids / name).read_text()) for name in ("sleeper0", "sleeper1")}
        self.assertLessEqual(sleepers, processes)
        self.addCleanup(Kill, processes)  # Should a test fail.
        return parent, processes

    def AssertAllGone(self, processes: set[int], seconds: float):
        WaitFor(lambda: not Alive(processes), seconds)
        self.assertEqual(Alive(processes), set(), (self.folder / "parent.log").read_text())

    def AssertInterruptsCleanly(self, backend: str, signum: int, seconds: float):
        parent, processes = self.Start(backend)
        parent.send_signal(signum)
        self.assertNotEqual(parent.wait(seconds), 0)
        self.AssertAllGone(processes, 5)
        self.assertTrue((self.output / "runs/quick/result.json").is_file())
        self.assertFalse((self.output / "runs/sleeper0/result.json").exists())

    def test_sigkill_of_the_parent_leaves_no_local_worker(self):
        parent, processes = self.Start("local")
        parent.kill()
        parent.wait()
        self.AssertAllGone(processes, 5)

    def test_sigint_stops_the_local_workers(self):
        self.AssertInterruptsCleanly("local", signal.SIGINT, 10)

    def test_sigterm_stops_the_local_workers(self):
        self.AssertInterruptsCleanly("local", signal.SIGTERM, 10)

    @unittest.skipUnless(HAVE_RAY, "needs ray")
    def test_sigkill_of_the_driver_leaves_no_ray_process(self):
        parent, processes = self.Start("ray")
        parent.kill()
        parent.wait()
        self.AssertAllGone(processes, 5)

    @unittest.skipUnless(HAVE_RAY, "needs ray")
    def test_sigint_stops_ray(self):
        self.AssertInterruptsCleanly("ray", signal.SIGINT, 30)


class CompressResultsTest(TemporaryFolder):
    """scripts/compress_results.py: the finished runs' arrays compressed, the same arrays."""

    def test_finished_runs_are_compressed_and_running_ones_left_alone(self):
        spec = importlib.util.spec_from_file_location(
            "compress_results", ROOT / "scripts" / "compress_results.py"
        )
        script = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(script)
        counts = np.zeros((300, 80))
        counts[::7, ::3] = 5.0
        for run in ("finished", "running"):
            generation = self.folder / "runs" / run / "model" / "g000001"
            generation.mkdir(parents=True)
            np.savez(generation / "arm.npz", counts=counts, tries=np.arange(300))
        (self.folder / "runs" / "finished" / battery.RESULT).write_text("{}")
        finished = self.folder / "runs/finished/model/g000001/arm.npz"
        running = self.folder / "runs/running/model/g000001/arm.npz"
        unchanged = running.read_bytes()

        other = self.folder / "runs" / "finished" / "other.npz"
        with zipfile.ZipFile(other, "w") as archive:
            archive.writestr("notes.txt", "not an array")
        (self.folder / "runs" / "finished" / "damaged.npz").write_bytes(b"PK\x03\x04 cut")
        before, after, left = script.CompressFinishedRuns(self.folder)
        self.assertEqual(len(left), 2)
        self.assertTrue(left[0].startswith(f"{self.folder}/runs/finished/damaged.npz: "))
        self.assertEqual(left[1], f"{other}: not arrays alone")
        self.assertEqual(before, len(unchanged))
        self.assertLess(after, before / 10)
        self.assertTrue(script.IsCompressed(finished))
        self.assertFalse(script.IsCompressed(running))
        self.assertEqual(running.read_bytes(), unchanged)
        with np.load(finished) as saved:
            np.testing.assert_array_equal(saved["counts"], counts)
            np.testing.assert_array_equal(saved["tries"], np.arange(300))
        self.assertEqual(script.CompressFinishedRuns(self.folder)[:2], (0, 0))


if __name__ == "__main__":
    unittest.main()
