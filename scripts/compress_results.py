"""Stores the arrays of a battery's finished runs compressed: every ``.npz`` file under a
``runs/<job>/`` folder that has its ``result.json`` and holds an uncompressed member is
written again as :func:`~mobee_drake.array_files.WriteArrays` writes them, deflated (the same
arrays; ``np.load`` reads either).

Runs written before the checkpoints were compressed hold their learned models' dense counts
as they are in memory (a rank-4 maintained exploration's 8.8 MB against 0.13 MB deflated).
Running and pending runs are left alone: their battery may be writing them.

Run: ``python scripts/compress_results.py FOLDER [FOLDER ...]`` (battery folders, e.g.
``docs/results/adaptive_space``); prints the bytes before and after.
"""

import argparse
import pathlib
import zipfile

import numpy as np

from mobee_drake.array_files import DAMAGED, WriteArrays
from mobee_drake.atomic_files import WriteFileAtomically
from mobee_drake.experiments.battery import RESULT


def IsCompressed(path: pathlib.Path) -> bool:
    """Whether every member of the ``.npz`` file ``path`` is compressed."""
    with zipfile.ZipFile(path) as archive:
        return all(m.compress_type != zipfile.ZIP_STORED for m in archive.infolist())


def _OfArrays(path: pathlib.Path) -> bool:
    """Whether every member of the zip file ``path`` is an array (``.npy``), as np.savez writes
    them; another member would come back an array of bytes."""
    with zipfile.ZipFile(path) as archive:
        return all(m.filename.endswith(".npy") for m in archive.infolist())


def Compress(path: pathlib.Path) -> None:
    """Writes the ``.npz`` file ``path`` again, compressed, through a staging file."""
    with np.load(path, allow_pickle=False) as saved:
        arrays = {name: saved[name] for name in saved.files}

    WriteFileAtomically(path, lambda staging: WriteArrays(staging, **arrays))


def CompressFinishedRuns(folder: pathlib.Path) -> tuple[int, int, list[str]]:
    """Compresses the uncompressed ``.npz`` files of ``folder``'s finished runs; their bytes
    before and after, and the files left as they were, each with why (not arrays alone, or
    unreadable)."""
    before, after, left = 0, 0, []
    for result in sorted(folder.glob(f"runs/*/{RESULT}")):
        for path in sorted(result.parent.rglob("*.npz")):
            try:
                if IsCompressed(path):
                    continue
                if not _OfArrays(path):
                    left.append(f"{path}: not arrays alone")
                    continue
                size = path.stat().st_size
                Compress(path)
            except DAMAGED as error:
                left.append(f"{path}: {error}")
                continue
            before, after = before + size, after + path.stat().st_size
    return before, after, left


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("folders", nargs="+", type=pathlib.Path)
    args = parser.parse_args()
    for folder in args.folders:
        if not (folder / "runs").is_dir():
            parser.error(f"{folder}: not a battery folder (no runs/)")
        before, after, left = CompressFinishedRuns(folder)
        print(f"{folder}: {before / 1e6:.1f} MB of uncompressed arrays now {after / 1e6:.1f} MB")
        for line in left:
            print(f"left as it was: {line}")


if __name__ == "__main__":
    main()
