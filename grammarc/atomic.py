"""Files that appear complete or not at all: written beside their place, fsynced, renamed onto it.

On the bottom floor, beside ``ragged``: the record writers, the renderer and the derivation's reports all
write files this way, and none of them may depend on another for it.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
from pathlib import Path

__all__ = ["replacing"]


@contextlib.contextmanager
def replacing(path: Path):
    """The path to write ``path``'s new contents at: a file of the same name in a private folder beside it
    (the same filesystem, for the rename; the umask's permissions, which ``mkstemp`` would not give; the
    suffix kept, for writers that pick a format by it). When the block ends the file is fsynced and moved
    onto ``path``; the folder goes whatever happens, so a failed write leaves ``path`` as it was."""
    folder = tempfile.mkdtemp(prefix=f".{path.name}.tmp", dir=path.parent)
    try:
        tmp = Path(folder) / path.name
        yield tmp
        with open(tmp, "rb") as file:
            os.fsync(file.fileno())
        os.replace(tmp, path)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
