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

__all__ = ["NAME_MAX", "private_folder", "remove_stale", "replace_folder", "replacing"]

#: The longest file name, in bytes, of the file systems grammarc writes to (Linux, macOS and Windows alike).
NAME_MAX = 255
#: The bytes of an output's name its temporary folder keeps: with ``.``, ``.tmp``, a process id and
#: ``mkdtemp``'s eight characters the folder's name stays under ``NAME_MAX`` whatever the output's is.
_NAME_KEPT = 200


def private_folder(path: Path) -> str:
    """A new private folder beside ``path`` for the temporary files of its writing (the same filesystem,
    for the rename): ``.<name>.tmp<pid>-<random>``, the name cut to its first 200 bytes so that an output
    whose name is legal has a legal temporary folder too. The folders that runs which died (a SIGKILL, a
    power cut: their process is gone) left for the same output are removed first."""
    path = Path(path)
    prefix = f".{_kept(path.name)}.tmp"
    remove_stale(path.parent, prefix)
    return tempfile.mkdtemp(prefix=f"{prefix}{os.getpid()}-", dir=path.parent)


def _kept(name: str) -> str:
    """``name`` cut to its first ``_NAME_KEPT`` bytes."""
    return os.fsdecode(os.fsencode(name)[:_NAME_KEPT])


def remove_stale(folder: Path, prefix: str) -> None:
    """Remove the entries ``<prefix><pid>-...`` of ``folder`` whose process ``pid`` no longer runs."""
    for entry in Path(folder).glob(f"{prefix}*-*"):
        pid = entry.name[len(prefix):].split("-", 1)[0]
        if pid.isdigit() and not _running(int(pid)):
            shutil.rmtree(entry, ignore_errors=True)


def _running(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's: alive
        return True
    return True


@contextlib.contextmanager
def replacing(path: Path):
    """The path to write ``path``'s new contents at: a file of the same name in a private folder beside it
    (the same filesystem, for the rename; the umask's permissions, which ``mkstemp`` would not give; the
    suffix kept, for writers that pick a format by it). When the block ends the file is fsynced and moved
    onto ``path``; the folder goes whatever happens, so a failed write leaves ``path`` as it was."""
    folder = private_folder(path)
    try:
        tmp = Path(folder) / path.name
        yield tmp
        with open(tmp, "rb") as file:
            os.fsync(file.fileno())
        os.replace(tmp, path)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def replace_folder(new: Path, path: Path, aside: Path) -> None:
    """Move the complete folder ``new`` onto ``path`` (the same filesystem). A folder already at ``path`` is
    first moved to ``aside`` (a name in a private folder) and removed after, so ``path`` is the old folder,
    then for an instant nothing, then the new one; never a mix of the two."""
    if path.is_dir():
        os.replace(path, aside)
    os.replace(new, path)
    shutil.rmtree(aside, ignore_errors=True)
