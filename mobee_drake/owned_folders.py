"""Folders a run writes into: never one that holds what we did not write, never two writers.

A checkpoint or battery folder is *claimed* before anything is written: it is created if it does
not exist, taken if it is empty or already carries our marker file (``.mobee-drake``, naming the
folder's kind), and refused otherwise (a user's folder, a file, a folder of another kind), with
an error that names it. While a run writes, it holds an exclusive lock on the folder
(``flock`` on ``.mobee-drake.lock``, released by the kernel if the process dies), so a second
writer is refused instead of racing the first.
"""

import contextlib
import fcntl
import json
import os
import pathlib
import tempfile

from mobee_drake.atomic_files import StrictJson, WriteTextAtomically

MARKER = ".mobee-drake"
_LOCK = ".mobee-drake.lock"


class FolderError(ValueError):
    """A folder that a run may not write into; the message names it and why."""


def ClaimFolder(folder: str | pathlib.Path, kind: str) -> pathlib.Path:
    """Makes ``folder`` ours for ``kind`` ("checkpoint", "battery") or raises FolderError."""
    folder = pathlib.Path(folder)
    if folder.exists() and not folder.is_dir():
        raise FolderError(f"{folder}: is a file, not a folder for a {kind}")
    marker = folder / MARKER
    if marker.is_file():
        try:
            found = json.loads(marker.read_text())["kind"]
        except (OSError, ValueError, KeyError, TypeError):
            raise FolderError(
                f"{marker}: not a marker that mobee-drake wrote (empty or damaged); if "
                f"{folder} holds only a run of yours, delete {marker} to claim it again"
            ) from None
        if found != kind:
            raise FolderError(f"{folder}: holds a {found}, not a {kind}")
        return folder
    try:
        folder.mkdir(parents=True, exist_ok=True)
        # (A staging file of the marker is a claim that a kill interrupted.)
        others = [
            p.name
            for p in folder.iterdir()
            if p.name != _LOCK and not (p.name.startswith(f"{MARKER}.") and p.name.endswith(".tmp"))
        ]
    except OSError as error:
        raise FolderError(f"{folder}: cannot be used: {error.strerror}") from None
    if others:
        raise FolderError(
            f"{folder}: not empty and not a mobee-drake {kind} (it holds "
            f"{', '.join(sorted(others)[:3])}{', ...' if len(others) > 3 else ''}); "
            "choose an empty or new folder"
        )
    try:
        WriteTextAtomically(marker, StrictJson({"kind": kind}))  # never a half-written marker
    except OSError as error:
        raise FolderError(f"{folder}: cannot be written: {error.strerror}") from None
    return folder


@contextlib.contextmanager
def OwnedFolder(folder: str | pathlib.Path, kind: str):
    """Claims ``folder`` for ``kind`` and holds its lock while the context lasts."""
    folder = ClaimFolder(folder, kind)
    handle = os.open(folder / _LOCK, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise FolderError(f"{folder}: in use by another run") from None
        yield folder
    finally:
        os.close(handle)


def CanWrite(path: str | pathlib.Path) -> bool:
    """Whether a file can be written at ``path`` now (its folder made if missing): tried with a
    small file beside it, removed again."""
    path = pathlib.Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(
            dir=path.parent, prefix=f".{path.name}.", suffix=".probe"
        ) as probe:
            probe.write(b"probe")
            probe.flush()
        return not path.is_dir()
    except OSError:
        return False
