"""A file's lowered statements, kept between runs in the user's cache folder (``user_cache``).

Parsing and lowering a rule file is most of the time it takes to compile it, and the result depends on
nothing but the code that does it, the dialect, the file's name as diagnostics give it (spans carry it),
its text and the number its first random-stream site gets (sites are numbered across imported files).
Those are the key; what a file imports, and everything the passes look up (assets, file searches), is
read again on every compile. A file whose lowering found an error is not kept (its diagnostics are
rendered from the live text anyway); its warnings are kept with its statements. The folder keeps the
``MAX_FILES`` files used last, and loses the temporary files of stores that were killed.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import time

from grammarc.diagnostics import Diagnostic
from grammarc.frontend.user_cache import cache_folder, code_stamp, load, store

#: Lowered files kept; the least recently used go first. A rule package can hold many (candler's is 76
#: files), and 256 let a few packages and a test run push out each other's; a file is a few kilobytes.
MAX_FILES = 1024


def lookup(dialect: str, file: str, text: str, first_site: int) -> tuple[list, list[Diagnostic], int] | None:
    """``(statements, warnings, next_site)`` of an earlier lowering of the same file, or None."""
    folder = cache_folder("lowered")
    if folder is None:
        return None
    path = folder / _name(dialect, file, text, first_site)
    found = load(path, pickle.load)
    if found is not None:
        os.utime(path)  # used: kept longer
    return found


def keep(dialect: str, file: str, text: str, first_site: int, statements: list, warnings: list[Diagnostic],
         next_site: int) -> None:
    """Keep a file's lowering for ``lookup``, and let the least recently used go beyond ``MAX_FILES``."""
    folder = cache_folder("lowered")
    if folder is None:
        return
    data = pickle.dumps((statements, warnings, next_site), protocol=pickle.HIGHEST_PROTOCOL)
    store(folder / _name(dialect, file, text, first_site), lambda f: f.write(data))
    kept = sorted(folder.glob("*.pickle"), key=_used, reverse=True)
    # beyond the last MAX_FILES, and temporary files of stores that a killed process left (an hour old)
    hour_ago = time.time_ns() - 3600 * 10**9
    for stale in [*kept[MAX_FILES:], *(t for t in folder.glob("*.tmp") if _used(t) < hour_ago)]:
        stale.unlink(missing_ok=True)


def _used(path) -> int:
    try:
        return path.stat().st_mtime_ns
    except OSError:  # another process let it go meanwhile
        return 0


def _name(dialect: str, file: str, text: str, first_site: int) -> str:
    key = "\0".join((code_stamp(), dialect, file, str(first_site), text))
    return hashlib.sha256(key.encode("utf-8", "surrogatepass")).hexdigest()[:32] + ".pickle"
