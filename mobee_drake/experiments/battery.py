"""The battery runner: every experiment's runs (seeds, strategies, settings) go through
:func:`RunBattery`, on local processes or on Ray, with the same files on disk.

A battery is a list of jobs (:class:`Job`), each a module-level function called as
``function(run, **kwargs)`` in a worker, returning a JSON-able dict, its result. ``output`` holds:

- ``runs/<name>/result.json``: the job's result, checked as strict JSON (a NaN or an infinity
  fails the job, naming it) and written atomically by the runner when the job returns. A job whose
  result file exists is not run again: its stored result is returned (run-if-missing).
  :func:`FinishedResults` returns the stored results alone, running nothing (a report of part
  of a battery).
- ``runs/<name>/job.json``: the job's function and arguments, written before it first runs. A
  battery whose job finds its folder holding a run of other arguments (a result or a checkpoint
  made with other settings) is refused before anything runs, naming what differs, so that a
  result is never reused, nor a run resumed, under settings it was not made with.
- ``runs/<name>/progress.json``: the last count the job gave :meth:`RunFolder.Progress`, from
  which the parent draws the run's bar (a battery bar counts the runs, a bar per running job
  counts its units; the parent reads the records every :data:`POLL_SECONDS`).
- ``sessions.jsonl`` (beside ``runs/``): a line per sitting that ran jobs (:data:`SESSIONS`):
  when it began, the package's version, the git commit its files were imported from and whether
  they differed from it, the backend and the BLAS variables, so that a kept battery says what
  code made it.
- anything else in ``runs/<name>/``: the job's own checkpoints. A job that saves its whole state
  there (atomically, see :mod:`mobee_drake.atomic_files`) and starts from it when it finds one
  resumes exactly after a kill, on either backend.

The output folder is claimed and locked while the battery runs (:mod:`mobee_drake.owned_folders`):
a folder of the user's is refused, and so is a second battery on the same folder. The results are
returned, keyed by job name in job order, as parsed from their files, so a
result computed now and one loaded later are equal. Jobs are deterministic functions of their
kwargs and the runner adds nothing to their results, so a job gives the same bytes on every
backend, and a battery interrupted on one backend finishes on another. A job that fails does not
stop the others; when all are done, :class:`BatteryError` names those that failed.

Backends (``Session()`` gives a ``submit(job, output)`` that returns a
:class:`concurrent.futures.Future` of the result's JSON text; ``capacity`` is how many jobs the
parent keeps submitted):

- :class:`LocalProcesses`, the default: a pool of ``workers`` spawned processes. Each worker asks
  Linux for SIGKILL when its parent dies (``prctl(PR_SET_PDEATHSIG)``; it checks right after that
  the parent is still the one that started it) and ignores SIGINT, so a Ctrl-C in a terminal reaches
  only the parent. The parent then stops the queue, asks the running jobs to stop (SIGUSR1:
  :func:`StopRequested` turns True, and a job that checkpoints saves and stops at its next safe
  point), waits for them up to :data:`STOP_SECONDS`, kills the workers and re-raises. During a
  battery, SIGTERM raises :class:`KeyboardInterrupt` in the parent as SIGINT does, so the same
  clean-up runs; after a SIGKILL of the parent the kernel kills the workers (processes that a job
  starts itself are the job's to tie to its own life). A worker that dies (say, at the hands of the
  OOM killer) breaks the pool: the battery stops with :class:`BatteryError`, and running it again
  resumes. The workers are the battery's parallelism, so each gets one BLAS thread
  (:data:`BLAS_THREADS`, unless the command's environment names a count): OpenBLAS threads a product
  above a size (a 256-state roadmap's model of 2028 state-actions is above it, the rank-4 lattice's
  of 1536 below), and on cores the other workers keep busy its threads wait for one another (the
  roadmap's runs of the curious agent took several times the lattice's wall time:
  docs/adaptive_space.md).
- :class:`Ray`: tasks on a Ray cluster (``ray.init(address)``; no address, a local instance, or
  the cluster ``RAY_ADDRESS`` names). When Ray is already initialised, the battery uses that
  connection (so a caller can pass ``runtime_env`` and other options to :func:`ray.init` itself)
  and leaves it open; otherwise it initialises Ray and shuts it down at the end. Ray retries a
  task whose worker died (its ``max_retries``), and the job resumes from its checkpoint. Ray
  gives a task of one CPU ``OMP_NUM_THREADS=1``, which OpenBLAS reads too (Ray 2.60). On a
  cluster of several nodes, ``output`` must be on storage that every node sees at the same path
  (a shared file system), and the package must be installed on every node. On Ctrl-C or SIGTERM
  the tasks are cancelled (their workers killed) before Ray is shut down.

  What a SIGKILL of the driver leaves of a local instance (Ray 2.60, Linux): Ray starts the GCS,
  raylet, dashboard and monitors with kernel fate-sharing (``PR_SET_PDEATHSIG`` = SIGKILL), and
  the workers exit when their raylet goes. But the raylet's two agents (``ray::DashboardAgent``,
  ``ray::RuntimeEnvAgent``) notice that the raylet died, then wait up to 60 s to report it to
  the dead GCS before exiting. So a local instance that the battery starts has a watchdog: a
  small process of its own session, started before :func:`ray.init`, that notes every second
  the instance's processes (the driver's children run from Ray's package folder and all their
  descendants, with their start times) and SIGKILLs those still alive when its stdin, a pipe
  from the driver, closes: at the end of the battery, or when the kernel closes it because the
  driver died.
- :class:`InProcess`: one job after the other in the calling process, for tests and debugging
  (a breakpoint in a job works); the display only advances between jobs.
"""

