"""Chunks of lots derived in forked worker processes, their records shipped back through memory files.

The derivation is mostly Python driving numpy and numba over columns, so threads would share one
interpreter lock; processes use both cores. The work is set before the
workers are forked, so they inherit the compiled plan and the occluders rather than receive them pickled;
each task sends only its lots.

A chunk's records (6 * 10^5 rows, ~40 MB) do not come back through the pool's pipe: pickling them and
pushing them through a pipe cost more than deriving them on a grammar as cheap as the facade benchmark.
A worker writes each record's arrays into one file in a private folder on a memory filesystem
(``/dev/shm`` where there is one), and the parent maps the file into memory, takes the arrays as views
of the mapping and deletes it: the records are copied once on their way, by the writer. The folder goes
when the pool does, so a failed build leaves nothing behind. What two workers gain, and what the pipe and
a read buffer cost, is measured in the README ("Figures").
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import itertools
import multiprocessing
import os
import shutil
import signal
import sys
import tempfile
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np

from grammarc.atomic import remove_stale
from grammarc.errors import DerivationError

__all__ = ["worker_pool"]

#: What the workers run, set in the parent before they are forked: ``work``, the shipping folder.
_SHARED: dict = {}
#: Numbers a worker's files (with its pid, unique in the folder).
_TASKS = itertools.count()
#: Arrays start at multiples of this in a shipped file, so their views are aligned.
_ALIGN = 64


@contextlib.contextmanager
def worker_pool(work: Callable, workers: int):
    """``submit(lots) -> Future`` of ``work(lots)``, which returns ``(results, failed)`` with results
    ``[(n_lots, (records, per_lot))]``: in this process when ``workers`` is 1 or processes cannot be forked
    (Windows), else in ``workers`` forked processes, but for the first task.

    The first task runs in this process, before the workers are forked: the kernels it loads (numba's
    machine code from its cache, fused regions' modules) are then the workers' from the start, where
    each worker would load them again, in every build, at a cost of a few hundredths of a second each."""
    if workers == 1 or "fork" not in multiprocessing.get_all_start_methods():
        yield functools.partial(_at_once, work)
        return
    memory = "/dev/shm" if os.path.isdir("/dev/shm") and os.access("/dev/shm", os.W_OK) else None
    shared = Path(memory if memory is not None else tempfile.gettempdir())
    remove_stale(shared, "grammarc-records-")  # what builds that were killed left
    folder = Path(tempfile.mkdtemp(prefix=f"grammarc-records-{os.getpid()}-", dir=shared))
    _SHARED.update(work=work, folder=folder)
    try:
        forked = False
        with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("fork"),
                                 initializer=_die_with_parent) as pool:
            def submit(lots) -> Future:
                nonlocal forked
                if not forked:  # the pool forks its workers at its first task: this one runs here
                    forked = True
                    return _at_once(work, lots)
                shipped = pool.submit(_run, lots)
                received: Future = Future()
                shipped.add_done_callback(lambda done: _receive(done, received, lots))
                return received

            yield submit
    finally:
        _SHARED.clear()
        shutil.rmtree(folder, ignore_errors=True)


def _at_once(work: Callable, lots) -> Future:
    """The future of ``work(lots)``, run in this process."""
    future: Future = Future()
    try:
        future.set_result(work(lots))
    except BaseException as error:  # noqa: BLE001 - handed to the caller by future.result()
        future.set_exception(error)
    return future


def _die_with_parent() -> None:
    """In a new worker: the kernel kills it when the parent dies however it dies (Linux's
    ``PR_SET_PDEATHSIG``; a SIGKILL of the parent runs no code of ours), and SIGTERM and SIGHUP end it
    as by default rather than unwind it as they do the parent (``errors.Stopped``)."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGHUP, signal.SIG_DFL)
    if sys.platform.startswith("linux"):
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # 1: PR_SET_PDEATHSIG
        if os.getppid() == 1:  # the parent died before the call: go now
            os._exit(1)


def _run(lots):
    """In a worker: the work, its records written to memory files."""
    results, failed = _SHARED["work"](lots)
    shipped = []
    for k, (n_lots, (records, per_lot)) in enumerate(results):
        path = _SHARED["folder"] / f"{os.getpid()}-{next(_TASKS)}-{k}.bin"
        shipped.append((n_lots, (_ship(records, path), per_lot)))
    return shipped, failed


def _receive(done: Future, received: Future, lots) -> None:
    if not received.set_running_or_notify_cancel():  # the build stopped (Ctrl-C) and gave this chunk up
        return
    try:
        shipped, failed = done.result()
        received.set_result(([(n, (_unship(layout), per_lot)) for n, (layout, per_lot) in shipped], failed))
    except BrokenProcessPool:
        # A worker was killed (most often by the kernel's out-of-memory killer: SIGKILL runs no code of
        # ours). Deriving its lots again would most likely kill again, so the build stops as after any
        # failure: the writer aborts and nothing is written.
        received.set_exception(DerivationError(
            f"a worker process was killed while deriving lots {_span(lots)} (out of memory?); "
            "nothing was written: rerun with fewer --workers or a smaller --chunk-size"))
    except BaseException as error:  # noqa: BLE001 - handed to the caller by received.result()
        received.set_exception(error)


def _span(lots) -> str:
    """``#first-#last`` of a chunk of lots, by their numbers in the input (of a search's states, how many)."""
    if not hasattr(lots, "index"):
        return f"({len(lots)} search states)"
    return f"#{lots.index[0]}-#{lots.index[-1]}" if len(lots) else "(none)"


def _ship(records, path: Path) -> tuple:
    """Write the arrays of a (nested) dataclass of arrays into ``path``; the layout to rebuild it."""
    arrays: list[np.ndarray] = []
    layout = _layout(records, arrays, [0])
    with open(path, "wb") as out:
        for array in arrays:
            out.write(np.ascontiguousarray(array).reshape(-1).view(np.uint8))  # its bytes, not a copy
            out.write(b"\0" * (-array.nbytes % _ALIGN))
    return str(path), layout


def _layout(value, arrays: list, at: list[int]) -> tuple:
    """``("dataclass", class, {field: layout})``, ``("array", dtype, shape, offset)`` or ``("value", v)``."""
    if dataclasses.is_dataclass(value):
        return "dataclass", type(value), {f.name: _layout(getattr(value, f.name), arrays, at)
                                          for f in dataclasses.fields(value)}
    if isinstance(value, np.ndarray):
        arrays.append(value)
        offset = at[0]
        at[0] += value.nbytes + (-value.nbytes % _ALIGN)
        return "array", value.dtype.str, value.shape, offset
    return "value", value


def _unship(shipped: tuple):
    """The records a worker wrote, as views of the file mapped into memory (private, copy-on-write: no
    copy is made, and none is written back); the file deleted, its pages freed with the last view."""
    path, layout = shipped
    data = np.memmap(path, dtype=np.uint8, mode="c") if os.path.getsize(path) else np.zeros(0, np.uint8)
    os.unlink(path)
    return _rebuild(layout, data)


def _rebuild(layout: tuple, data: np.ndarray):
    kind = layout[0]
    if kind == "dataclass":
        return layout[1](**{name: _rebuild(item, data) for name, item in layout[2].items()})
    if kind == "array":
        dtype, shape, offset = np.dtype(layout[1]), layout[2], layout[3]
        size = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
        return data[offset:offset + size].view(dtype).reshape(shape)
    return layout[1]
