"""Files and folders written so that a crash never leaves half of one: the one atomic writer.

Each writer stages its output beside the destination (same file system) and renames it into
place with :func:`os.replace`, so a reader sees the old whole or the new whole, never a part.
"""

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


def WriteFolderAtomically(folder: str | pathlib.Path, write) -> None:
    """Calls ``write(staging)`` on a new folder beside ``folder``, then renames it into place, so
    that ``folder`` is always either the old or the new whole."""
    folder = pathlib.Path(folder)
    folder.parent.mkdir(parents=True, exist_ok=True)
    staging = pathlib.Path(tempfile.mkdtemp(dir=folder.parent, prefix=f".{folder.name}-"))
    try:
        write(staging)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    if folder.exists():
        old = folder.with_name(f".{folder.name}-old")
        shutil.rmtree(old, ignore_errors=True)
        os.replace(folder, old)
        os.replace(staging, folder)
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.replace(staging, folder)


def PublishFolder(staging: pathlib.Path, folder: pathlib.Path) -> bool:
    """Renames a complete ``staging`` folder to ``folder`` unless another writer got there
    first (then ``staging`` is removed); returns whether this writer's copy is the one in place.
    For caches whose entries, once written, never change."""
    try:
        os.replace(staging, folder)
        return True
    except OSError:
        shutil.rmtree(staging, ignore_errors=True)
        if not folder.exists():
            raise
        return False
