"""Work a command may leave until after it has answered: releasing what it no longer needs.

Some of a build's last steps change nothing the user sees and cost the kernel time in proportion to the
build's size: freeing the blocks of the output a new one replaced, the exit of the forked workers, the
unmapping of the shared memory their records came through. A command in its own process does them where
they come (``later`` runs them at once): its process ends right after, and ending would do the same work.
A served command's child (``server``) ``hold``\\s them instead, sends its client the exit status, lets go
of the client's streams and only then runs them (``release_all``), so the client's command ends first. A
command that starts such work again (a search, the conformance runs derive again and again) ``flush``\\es
what it holds first: only the last work's releases wait for the reply, not a pile of idle workers.
"""

from __future__ import annotations

import contextlib
import functools
import os
import stat
from collections.abc import Callable

__all__ = ["flush", "hold", "holding", "later", "release_all", "replace"]

_held: list[Callable[[], object]] | None = None


def hold() -> None:
    """From now on keep what ``later`` is given until ``release_all``."""
    global _held
    _held = []


def holding() -> bool:
    """Whether this process keeps its releases (``hold``) until ``release_all``."""
    return _held is not None


def later(release: Callable[[], object]) -> None:
    """Run ``release`` now, or keep it for ``release_all`` where this process holds its releases."""
    if _held is None:
        release()
    else:
        _held.append(release)


def flush() -> None:
    """Run the kept releases now, in the order they were given, and go on holding the next ones."""
    if _held:
        held = _held[:]
        _held.clear()
        _run(held)


def release_all() -> None:
    """Run the kept releases in the order they were given, and hold no more."""
    global _held
    held, _held = _held or [], None
    _run(held)


def _run(releases: list[Callable[[], object]]) -> None:
    """Each of ``releases``: one that fails (a worker that will not exit cleanly) stops neither the others
    nor the command, as it changes nothing the command made."""
    for release in releases:
        with contextlib.suppress(Exception):
            release()


def replace(new: str | os.PathLike, path: str | os.PathLike) -> None:
    """``os.replace(new, path)``, the file it replaces freed ``later``.

    The filesystem frees a file's blocks when its last name and its last descriptor are gone: a
    descriptor held over the rename moves that work to where it is closed. Taken only where releases are
    held (Windows, which cannot rename over an open file, has no server)."""
    old = _opened(path) if holding() else None
    os.replace(new, path)
    if old is not None:
        later(functools.partial(os.close, old))


def _opened(path: str | os.PathLike) -> int | None:
    """A descriptor of the regular file at ``path`` (not through a link; a FIFO does not block it), or None."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError:
        return None
    if stat.S_ISREG(os.fstat(fd).st_mode):
        return fd
    os.close(fd)
    return None
