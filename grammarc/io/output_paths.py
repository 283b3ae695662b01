"""The paths a build will write, checked before it derives anything.

A build that cannot write its output should say so at once, not after deriving the whole city: every path
it will write (the output, the files and folders its writer puts beside it, the reports) is checked first,
and the first problem is a ``UsageError`` (exit 2) naming the path and the reason:

- the path is an existing folder (an output file cannot replace it);
- a folder above it is a file;
- the nearest existing folder above it is not writable (a missing folder below it is made by the build);
- its name is longer than the file system allows (``atomic.NAME_MAX`` bytes). The temporary folders of
  atomic writing cut the output's name (``atomic.private_folder``), so every legal name is writable.

What happens to the disk later (it fills, a folder's permissions change) is an ``OSError`` the command
reports in one line (``cli.main``).
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

from grammarc.atomic import NAME_MAX
from grammarc.errors import UsageError

__all__ = ["check_writable"]


def check_writable(files: Iterable[Path], folders: Iterable[Path] = ()) -> None:
    """Raise a ``UsageError`` for the first of ``files`` (to be written as files) or ``folders`` (to be
    made as folders, replacing any there) that cannot be written; see the module docstring."""
    for path, is_file in [*((Path(f), True) for f in files), *((Path(f), False) for f in folders)]:
        problem = _problem(path, is_file)
        if problem is not None:
            raise UsageError(f"cannot write `{path}`: {problem}")


def _problem(path: Path, is_file: bool) -> str | None:
    """Why ``path`` cannot be written, or None."""
    size = len(os.fsencode(path.name))
    if size > NAME_MAX:
        return f"its name is {size} bytes long, longer than the {NAME_MAX} a file name may have"
    if is_file and path.is_dir():
        return "it is a folder"
    folder = path.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        return f"`{folder}` is a file, not a folder"
    if not os.access(folder, os.W_OK | os.X_OK):
        return f"the folder `{folder}` is not writable"
    return None