import argparse
import collections
from collections.abc import Callable, Iterable
import concurrent.futures
import contextlib
import ctypes
import dataclasses
import errno
import hashlib
import json
import math
import multiprocessing
import os
import pathlib
import pickle
import re
import select
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from typing import ClassVar

from mobee_drake import __version__
from mobee_drake.atomic_files import StrictJson, WriteJsonAtomically, WriteTextAtomically
from mobee_drake.experiments.arguments import PositiveInt
from mobee_drake.experiments.platform_record import PlatformRecord
from mobee_drake.owned_folders import OwnedFolder
from mobee_drake.progress import ProgressBar, Say
from mobee_drake.yaml_io import YamlDifferences

RESULT = "result.json"
PROGRESS = "progress.json"
# A job's arguments, as it was first run with them.
ARGUMENTS = "job.json"
# How often the parent reads the running jobs' progress records, and the most often a job
# writes its own (s).
POLL_SECONDS = PROGRESS_SECONDS = 1.0
# How long an interrupted battery waits for its running jobs to save and stop (s).
STOP_SECONDS = 30.0
RAY_MISSING = '--ray needs the optional extra: pip install "mobee-drake[ray]"'
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._+=-]*")


@dataclasses.dataclass(frozen=True)
class Job:
    """One run of a battery: ``function(run, **kwargs)``, with ``run`` its :class:`RunFolder`.

    Attributes:
        name: Unique in the battery; names the run's folder (letters, digits and ``._+=-``).
        function: A module-level function (workers import it by name) returning a JSON-able
            dict.
        kwargs: Its keyword arguments; picklable.
        total: The units of :meth:`RunFolder.Progress` in a whole run (0: unknown).
    """

    name: str
    function: Callable[..., dict]
    kwargs: dict = dataclasses.field(default_factory=dict)
    total: int = 0

    def __post_init__(self):
        if not _NAME.fullmatch(self.name):
            raise ValueError(
                f"job name {self.name!r}: it names a folder; use letters, digits and ._+=-"
            )
        try:
            pickle.dumps(self)
        except (pickle.PicklingError, AttributeError, TypeError) as error:
            raise TypeError(
                f"job {self.name!r} cannot be sent to a worker (the function must "
                f"be module-level, the kwargs picklable): {error}"
            ) from error


