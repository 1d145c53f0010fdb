"""Jobs for tests/test_battery.py, in a module of their own so that spawned workers and Ray
workers import them by name (with ``tests/`` on their PYTHONPATH); and the battery the no-orphans
tests run in a process of their own (:func:`Main`, run as
``python -c "import battery_jobs; battery_jobs.Main(...)"`` so that its jobs are this module's)."""

import ctypes
import errno
import json
import os
import pathlib
import signal
import time

import numpy as np

from mobee_drake.atomic_files import WriteJsonAtomically, WriteTextAtomically
from mobee_drake.experiments.battery import (
    BLAS_THREADS,
    Job,
    JobStopped,
    LocalProcesses,
    Ray,
    RunBattery,
    StopRequested,
)


def DefaultSigint() -> None:
    """A child's ``preexec_fn``: Ctrl-C acts on it as in a terminal, even when the tests run in a
    shell's background job, whose children inherit SIGINT ignored (Python then installs no
    KeyboardInterrupt handler)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def Count(run, x: int, calls: str) -> dict:
    """Appends the run's name to the file ``calls``; returns numbers of ``x``."""
    with open(calls, "a") as stream:
        stream.write(run.path.name + "\n")
    return dict(square=x * x, third=x / 3)


def FullDisk(run, calls: str) -> dict:
    """Appends the run's name to ``calls``, then fails as a write to a full disk does."""
    with open(calls, "a") as stream:
        stream.write(run.path.name + "\n")
    raise OSError(errno.ENOSPC, "No space left on device", str(run.path / "result.json"))


def BlasThreads(run) -> dict:
    """The BLAS thread counts the worker's environment names, and the threads numpy's OpenBLAS
    uses (None if numpy was built with another BLAS)."""
    names = {name: os.environ.get(name) for name in BLAS_THREADS}
    libraries = [line.split()[-1] for line in open("/proc/self/maps") if "openblas" in line]
    for symbol in ("scipy_openblas_get_num_threads64_", "openblas_get_num_threads"):
        for library in libraries:
            if hasattr(ctypes.CDLL(library), symbol):
                return dict(names, openblas=getattr(ctypes.CDLL(library), symbol)())
    return dict(names, openblas=None)


def Nan(run) -> dict:
    return dict(value=float("nan"))


def Walk(run, steps: int, seed: int, die_at: int | None = None, pause: float = 0.0) -> dict:
    """A random walk of ``steps`` steps, checkpointed after each with its generator's state; the
    first attempt that reaches step ``die_at`` SIGKILLs its own process."""
    checkpoint, died = run.path / "checkpoint.json", run.path / "died"
    rng, step, position = np.random.default_rng(seed), 0, 0.0
    if checkpoint.is_file():
        saved = json.loads(checkpoint.read_text())
        step, position, rng.bit_generator.state = saved["step"], saved["position"], saved["rng"]
    while step < steps:
        if step == die_at and not died.exists():
            died.touch()
            os.kill(os.getpid(), signal.SIGKILL)
        position += rng.normal()
        step += 1
        time.sleep(pause)
        WriteJsonAtomically(
            checkpoint, dict(step=step, position=position, rng=rng.bit_generator.state)
        )
        run.Progress(step)
    return dict(steps=step, position=position, next=rng.normal())


def Sleep(run, pids: str, seconds: float, cooperative: bool = True) -> dict:
    """Writes its process id to ``pids/<run name>``, then sleeps; a cooperative sleeper stops
    when the battery asks (:func:`StopRequested`), the other only when killed."""
    WriteTextAtomically(pathlib.Path(pids) / run.path.name, str(os.getpid()))
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if cooperative and StopRequested():
            raise JobStopped(run.path.name)
        time.sleep(0.05)
    return dict(seconds=seconds)


def Main(backend: str, output: str, pids: str) -> None:
    """A quick job and two that sleep for ten minutes, on ``backend`` ("local" or "ray")."""
    jobs = [Job("quick", Sleep, dict(pids=pids, seconds=0))]
    jobs += [Job(f"sleeper{i}", Sleep, dict(pids=pids, seconds=600)) for i in range(2)]
    RunBattery(
        jobs, output, backend=LocalProcesses(3) if backend == "local" else Ray(), progress=False
    )


def StopWalk(run, steps: int, seed: int, pause: float) -> dict:
    """A random walk that saves its checkpoint only when the battery asks it to stop."""
    checkpoint = run.path / "checkpoint.json"
    rng, step, position = np.random.default_rng(seed), 0, 0.0
    if checkpoint.is_file():
        saved = json.loads(checkpoint.read_text())
        step, position, rng.bit_generator.state = saved["step"], saved["position"], saved["rng"]
    while step < steps:
        position += rng.normal()
        step += 1
        run.Progress(step)
        time.sleep(pause)
        if StopRequested():
            WriteJsonAtomically(
                checkpoint, dict(step=step, position=position, rng=rng.bit_generator.state)
            )
            raise JobStopped(f"stopped at step {step}")
    return dict(steps=step, position=position, next=rng.normal())
