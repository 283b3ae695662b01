"""Files kept between runs in the user's own cache folder, and loaded only if nobody else could have
written them.

What is kept (an LALR parser's tables, a file's lowered statements) is a pickle, or a fused region's
code object (``backend.fusion.compiled``), and loading either runs what it says: so files live in
``$XDG_CACHE_HOME/grammarc`` (by default ``~/.cache/grammarc``), a folder created ``0700``, never in the
shared temp folder; a file is loaded only if that folder and the file belong to the user and nobody else
can write them, and it is written atomically (a temporary file renamed over it), so that a reader never
sees half a file. A cache that cannot be used is no error: the
caller computes what it would have held.
"""

from __future__ import annotations

import hashlib
import os
import stat
import sys
import tempfile
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import BinaryIO, TypeVar

import grammarc

T = TypeVar("T")


def cache_home() -> str:
    """The user's cache folder: ``$XDG_CACHE_HOME``, or ``~/.cache`` where it is unset or relative (the XDG
    rule: a relative path is ignored)."""
    base = os.environ.get("XDG_CACHE_HOME", "")
    return base if os.path.isabs(base) else os.path.join(os.path.expanduser("~"), ".cache")


def cache_folder(*parts: str) -> Path | None:
    """``cache_home()/grammarc[/parts...]``, created ``0700``; ``None`` if it cannot be made, is not a folder
    of the user's own (a link, another owner), or others may write into it or into the folders between."""
    folder = Path(cache_home()) / "grammarc"
    for name in (None, *parts):
        folder = folder / name if name else folder
        try:
            folder.mkdir(mode=0o700, parents=True, exist_ok=True)
            info = os.lstat(folder)
        except OSError:
            return None
        if not stat.S_ISDIR(info.st_mode) or not _private(info):
            return None
    return folder


def _private(info: os.stat_result) -> bool:
    """Owned by the user, writable by nobody else."""
    return info.st_uid == os.getuid() and not info.st_mode & (stat.S_IWGRP | stat.S_IWOTH)


def load(path: Path, read: Callable[[BinaryIO], T]) -> T | None:
    """``read`` of the file at ``path``, if the file is the user's own, writable by nobody else, and
    ``read`` takes it (a stale or truncated file is None, as a missing one)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW)
    except OSError:
        return None
    with os.fdopen(fd, "rb") as f:
        info = os.fstat(f.fileno())
        if not stat.S_ISREG(info.st_mode) or not _private(info):
            return None
        try:
            return read(f)
        except Exception:  # noqa: BLE001 - a stale or truncated file of the user's own raises anything
            return None


def store(path: Path, write: Callable[[BinaryIO], None]) -> None:
    """``write`` to ``path`` through a temporary file of the same folder (mode 0600) renamed over it; a
    folder that cannot be written leaves the cache as it was."""
    try:
        fd, temporary = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    except OSError:
        return
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
        os.replace(temporary, path)
    except OSError:
        os.unlink(temporary)


@cache
def code_stamp() -> str:
    """A digest of the code that made a cached file: grammarc's version and the name, size and time of
    each of its source files and grammars, and the Python (pickles are read by the same one): its
    environment and its program, whichever of its names started it (``python``, ``python3``, the
    ``grammarc`` script's), so that ``python -m grammarc`` finds the server ``grammarc server start`` left."""
    python = f"{sys.prefix}\0{os.path.realpath(sys.executable)}\0{sys.version}"
    digest = hashlib.sha256(f"{grammarc.__version__}\0{python}\0".encode())
    for parts, info in sorted(_sources(os.path.dirname(grammarc.__file__), ())):
        digest.update(f"{'/'.join(parts)}\0{info.st_mtime_ns}\0{info.st_size}\0".encode())
    return digest.hexdigest()


def _sources(folder: str, parts: tuple[str, ...]) -> list[tuple[tuple[str, ...], os.stat_result]]:
    """``(path parts, stat)`` of the ``.py`` and ``.lark`` files under ``folder``, found with ``os.scandir``
    past the ``__pycache__`` folders (full of numba's cache files, which ``Path.rglob`` listed on every
    command's start)."""
    found = []
    with os.scandir(folder) as entries:
        for entry in entries:
            if entry.is_dir(follow_symlinks=False):
                if entry.name != "__pycache__":
                    found += _sources(entry.path, (*parts, entry.name))
            elif entry.name.endswith((".py", ".lark")):
                found.append(((*parts, entry.name), entry.stat()))
    return found