@dataclasses.dataclass
class RunFolder:
    """A job's own folder, ``output/runs/<name>/``, for its checkpoints: any files but
    ``result.json`` and ``progress.json``, which are the runner's."""

    path: pathlib.Path
    # When its progress record was last written (time.monotonic()).
    _written: float = dataclasses.field(default=-math.inf, repr=False)

    def Progress(self, done: int) -> None:
        """Records that ``done`` of the job's :attr:`Job.total` units are done, for the display:
        one small atomic write, at most once every :data:`PROGRESS_SECONDS` (call it as often
        as is convenient; a ch. 7 run calls it about 1,000 times)."""
        now = time.monotonic()
        if now - self._written >= PROGRESS_SECONDS:
            WriteJsonAtomically(self.path / PROGRESS, {"done": int(done)})
            self._written = now


class BatteryError(RuntimeError):
    """Jobs of a battery failed (the message names them); the others' results are on disk."""


class BatteryRefused(ValueError):
    """A battery that may not run in its folder (runs of other arguments are there)."""


class NotStarted(Exception):
    """A job the battery did not start, after another's write failed for want of space."""


# A write that fails for one of these fails for every job (the disk is full or read-only).
DISK_ERRNOS = (errno.ENOSPC, errno.EDQUOT, errno.EROFS)


def _DiskRefuses(error: BaseException) -> bool:
    """Whether ``error`` (or the error a Ray task's wraps) is a write the disk refused."""
    cause = getattr(error, "cause", None)  # (Ray's RayTaskError: its errno is lost)
    if isinstance(cause, BaseException) and cause is not error:
        return _DiskRefuses(cause)
    return isinstance(error, OSError) and error.errno in DISK_ERRNOS


class JobStopped(Exception):
    """A job that, asked to stop (:func:`StopRequested`), saved its checkpoint and stopped."""


_stop_requested = False
_job_asks = False


def StopRequested() -> bool:
    """Whether the battery has asked its running jobs to stop.

    The parent asks on Ctrl-C or SIGTERM (local processes). A job that checkpoints asks at its
    safe points; when True, it saves its checkpoint and raises :class:`JobStopped`, so that it
    resumes from there. A job that never asks has nothing to save: asked to stop, its worker
    exits at once.
    """
    global _job_asks
    _job_asks = True
    return _stop_requested


def _RequestStop(signum, frame) -> None:
    global _stop_requested
    if not _job_asks:
        os._exit(1)
    _stop_requested = True


def _RunJob(job: Job, output: pathlib.Path) -> str:
    """Runs ``job`` wherever the backend put it; writes its result and returns it as JSON."""
    global _job_asks
    _job_asks = False  # Until this job asks (see StopRequested).
    run = RunFolder(output / "runs" / job.name)
    run.path.mkdir(parents=True, exist_ok=True)
    run.Progress(0)
    result = job.function(run, **job.kwargs)
    if not isinstance(result, dict):
        raise TypeError(f"job {job.name!r} returned a {type(result).__name__}, not a dict")
    try:
        text = json.dumps(result, allow_nan=False)
    except (TypeError, ValueError) as error:
        raise ValueError(
            f"job {job.name!r} returned a result that is not strict JSON: {error}"
        ) from error
    WriteTextAtomically(run.path / RESULT, text)
    return text


def _RunHere(job: Job, output: pathlib.Path) -> concurrent.futures.Future:
    future = concurrent.futures.Future()
    try:
        future.set_result(_RunJob(job, output))
    except Exception as error:
        future.set_exception(error)
    return future


@dataclasses.dataclass(frozen=True)
class InProcess:
    """Runs the jobs one after the other in the calling process (for tests and debugging)."""

    capacity: ClassVar[float] = 1

    @contextlib.contextmanager
    def Session(self):
        yield _RunHere


def DieWithParent(parent: int) -> None:
    """Makes the calling process (a child of ``parent``) receive SIGKILL when its parent dies
    (Linux; elsewhere nothing)."""
    if sys.platform.startswith("linux"):
        PR_SET_PDEATHSIG = 1
        if ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0):
            raise OSError(ctypes.get_errno(), "prctl(PR_SET_PDEATHSIG) failed")
        if os.getppid() != parent:  # The parent died before the prctl.
            os._exit(1)


# Each sitting of a battery (a call that runs jobs) as a line of JSON in its folder.
SESSIONS = "sessions.jsonl"

# The thread counts of the BLAS libraries numpy and scipy may load (a library reads its count
# when it loads; OpenBLAS and MKL fall back on OMP_NUM_THREADS).
BLAS_THREADS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


