"""The ``.npz`` files of checkpoints, learned models and roadmaps: :func:`WriteArrays`.

A learned model's transition counts are a dense array of mostly zeros (a rank-4 exploration's
1536 state-actions by 256 states), rewritten with every checkpoint. Deflated at level 1 they
take about a fortieth of the space (a rank-4 lattice's or a roadmap's model; a rank-3
lattice's, smaller and denser, about a seventh) for a little more time
than an uncompressed write (zlib's default level takes about three times as long for a fifth
less), so a run's folders stay small without slowing the run. ``np.load`` reads them as it
reads ``np.savez``'s.
"""

from tokenize import TokenError
import zipfile
import zlib

import numpy as np

# What reading a damaged .npz raises: a truncated or altered zip, a damaged deflate stream, or a
# damaged array header.
DAMAGED = (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error, SyntaxError, TokenError)


def WriteArrays(file, **arrays) -> None:
    """Writes ``arrays`` (name: array) to ``file`` (a path or a binary file object) as an
    ``.npz``, each array a member ``<name>.npy`` deflated at level 1. Object arrays are refused
    (ValueError), as ``np.load`` refuses them by default."""
    with zipfile.ZipFile(file, "w", compression=zipfile.ZIP_DEFLATED, compresslevel=1) as archive:
        for name, value in arrays.items():
            with archive.open(f"{name}.npy", "w", force_zip64=True) as member:
                np.lib.format.write_array(member, np.asanyarray(value), allow_pickle=False)
