"""Files and folders written so that a crash never leaves half of one: the one atomic writer.

Each writer stages its output beside the destination (same file system) and renames it into
place with :func:`os.replace`, so a reader sees the old whole or the new whole, never a part.

Checkpoints, which a run rewrites again and again, are *generations*
(:func:`WriteGeneration`, :func:`CurrentGeneration`): a folder holds complete generations
``g000001``, ``g000002``, ... A write stages the new generation in a hidden folder, renames it
to its final name (one atomic step: from then on it is complete and the newest), and only then
removes the older generations. A kill at any moment leaves at least one complete generation, and
the reader takes the highest-numbered one; half-written staging and half-removed old generations
are ignored, and cleared by the next write.
"""

import contextlib
import glob
import json
import os
import pathlib
import re
import shutil
import tempfile


def _Umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _Named(error: BaseException, path: pathlib.Path) -> BaseException:
    """``error`` as the caller should see it: a failed write of the system's (a full disk) named
    by the file or folder meant, not by a staging file or by nothing; anything else as it is."""
    if isinstance(error, OSError) and error.errno is not None:
        return OSError(error.errno, error.strerror, str(path))  # (the errno's subclass)
    return error


def WriteFileAtomically(path: str | pathlib.Path, write) -> None:
    """Writes ``path`` through a staging file in the same folder: ``write(staging)`` writes the
    staging file (a path), which then replaces ``path``."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, staging = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(handle)
    try:
        write(staging)
        os.chmod(staging, 0o666 & ~_Umask())  # As open() would have made it (mkstemp: 0o600).
        os.replace(staging, path)
    except BaseException as error:
        pathlib.Path(staging).unlink(missing_ok=True)
        raise _Named(error, path) from error
    # What a kill left of earlier writes of this file (one writer a file: folders are locked).
    for leftover in path.parent.glob(f".{glob.escape(path.name)}.*.tmp"):
        leftover.unlink(missing_ok=True)


def WriteTextAtomically(path: str | pathlib.Path, text: str) -> None:
    """Writes ``text`` to ``path`` (see :func:`WriteFileAtomically`)."""
    WriteFileAtomically(path, lambda staging: pathlib.Path(staging).write_text(text))


def StrictJson(data, **options) -> str:
    """``data`` as strict JSON (no NaN or Infinity, which JSON has not: a ValueError instead);
    ``options`` as for :func:`json.dumps`. Every JSON file the package writes goes through it."""
    return json.dumps(data, allow_nan=False, **options)


def WriteJsonAtomically(path: str | pathlib.Path, data) -> None:
    """Writes ``data`` as strict JSON to ``path`` (see :func:`WriteTextAtomically`)."""
    WriteTextAtomically(path, StrictJson(data))


@contextlib.contextmanager
def _StagedFolder(folder: pathlib.Path):
    """A new folder beside ``folder`` (same file system), removed if the block fails."""
    folder.parent.mkdir(parents=True, exist_ok=True)
    staging = pathlib.Path(tempfile.mkdtemp(dir=folder.parent, prefix=f".{folder.name}-"))
    try:
        yield staging
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise


def WriteFolderOnce(folder: str | pathlib.Path, write) -> None:
    """Calls ``write(staging)`` on a new folder beside ``folder``, then renames it to ``folder``:
    for a cache entry that never changes once written. When another writer put its whole copy in
    place first, that copy stays and this one is dropped."""
    folder = pathlib.Path(folder)
    with _StagedFolder(folder) as staging:
        write(staging)
    try:
        os.replace(staging, folder)
    except OSError:
        shutil.rmtree(staging, ignore_errors=True)
        if not folder.is_dir():
            raise


_GENERATION = re.compile(r"g(\d{6})")


def _Generations(folder: pathlib.Path) -> list[pathlib.Path]:
    """The generations in ``folder``, oldest first."""
    if not folder.is_dir():
        return []
    found = [p for p in folder.iterdir() if p.is_dir() and _GENERATION.fullmatch(p.name)]
    return sorted(found, key=lambda p: p.name)


def _Step(name: str) -> None:
    """A point between two steps of :func:`WriteGeneration`, where the tests inject kills."""


def CurrentGeneration(folder: str | pathlib.Path) -> pathlib.Path | None:
    """The newest complete generation of ``folder`` (None when it holds none)."""
    generations = _Generations(pathlib.Path(folder))
    return generations[-1] if generations else None


def WriteGeneration(folder: str | pathlib.Path, write) -> pathlib.Path:
    """Calls ``write(staging)`` on a new folder inside ``folder``, makes it the newest complete
    generation and removes the older ones and any staging a kill left; returns the generation."""
    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    generations = _Generations(folder)
    number = int(_GENERATION.fullmatch(generations[-1].name).group(1)) + 1 if generations else 1
    generation = folder / f"g{number:06d}"
    staging = pathlib.Path(tempfile.mkdtemp(dir=folder, prefix=".staging-"))
    try:
        write(staging)
    except BaseException as error:
        shutil.rmtree(staging, ignore_errors=True)
        raise _Named(error, folder) from error
    _Step("staged")
    os.rename(staging, generation)
    _Step("renamed")
    for old in generations:
        shutil.rmtree(old, ignore_errors=True)
        _Step("pruned one")
    for leftover in folder.glob(".staging-*"):
        shutil.rmtree(leftover, ignore_errors=True)
    return generation