@contextlib.contextmanager
def _OneBlasThread():
    """Within it, the processes this one starts get one BLAS thread, unless its environment
    names a count in any of :data:`BLAS_THREADS` (then all are left as they are); on leaving,
    the environment is as it was."""
    saved = {name: os.environ.get(name) for name in BLAS_THREADS}
    if not any(saved.values()):
        os.environ.update(dict.fromkeys(BLAS_THREADS, "1"))
    try:
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


def _DieWithParent(parent: int) -> None:
    """The local workers' initializer: SIGKILL when the parent dies; no SIGINT; SIGUSR1 asks
    the job to stop (see :func:`StopRequested`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGUSR1, _RequestStop)
    DieWithParent(parent)


@dataclasses.dataclass(frozen=True)
class LocalProcesses:
    """Runs the jobs in ``workers`` spawned processes of this machine."""

    workers: int = 1

    @property
    def capacity(self) -> float:
        return self.workers

    @contextlib.contextmanager
    def Session(self):
        with _OneBlasThread():
            pool = concurrent.futures.ProcessPoolExecutor(
                self.workers,
                mp_context=multiprocessing.get_context("spawn"),
                initializer=_DieWithParent,
                initargs=(os.getpid(),),
            )
            submitted = []

            def Submit(job: Job, output: pathlib.Path) -> concurrent.futures.Future:
                submitted.append(pool.submit(_RunJob, job, output))
                return submitted[-1]

            try:
                yield Submit
            except BaseException:
                # Interrupted: the queue stops, the running jobs are asked to save and stop, and
                # after STOP_SECONDS no worker outlives the battery (Python 3.11 has no public way).
                for future in submitted:
                    future.cancel()
                processes = list(pool._processes.values())
                for process in processes:
                    with contextlib.suppress(ProcessLookupError):
                        os.kill(process.pid, signal.SIGUSR1)
                concurrent.futures.wait(submitted, STOP_SECONDS)
                for process in processes:
                    process.kill()
                raise
            finally:
                pool.shutdown(cancel_futures=True)


def _ProcessTable() -> dict[int, tuple[int, int]]:
    """Every live process (zombies excepted): pid -> (parent pid, start time), from /proc."""
    table = {}
    for entry in os.scandir("/proc"):
        if entry.name.isdigit():
            try:
                fields = pathlib.Path(entry.path, "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if fields[0] != "Z":
                table[int(entry.name)] = (int(fields[1]), int(fields[19]))
    return table


def _CommandLine(pid: int) -> str:
    try:
        return pathlib.Path(f"/proc/{pid}/cmdline").read_bytes().decode(errors="replace")
    except OSError:
        return ""


def _WatchRay(driver: int, ray_folder: str) -> None:
    """The watchdog of a local Ray instance (see the module's docstring), in its own process:
    until its stdin closes, notes the processes of the instance that ``driver`` started; then
    kills those still alive (the same pid and start time)."""
    tracked = {}
    while not select.select([sys.stdin], [], [], POLL_SECONDS)[0]:
        table = _ProcessTable()
        children = collections.defaultdict(list)
        for pid, (parent, _) in table.items():
            children[parent].append(pid)
        stack = [
            pid
            for pid in children[driver]
            if pid != os.getpid() and ray_folder in _CommandLine(pid)
        ]
        while stack:
            pid = stack.pop()
            tracked[pid] = table[pid][1]
            stack.extend(children[pid])
    table = _ProcessTable()
    for pid, start in tracked.items():
        if pid in table and table[pid][1] == start:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)


@contextlib.contextmanager
def _RayWatchdog(ray_folder: str):
    """Runs :func:`_WatchRay` for this driver while the context lasts."""
    code = f"from {__name__} import _WatchRay; _WatchRay({os.getpid()}, {ray_folder!r})"
    watchdog = subprocess.Popen(
        [sys.executable, "-c", code], stdin=subprocess.PIPE, start_new_session=True
    )
    try:
        yield
    finally:
        watchdog.stdin.close()
        watchdog.wait()


@dataclasses.dataclass(frozen=True)
class Ray:
    """Runs the jobs as tasks on a Ray cluster at ``address`` (None: a local instance)."""

    address: str | None = None
    capacity: ClassVar[float] = math.inf

    @contextlib.contextmanager
    def Session(self):
        try:
            import ray
        except ImportError:
            raise ImportError(RAY_MISSING) from None
        with contextlib.ExitStack() as stack:
            if not ray.is_initialized():
                if sys.platform.startswith("linux"):
                    stack.enter_context(_RayWatchdog(os.path.dirname(ray.__file__)))
                ray.init(address=self.address)
                stack.callback(ray.shutdown)
            remote, refs = ray.remote(_RunJob), []

            def Submit(job: Job, output: pathlib.Path) -> concurrent.futures.Future:
                refs.append(remote.remote(job, output))
                return refs[-1].future()

            try:
                yield Submit
            except BaseException:
                for ref in refs:
                    ray.cancel(ref, force=True)
                raise


Backend = InProcess | LocalProcesses | Ray


def _Terminate(signum, frame):
    raise KeyboardInterrupt  # (the command line's one line and exit code 130, as for Ctrl-C)


@contextlib.contextmanager
def TerminationInterrupts():
    """SIGTERM raises KeyboardInterrupt in the main thread while the context lasts."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _Terminate)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL if previous is None else previous)


class _Display:
    """The battery's bar and a bar per running job that counts its units (a total) and has a
    progress record."""

    def __init__(self, output: pathlib.Path, jobs: int, done: int, description: str, enabled: bool):
        self.output, self.enabled, self.runs = output, enabled, {}
        self.battery = ProgressBar(
            total=jobs,
            initial=done,
            desc=description or "battery",
            unit="run",
            disable=not enabled,
            dynamic_ncols=True,
        )

    def Update(self, running: Iterable[Job], finished: int) -> None:
        self.battery.update(finished)
        if not self.enabled:
            return
        running = {job.name: job for job in running}
        for name in self.runs.keys() - running.keys():  # Finished: its bar ends at its count.
            bar = self.runs.pop(name)
            done = bar.total if _StoredResult(self.output, name) is not None else self._Done(name)
            bar.update((done or bar.n) - bar.n)
            bar.close()
        for name, job in running.items():
            done = self._Done(name)
            if done is None or not job.total:  # Not started, or its units unknown: no bar.
                continue
            if name not in self.runs:
                self.runs[name] = ProgressBar(
                    total=job.total or None,
                    initial=done,
                    desc=name,
                    leave=False,
                    dynamic_ncols=True,
                )
            self.runs[name].update(done - self.runs[name].n)

    def _Done(self, name: str) -> int | None:
        """A job's progress record, or None before it has one."""
        try:
            return json.loads((self.output / "runs" / name / PROGRESS).read_text())["done"]
        except (OSError, ValueError):
            return None

    def Failed(self, name: str, error: Exception) -> None:
        """Says at once that job ``name`` failed (the battery names every failed job again
        when it ends)."""
        if self.enabled:
            Say(f"{name} failed: {type(error).__name__}: {error}")

    def Close(self) -> None:
        for bar in self.runs.values():
            bar.close()
        self.battery.close()


def _StoredResult(output: pathlib.Path, name: str) -> dict | None:
    try:
        return json.loads((output / "runs" / name / RESULT).read_text())
    except FileNotFoundError:
        return None


def RunBattery(
    jobs: Iterable[Job],
    output: str | pathlib.Path,
    *,
    backend: Backend | None = None,
    workers: int = 1,
    progress: bool = True,
    description: str = "",
) -> dict[str, dict]:
    """Runs the ``jobs`` that have no result in ``output`` yet and returns every job's result,
    keyed by name in job order (see the module's docstring).

    Args:
        jobs: The battery's runs.
        output: The battery's folder (``runs/<name>/`` for each job).
        backend: Where the jobs run; None: ``LocalProcesses(workers)``.
        workers: The local processes of the default backend.
        progress: Whether to show the bars.
        description: The battery bar's label.

    Raises:
        BatteryError: When jobs failed, after the others finished.
        ValueError: Before anything runs, when job names repeat.
        BatteryRefused: Before anything runs, when a job's folder holds a run of other arguments
            (naming what differs).
        FolderError: When ``output`` is not ours or another battery is using it.
    """
    jobs, output = list(jobs), pathlib.Path(output).absolute()  # Workers have their own cwd.
    names = [job.name for job in jobs]
    if len(set(names)) != len(names):
        raise ValueError(f"job names repeat: {sorted({n for n in names if names.count(n) > 1})}")
    with OwnedFolder(output, "battery"):
        _CheckArguments(jobs, output)
        return _RunJobs(jobs, output, backend or LocalProcesses(workers), progress, description)


def _Plain(value):
    """JSON for what a job's arguments hold besides JSON's own types. A dataclass's fields
    named in its ``LATER_FIELDS`` (name: value) are left out at those values: fields added
    after batteries were kept, whose recorded arguments must still match (of a dataclass that
    is itself an argument: ``asdict`` writes those nested in it whole)."""
    if dataclasses.is_dataclass(value):
        fields = dataclasses.asdict(value)
        for name, default in getattr(value, "LATER_FIELDS", {}).items():
            if fields[name] == default:
                del fields[name]
        return {type(value).__name__: fields}
    if hasattr(value, "tolist"):
        return value.tolist()
    return str(value)


def _ArgumentsText(job: Job) -> str:
    arguments = dict(
        mobee_drake_version=__version__,
        function=f"{job.function.__module__}.{job.function.__qualname__}",
    )
    arguments.update(job.kwargs)
    return StrictJson(arguments, default=_Plain, sort_keys=True, indent=1)


def FinishedResults(jobs: Iterable[Job], output: str | pathlib.Path) -> dict[str, dict]:
    """The stored results of those of ``jobs`` that have finished in ``output``, keyed by name in
    job order, running and writing nothing (a report while the battery runs, or of part of it).

    Raises:
        BatteryRefused: When a finished job's folder holds a run of other arguments, as
            :func:`RunBattery` would.
    """
    jobs, output = list(jobs), pathlib.Path(output).absolute()
    results = {job.name: _StoredResult(output, job.name) for job in jobs}
    _RefuseOtherArguments([job for job in jobs if results[job.name] is not None], output)
    return {name: result for name, result in results.items() if result is not None}


def SharedResults(
    jobs: Iterable[Job], output: str | pathlib.Path, unused: str | None = None
) -> dict[str, dict]:
    """The stored results of those of ``jobs`` that have finished in another battery's
    ``output``, whose recorded arguments are theirs, but maybe for the argument ``unused``: one
    their function does not use for these jobs (a battery that reads the runs it shares with
    another rather than make them again). Runs and writes nothing.

    Raises:
        BatteryRefused: When a finished job's recorded arguments differ in another one.
    """
    output, results, mismatches = pathlib.Path(output).absolute(), {}, []
    for job in jobs:
        result = _StoredResult(output, job.name)
        if result is not None:
            mismatches.append(_Mismatch(job, output, unused))
            results[job.name] = result
    if any(mismatches):
        but = f" but for {unused}" if unused else ""
        raise _Refusal(output, f"holds runs of other arguments than ours{but}", mismatches)
    return results


def CopySharedRuns(jobs: Iterable[Job], source: str | pathlib.Path, output: pathlib.Path) -> list:
    """Copies into ``output`` (a battery's folder, owned) the runs of ``jobs`` finished in
    another battery's ``source`` with the same arguments, where ``output`` has none of its own:
    the battery then reads the very files the other one made. The names copied.

    Raises:
        BatteryRefused: As :func:`SharedResults`.
    """
    copied = []
    for name in SharedResults(jobs, source):
        if not (output / "runs" / name).exists():
            shutil.copytree(pathlib.Path(source) / "runs" / name, output / "runs" / name)
            copied.append(name)
    return copied


def _Mismatch(job: Job, output: pathlib.Path, unused: str | None = None) -> str | None:
    """What the arguments recorded in ``job``'s folder in ``output`` differ in from its own
    (but for ``unused``), named; None when they are the same."""
    path = output / "runs" / job.name / ARGUMENTS
    if not path.is_file():
        return f"{job.name}: its folder holds a run without recorded arguments"
    recorded, own = json.loads(path.read_text()), json.loads(_ArgumentsText(job))
    for arguments in (recorded, own):
        arguments.pop(unused, None)
    recorded, own = (json.dumps(a, sort_keys=True) for a in (recorded, own))
    if recorded == own:
        return None
    return f"{job.name}: {'; '.join(YamlDifferences(recorded, own)[:3])}"


def _CheckArguments(jobs: list[Job], output: pathlib.Path) -> None:
    """Records each job's arguments in its folder (``job.json``), or, when the folder holds
    a run of other arguments, refuses the battery naming what differs."""
    _RefuseOtherArguments(jobs, output)
    for job in jobs:
        if not (output / "runs" / job.name / ARGUMENTS).is_file():
            WriteTextAtomically(output / "runs" / job.name / ARGUMENTS, _ArgumentsText(job))


def _RefuseOtherArguments(jobs: list[Job], output: pathlib.Path) -> None:
    mismatches = []
    for job in jobs:
        folder = output / "runs" / job.name
        if (folder / ARGUMENTS).is_file() or (folder.is_dir() and any(folder.iterdir())):
            mismatches.append(_Mismatch(job, output))
    if any(mismatches):
        raise _Refusal(
            output,
            "holds runs of other arguments",
            mismatches,
            "; use another output folder for these settings",
        )


def _Refusal(output: pathlib.Path, what: str, mismatches: list[str], advice: str = ""):
    """The refusal of a battery whose ``output`` holds runs of other arguments than its jobs'
    (``what``), naming the first three ``mismatches``."""
    mismatches = [m for m in mismatches if m]
    more = f" | and {len(mismatches) - 3} more" if len(mismatches) > 3 else ""
    return BatteryRefused(f"{output}: {what} ({' | '.join(mismatches[:3])}{more}){advice}")


def _SourceCommit() -> dict:
    """The git commit this package's files were imported from (``commit``) and whether they,
    or the models and diagrams the package ships from beside it, differ from it (``changed``);
    both None when they are not a git checkout's (an installed wheel, say) or git cannot
    tell."""
    package = pathlib.Path(__file__).resolve().parents[1]

    def Git(*arguments: str) -> str | None:
        try:
            done = subprocess.run(
                ["git", "--no-optional-locks", "-C", str(package), *arguments],
                capture_output=True, text=True, timeout=30,
            )  # fmt: skip
        except (OSError, subprocess.TimeoutExpired):
            return None
        return done.stdout if done.returncode == 0 else None

    if not Git("ls-files", "--", "__init__.py"):  # (not tracked: not a checkout's files)
        return dict(commit=None, changed=None)
    shipped = (".", "../models", "../diagrams")  # (pyproject.toml's package data)
    commit, status = Git("rev-parse", "HEAD"), Git("status", "--porcelain", "--", *shipped)
    return dict(
        commit=commit and commit.strip(), changed=None if status is None else bool(status.strip())
    )


def _RecordSession(output: pathlib.Path, backend: Backend) -> None:
    """Appends to ``output``'s :data:`SESSIONS` a line on this sitting of the battery: when it
    began, the package's version and source commit, the backend, the BLAS variables of the
    environment (the workers' thread counts follow from them, see the module) and the platform
    (:func:`~mobee_drake.experiments.platform_record.PlatformRecord`: this process's, which on
    Ray is the driver's, not the workers')."""
    record = dict(
        began=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        version=__version__,
        **_SourceCommit(),
        backend=repr(backend),
        blas_environment={name: os.environ.get(name) for name in BLAS_THREADS},
        platform=PlatformRecord(),
    )
    try:
        with open(output / SESSIONS, "a") as stream:
            stream.write(StrictJson(record) + "\n")
    except OSError as error:  # (a full disk's error names no file)
        raise OSError(error.errno, error.strerror, str(output / SESSIONS)) from None


def _RunJobs(
    jobs: list[Job], output: pathlib.Path, backend: Backend, progress: bool, description: str
) -> dict[str, dict]:
    names = [job.name for job in jobs]
    results = {job.name: _StoredResult(output, job.name) for job in jobs}
    queue = collections.deque(job for job in jobs if results[job.name] is None)
    if not queue:
        return results
    # Records of an interrupted battery would show bars for jobs not yet started.
    for job in queue:
        (output / "runs" / job.name / PROGRESS).unlink(missing_ok=True)
    errors = {}
    display = _Display(output, len(jobs), len(jobs) - len(queue), description, progress)
    try:
        with TerminationInterrupts(), backend.Session() as submit:
            _RecordSession(output, backend)
            running = {}
            while queue or running:
                while queue and len(running) < backend.capacity:
                    job = queue.popleft()
                    try:
                        running[submit(job, output)] = job
                    except Exception as error:  # A broken pool, say.
                        errors[job.name] = error
                finished, _ = concurrent.futures.wait(
                    running, POLL_SECONDS, concurrent.futures.FIRST_COMPLETED
                )
                for future in finished:
                    job = running.pop(future)
                    try:
                        results[job.name] = json.loads(future.result())
                    except Exception as error:
                        errors[job.name] = error
                        display.Failed(job.name, error)
                        if _DiskRefuses(error):  # Every later job's writes would fail too.
                            for waiting in queue:
                                errors[waiting.name] = NotStarted(f"not started: {error}")
                            queue.clear()
                display.Update(running.values(), len(finished))
    finally:
        display.Close()
    if errors:
        failures = [
            f"{name}: {type(errors[name]).__name__}: {errors[name]}"
            for name in names
            if name in errors
        ]
        raise BatteryError(
            f"{len(errors)} of {len(jobs)} jobs failed:\n" + "\n".join(failures)
        ) from next(iter(errors.values()))
    return results


def Provenance(output: str | pathlib.Path) -> str:
    """A line for a report: the package's version and a fingerprint of the arguments of every
    run in ``output`` (the SHA-256 of their ``job.json`` files, in name order)."""
    digest = hashlib.sha256()
    for path in sorted(pathlib.Path(output).glob(f"runs/*/{ARGUMENTS}")):
        digest.update(path.parent.name.encode() + b"\0" + path.read_bytes())
    return f"mobee-drake {__version__}; the runs' arguments: sha256 {digest.hexdigest()[:16]}"


# How long a cluster's address may take to accept a connection before --ray refuses it.
RAY_CONNECT_SECONDS = 10.0


def RayAddress(text: str) -> str:
    """``--ray``'s address, checked before any work (``ray.init`` waits for an address that does
    not answer for minutes, printing warnings): "auto" (Ray finds the local cluster), or
    ``[ray://]host:port`` of a cluster that accepts a connection; "" (the bare flag) for a local
    Ray instance."""
    if text in ("", "auto"):
        return text
    match = re.fullmatch(r"(?:ray://)?(\[[^\]]+\]|[^:/\s]+):(\d{1,5})", text)
    if match is None or not 0 < int(match[2]) < 65536:
        raise argparse.ArgumentTypeError(f"must be auto or [ray://]host:port, got '{text}'")
    host, port = match[1].strip("[]"), int(match[2])
    try:
        socket.create_connection((host, port), timeout=RAY_CONNECT_SECONDS).close()
    except OSError as error:
        reason = "timed out" if isinstance(error, TimeoutError) else error.strerror or str(error)
        raise argparse.ArgumentTypeError(
            f"no Ray cluster answers at {host}:{port} ({reason})"
        ) from None
    return text


def AddBackendArguments(parser, workers: int = 1) -> None:
    """Adds ``--workers`` and ``--ray [ADDRESS]`` to an experiment's command line."""
    parser.add_argument(
        "--workers",
        type=PositiveInt,
        default=workers,
        help="local worker processes",
    )
    parser.add_argument(
        "--ray",
        nargs="?",
        const="",
        default=None,
        type=RayAddress,
        metavar="ADDRESS",
        help="run on Ray instead: a cluster's address, or none for a local Ray instance "
        '(needs pip install "mobee-drake[ray]")',
    )


def BackendOf(args) -> Backend:
    """The backend an experiment's command line asks for (see :func:`AddBackendArguments`)."""
    if args.ray is not None:
        return Ray(address=args.ray or None)
    return LocalProcesses(args.workers)
