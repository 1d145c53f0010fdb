"""What a result was computed on, for its record beside the commit: the Python, numpy, scipy and
Drake versions, numpy's BLAS and the CPU.

Runs repeat exactly on one machine and library build, but a long simulation can turn on the
last bit of a sum, so the same code on another build can count a few penetrating periods more
or fewer (docs/mobee.md, "Reading the tables"): the record lets a reader tell such a drift from
a change of code."""

import importlib.metadata
import json
import pathlib
import platform


def _Version(package: str) -> str | None:
    try:
        return importlib.metadata.version(package)
    except importlib.metadata.PackageNotFoundError:
        return None


def _Blas() -> str | None:
    """The BLAS numpy was built with, as its build describes it (OpenBLAS's configuration
    names its kernels)."""
    import numpy as np

    try:
        blas = np.show_config(mode="dicts")["Build Dependencies"]["blas"]
    except (KeyError, TypeError):
        return None
    return blas.get("openblas configuration") or f"{blas.get('name')} {blas.get('version')}"


def _Cpu() -> str:
    """The CPU's model name (Linux's /proc/cpuinfo; the platform's processor elsewhere)."""
    try:
        for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def PlatformRecord() -> dict:
    """This process's platform, for a result's record (plain JSON)."""
    return dict(
        python=platform.python_version(),
        numpy=_Version("numpy"),
        scipy=_Version("scipy"),
        drake=_Version("drake"),
        blas=_Blas(),
        cpu=_Cpu(),
    )


if __name__ == "__main__":  # (a line for the record of a battery run from older code)
    print(json.dumps(PlatformRecord()))
