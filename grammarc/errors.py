"""The exceptions of grammarc: one base class, a few flat subclasses."""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading


class GrammarcError(Exception):
    """Base class of every error grammarc raises on purpose."""

    exit_code = 1


class GrammarError(GrammarcError):
    """The grammar has errors; ``diagnostics`` holds all of them, ``sources`` the texts to render them."""

    exit_code = 2

    def __init__(self, diagnostics, sources):
        from grammarc.diagnostics import render_all

        self.diagnostics = list(diagnostics)
        self.sources = dict(sources)
        super().__init__(render_all([d for d in self.diagnostics], self.sources))


class UsageError(GrammarcError):
    """A command-line option or argument is wrong (bad --attr, missing file)."""

    exit_code = 2


class LotsError(GrammarcError):
    """The lots file cannot be read at all (missing, not GeoJSON/OBJ, no polygon)."""


class DerivationError(GrammarcError):
    """A rule cannot be applied to a shape (NaN or negative size, an unsupported geometry)."""


class AssetError(GrammarcError):
    """An asset cannot be resolved, or its path escapes the asset roots."""


class LotFailure(DerivationError):
    """Some lots of a chunk cannot be derived (a negative size, an unsupported geometry, a limit reached).

    ``lots`` holds their chunk-local indices: the build reports them as bad lots and derives the chunk
    again without them, so the other lots are not lost. ``reasons``, when given, is one message per lot
    of ``lots`` (a limit names each lot's own count); otherwise ``message`` is every lot's reason.
    """

    def __init__(self, message: str, lots, reasons=None):
        super().__init__(message)
        self.lots = lots
        self.reasons = reasons

    def reason(self, k: int) -> str:
        """Why the ``k``-th lot of ``lots`` failed."""
        return str(self) if self.reasons is None else self.reasons[k]


class ChunkTooLarge(GrammarcError):
    """A chunk made more shapes than its memory budget; the build splits it and derives the halves."""


class Stopped(KeyboardInterrupt):
    """SIGTERM or SIGHUP (what ``timeout``, docker, systemd, Slurm and a closed terminal send), raised where
    the program is, so that it unwinds as from Ctrl-C: writers abort, temporary files and the workers'
    shared memory go, the pool's workers end."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


#: The signals that stopped the command: kept until the command ends, because the stop is not always
#: raised where the signal comes (``raise_stopped``), and a raise can be lost.
_pending: list[int] = []
#: Blocks of ``stops_held`` running: a stop is held until they end.
_held = 0


def raise_stopped(signum, frame) -> None:
    """The handler of SIGINT, SIGTERM and SIGHUP while a command runs: the stop is raised where the program
    is, unless that is inside ``stops_held``, or numba's or llvmlite's Python code. There, raising is unsafe:
    llvmlite's ctypes callbacks, while numba compiles, swallow the exception ("Exception ignored on calling
    ctypes callback function") and the compile leaves objects that are freed twice later (glibc aborts the
    process); numba's callbacks from compiled code turn it into a ``SystemError``. The stop is then held,
    and raised where the block ends or by ``check_stopped`` where the command next looks."""
    _pending.append(signum)
    if not _held and not _in_numba(frame):
        raise Stopped(signum)


def _in_numba(frame) -> bool:
    roots = tuple(os.path.dirname(module.__file__) + os.sep
                  for module in (sys.modules.get("numba"), sys.modules.get("llvmlite")) if module is not None)
    while frame is not None:
        if frame.f_code.co_filename.startswith(roots):
            return True
        frame = frame.f_back
    return False


@contextlib.contextmanager
def signals_stop():
    """While the block runs, SIGINT, SIGTERM and SIGHUP stop the command (``raise_stopped``; in the main
    thread only, where Python runs handlers) and a stop a callback's caller swallowed is not printed
    (``hide_lost_stops``); after it, the handlers and hook are the ones before and no stop is held."""
    handlers = {s: signal.signal(s, raise_stopped) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)} \
        if threading.current_thread() is threading.main_thread() else {}
    unraisable, sys.unraisablehook = sys.unraisablehook, hide_lost_stops
    try:
        yield
    finally:
        for signum, handler in handlers.items():
            signal.signal(signum, handler)
        clear_stopped()
        sys.unraisablehook = unraisable


@contextlib.contextmanager
def stops_held():
    """While the block runs, a stop is held (``raise_stopped``) and raised when it ends: for what must be
    made whole or not at all, such as an output's temporary folder and the removal of it that an abort
    runs. Held, not blocked: a signal sent to the process goes to any thread that does not block it, and
    Python runs the handler in the main thread wherever it is."""
    global _held
    _held += 1
    try:
        yield
    finally:
        _held -= 1
    if not _held:
        check_stopped()


def check_stopped() -> None:
    """Raise the stop that was held or whose raise was lost, if any: called where a command goes on for
    long (each round of a derivation) and before an output is put in place."""
    if _pending:
        raise Stopped(_pending[0])


def hide_lost_stops(unraisable) -> None:
    """``sys.unraisablehook`` while a command runs: a stop that a callback's caller swallowed is kept and
    said when the command stops; the traceback Python would print for it is not the user's to read."""
    if not isinstance(unraisable.exc_value, KeyboardInterrupt):
        sys.__unraisablehook__(unraisable)


def clear_stopped() -> None:
    """The command is over: a later command in this process (tests, a served command's fork) starts
    without its stop."""
    _pending.clear()


def interruption(error: BaseException) -> KeyboardInterrupt | None:
    """The Ctrl-C or ``Stopped`` behind ``error``, if any: in its chain of causes (numba's ``SystemError``),
    or a stop whose raise was lost (see ``_pending``). Whatever failed after a stop, the command was
    stopped."""
    seen = set()
    while error is not None and id(error) not in seen:
        if isinstance(error, KeyboardInterrupt):
            return error
        seen.add(id(error))
        error = error.__cause__ or error.__context__
    return Stopped(_pending[0]) if _pending else None


def stopped(stop: KeyboardInterrupt, command: str = "grammarc", kept: str = "nothing was written") -> int:
    """Say that ``command`` was stopped (Ctrl-C or ``Stopped``) and what it ``kept``; its exit status (128 +
    the signal)."""
    signum = stop.signum if isinstance(stop, Stopped) else signal.SIGINT
    said = "interrupted" if signum == signal.SIGINT else f"{signal.Signals(signum).name}: stopped"
    print(f"{command}: {said}; {kept}", file=sys.stderr)
    return 128 + signum
