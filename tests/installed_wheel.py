"""The package as a user installs it: a wheel built from the repository and installed into a
folder of its own (once per test session), and the docs' commands and examples run against it in
an empty folder, as written."""

import atexit
import functools
import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
# A docs command is given this long to finish.
TIMEOUT = 600


@functools.cache
def InstalledWheel() -> tuple[pathlib.Path, pathlib.Path]:
    """(the wheel, the folder it is installed into), built once and removed at exit."""
    folder = pathlib.Path(tempfile.mkdtemp(prefix="mobee_wheel_"))
    atexit.register(shutil.rmtree, folder, True)
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q",
         "-w", str(folder / "dist"), str(ROOT)],
        check=True,
    )  # fmt: skip
    (wheel,) = (folder / "dist").glob("mobee_drake-*.whl")
    site = folder / "site"
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(site),
         str(wheel)],
        check=True,
    )  # fmt: skip
    return wheel, site


def Environment() -> dict[str, str]:
    """The environment in which ``import mobee_drake`` finds the installed wheel first."""
    return {**os.environ, "PYTHONPATH": str(InstalledWheel()[1])}


def _Run(command: list[str], cwd: pathlib.Path, stdout=None) -> subprocess.CompletedProcess:
    run = subprocess.run(
        command,
        cwd=cwd,
        env=Environment(),
        stdout=stdout or subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        timeout=TIMEOUT,
    )
    if run.returncode != 0:
        raise AssertionError(f"{shlex.join(command)} failed ({run.returncode}):\n{run.stderr}")
    return run


def RunCommandLine(line: str, cwd: pathlib.Path) -> str:
    """Runs a line of a docs' shell block as a user with the wheel installed would: the venv and
    ``pip install`` steps are the installed wheel, ``mobee-drake`` (or ``.venv/bin/mobee-drake``)
    is its command line, ``> FILE`` redirects; returns what it printed."""
    printed = []
    for part in line.split("#", 1)[0].split("&&"):
        words = shlex.split(part)
        if not words or words[0] in ("python3", ".venv/bin/pip"):  # installing: done already
            continue
        if words[0] not in ("mobee-drake", ".venv/bin/mobee-drake"):
            raise AssertionError(f"a docs command this test cannot run: {part.strip()}")
        command = [sys.executable, "-m", "mobee_drake.cli", *words[1:]]
        if ">" in words:
            at = words.index(">")
            with open(cwd / words[at + 1], "w") as out:
                _Run(command[: at + 2], cwd, stdout=out)  # words[at] is command[at + 2]
        else:
            printed.append(_Run(command, cwd).stdout)
    return "".join(printed)


def RunPython(code: str, cwd: pathlib.Path) -> str:
    """Runs a docs' Python example with the installed wheel; returns what it printed."""
    return _Run([sys.executable, "-c", code], cwd).stdout


def CodeBlocks(text: str) -> list[tuple[str, str]]:
    """The fenced code blocks of a Markdown text, in order: (language, code), unindented."""
    blocks = []
    for indent, language, code in re.findall(r"(?m)^( *)```(\w*)\n(.*?)^ *```", text, re.S):
        lines = code.splitlines()
        blocks.append((language, "\n".join(line.removeprefix(indent) for line in lines)))
    return blocks
