"""Files and folders written so that a crash never leaves half of one: the one atomic writer.

Each writer stages its output beside the destination (same file system) and renames it into
place with :func:`os.replace`, so a reader sees the old whole or the new whole, never a part.
"""

import contextlib
import json
import os
import pathlib
import shutil
import tempfile


def WriteTextAtomically(path: str | pathlib.Path, text: str) -> None:
    """Writes ``text`` to ``path`` through a staging file in the same folder."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, staging = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(handle, "w") as stream:
            stream.write(text)
        os.replace(staging, path)
    except BaseException:
        pathlib.Path(staging).unlink(missing_ok=True)
        raise


def WriteJsonAtomically(path: str | pathlib.Path, data) -> None:
    """Writes ``data`` as JSON to ``path`` (see :func:`WriteTextAtomically`)."""
    WriteTextAtomically(path, json.dumps(data))


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


def WriteFolderAtomically(folder: str | pathlib.Path, write) -> None:
    """Calls ``write(staging)`` on a new folder beside ``folder``, then renames it into place, so
    that ``folder`` is always either the old or the new whole."""
    folder = pathlib.Path(folder)
    with _StagedFolder(folder) as staging:
        write(staging)
    if folder.exists():
        old = folder.with_name(f".{folder.name}-old")
        shutil.rmtree(old, ignore_errors=True)
        os.replace(folder, old)
        os.replace(staging, folder)
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.replace(staging, folder)


def WriteFolderOnce(folder: str | pathlib.Path, write) -> None:
    """As :func:`WriteFolderAtomically`, for a cache entry that never changes once written: when
    another writer put its whole copy in place first, that copy stays and this one is dropped."""
    folder = pathlib.Path(folder)
    with _StagedFolder(folder) as staging:
        write(staging)
    try:
        os.replace(staging, folder)
    except OSError:
        shutil.rmtree(staging, ignore_errors=True)
        if not folder.is_dir():
            raise
