"""What a result was computed on, for its record beside the commit: the Python, numpy, scipy and
Drake versions, each BLAS loaded with the kernel it chose at run time, and the CPU.

Runs repeat exactly on one machine and library build, but a long simulation can turn on the
last bit of a sum, so the same code on another build, or with another BLAS kernel (another CPU,
or ``OPENBLAS_CORETYPE``), can count a few penetrating periods more or fewer (docs/mobee.md,
"Reading the tables"): the record lets a reader tell such a drift from a change of code."""

import importlib.metadata
import json
import pathlib
import platform
import sys

from threadpoolctl import threadpool_info


def _Version(package: str) -> str | None:
    try:
        return importlib.metadata.version(package)
    except importlib.metadata.PackageNotFoundError:
        return None


def _Blas() -> list[dict]:
    """Each BLAS numpy and scipy loaded (scipy ships its own): its library, version and the
    kernel it chose at run time (``architecture``: from the CPU, or ``OPENBLAS_CORETYPE``), in
    the libraries' order (not the order they were loaded in)."""
    import numpy  # noqa: F401
    import scipy.linalg  # noqa: F401

    loaded = [
        dict(
            library=pathlib.Path(info["filepath"]).name,
            version=info.get("version"),
            architecture=info.get("architecture"),
        )
        for info in threadpool_info()
        if info.get("user_api") == "blas"
    ]
    return sorted(loaded, key=lambda blas: blas["library"])


def _Cpu() -> str:
    """The CPU: its model name, family, model and stepping (Linux's /proc/cpuinfo; the
    platform's processor elsewhere)."""
    fields = {}
    try:
        for line in pathlib.Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            fields.setdefault(key.strip(), value.strip())
    except OSError:
        pass
    if "model name" not in fields:
        return platform.processor() or platform.machine()
    return (
        f"{fields['model name']} (family {fields.get('cpu family')}, model "
        f"{fields.get('model')}, stepping {fields.get('stepping')})"
    )


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


def RecordSitting(folder: pathlib.Path) -> str:
    """For a battery run by code older than the record: appends to ``folder``'s
    ``platforms.jsonl`` a line on its last sitting (its ``began`` from the battery's
    ``sessions.jsonl``, and this process's platform, which must be the sitting's); the line."""
    sittings = (folder / "sessions.jsonl").read_text().splitlines()
    line = json.dumps({"began": json.loads(sittings[-1])["began"], "platform": PlatformRecord()})
    with open(folder / "platforms.jsonl", "a") as stream:
        stream.write(line + "\n")
    return line


if __name__ == "__main__":  # python -m ...platform_record [BATTERY_FOLDER]
    if len(sys.argv) > 1:
        print(RecordSitting(pathlib.Path(sys.argv[1])))
    else:
        print(json.dumps(PlatformRecord()))
