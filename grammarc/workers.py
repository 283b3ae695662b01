"""Chunks of lots derived in forked worker processes, their records shipped back through memory files.

The derivation is mostly Python driving numpy and numba over columns, so threads would share one
interpreter lock; processes use both cores. The work is set before the
workers are forked, so they inherit the compiled plan and the occluders rather than receive them pickled;
each task sends only its lots.

A chunk's records (6 * 10^5 rows, ~40 MB) do not come back through the pool's pipe: pickling them and
pushing them through a pipe cost more than deriving them on a grammar as cheap as the facade benchmark.
A worker writes a task's record arrays into one file of a private folder on a memory filesystem
(``/dev/shm`` where there is one), and the parent takes the arrays as views of the file mapped into
memory: the records are copied into the file by the worker and out of it by the writer. The files are
slots that are used again: the parent gives each task a slot that no array refers to any more, so a
worker writes over pages the memory filesystem already holds (and cuts the file to the task's size, so a
large chunk's pages go with the next task) and the parent's mapping of them is already there. A new file for
each task had the kernel allocate, zero and map its pages and free them again, chunk after chunk, for
every record byte: that cost more system time than a second worker saves on a grammar as cheap as the
facade benchmark (README, "Figures"). The folder goes when the pool does, so a failed build leaves
nothing behind.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import itertools
import mmap
import multiprocessing
import os
import shutil
import signal
import sys
import tempfile
import threading
import weakref
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np

from grammarc import releases
from grammarc.atomic import remove_stale
from grammarc.errors import DerivationError

__all__ = ["worker_pool"]

#: What the workers run, set in the parent before they are forked.
_SHARED: dict = {}
#: Arrays start at multiples of this in a shipped file, so their views are aligned.
_ALIGN = 64
#: Whether this process is warm (``warm``).
_warm = False
#: Shipped arrays smaller than this are copied out of their file: consumers keep small tables past a
#: chunk (the npz writer keeps each chunk's lot origins to its close), and a view would keep the file's
#: slot from being used again.
_COPIED = 1 << 20


def warm() -> None:
    """Mark this process warm: it has loaded every kernel numba's cache holds (a server does, before it
    forks a child for each command), so workers forked from it have them whatever they derive first."""
    global _warm
    _warm = True


def forks() -> bool:
    """Whether this system forks workers (not Windows)."""
    return "fork" in multiprocessing.get_all_start_methods()


def first_tasks(workers: int) -> int:
    """How many tasks a pool of ``workers`` is given before the first one's result is known: one, run in
    this process, unless it is warm (``worker_pool``); else one for each worker."""
    return workers if _warm and workers > 1 and forks() else 1


@contextlib.contextmanager
def worker_pool(work: Callable, workers: int):
    """``submit(lots) -> Future`` of ``work(lots)``, which returns ``(results, failed)`` with results
    ``[(n_lots, (records, per_lot))]``: in this process when ``workers`` is 1 or processes cannot be forked
    (Windows), else in ``workers`` forked processes, but for the first task unless this process is warm.

    The first task runs in this process, before the workers are forked: the kernels it loads (numba's
    machine code from its cache, fused regions' modules) are then the workers' from the start, where
    each worker would load them again, in every build, at a cost of a few hundredths of a second each.
    While it runs, the other cores wait. A warm process (``warm``) has them all loaded already: its
    workers are forked at the first task, and each is given one of the first tasks (``first_tasks``)."""
    if workers == 1 or not forks():
        yield functools.partial(_at_once, work)
        return
    releases.flush()  # the workers of a pool before, kept for after a served command's reply, go first
    memory = "/dev/shm" if os.path.isdir("/dev/shm") and os.access("/dev/shm", os.W_OK) else None
    shared = Path(memory if memory is not None else tempfile.gettempdir())
    remove_stale(shared, "grammarc-records-")  # what builds that were killed left
    folder = Path(tempfile.mkdtemp(prefix=f"grammarc-records-{os.getpid()}-", dir=shared))
    _SHARED.update(work=work)
    slots = _Slots(folder)
    pool = None
    try:
        here = not _warm  # the first task runs here, but in a warm process; the pool forks its workers at the next
        pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("fork"),
                                   initializer=_start_worker)

        def submit(lots) -> Future:
            nonlocal here
            if here:
                here = False
                return _at_once(work, lots)
            slot = slots.take()
            try:
                shipped = pool.submit(_run, lots, slot)
            except BrokenProcessPool as broken:  # a worker was killed before this task went in
                shipped = Future()
                shipped.set_exception(broken)
            received: Future = Future()
            shipped.add_done_callback(lambda done: _receive(done, received, lots, slots, slot))
            return received

        yield submit
    finally:
        _SHARED.clear()
        # the workers' exit and the unmapping of the memory files (the slots, kept to then) are left for
        # after a served build's reply; the folder goes once no worker can write into it
        releases.later(functools.partial(_close_pool, pool, slots, folder))


def _close_pool(pool: ProcessPoolExecutor | None, slots: _Slots, folder: Path) -> None:
    """Wait for the workers to exit, then remove the folder of memory files (and, with ``slots``, the
    mappings of its files that no record array refers to any more)."""
    if pool is not None:
        pool.shutdown(wait=True)
    shutil.rmtree(folder, ignore_errors=True)
    slots.close()


def _at_once(work: Callable, lots) -> Future:
    """The future of ``work(lots)``, run in this process."""
    future: Future = Future()
    try:
        future.set_result(work(lots))
    except BaseException as error:  # noqa: BLE001 - handed to the caller by future.result()
        future.set_exception(error)
    return future


def _start_worker() -> None:
    """In a new worker: the kernel kills it when the parent dies however it dies (Linux's
    ``PR_SET_PDEATHSIG``; a SIGKILL of the parent runs no code of ours), and SIGTERM and SIGHUP end it
    as by default rather than unwind it as they do the parent (``errors.Stopped``).

    Its C heap keeps the memory it frees (glibc's ``mallopt``): each chunk's columns (up to ~30 MB each)
    would otherwise be mapped fresh and unmapped again, and the kernel would fault in and zero every page
    of them, chunk after chunk; kept, the next chunk's columns take the same pages. A worker lives for one
    build, and its memory is bounded by its largest chunk as before."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGHUP, signal.SIG_DFL)
    if sys.platform.startswith("linux"):
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGKILL)  # 1: PR_SET_PDEATHSIG
        if os.getppid() == 1:  # the parent died before the call: go now
            os._exit(1)
        if hasattr(libc, "mallopt"):  # glibc (musl has none)
            libc.mallopt(-3, 32 << 20)  # M_MMAP_THRESHOLD: glibc's largest; blocks above it are still mapped
            libc.mallopt(-1, 1 << 30)  # M_TRIM_THRESHOLD (an int): keep up to 1 GiB free at the heap's top


def _run(lots, slot: Path):
    """In a worker: the work, its records written to the memory file ``slot``."""
    results, failed = _SHARED["work"](lots)
    layouts, size = _ship([records for _, (records, _) in results], slot)
    return [(n_lots, per_lot) for n_lots, (_, per_lot) in results], layouts, size, failed


def _receive(done: Future, received: Future, lots, slots: _Slots, slot: Path) -> None:
    if not received.set_running_or_notify_cancel():  # the build stopped (Ctrl-C) and gave this chunk up
        return
    try:
        counts, layouts, size, failed = done.result()
        data = slots.open(slot, size)
        received.set_result(([(n_lots, (_rebuild(layout, data), per_lot))
                              for (n_lots, per_lot), layout in zip(counts, layouts, strict=True)], failed))
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


def _ship(values: list, path: Path) -> tuple[list[tuple], int]:
    """Write the arrays of (nested) dataclasses of arrays into ``path``, over what it held, and cut it to
    their size; their layouts (to rebuild them) and that size."""
    arrays: list[np.ndarray] = []
    at = [0]
    layouts = [_layout(value, arrays, at) for value in values]
    fd = os.open(path, os.O_WRONLY | os.O_CREAT, 0o600)
    try:
        os.ftruncate(fd, at[0])
        offset = 0
        for array in arrays:
            view = memoryview(np.ascontiguousarray(array).reshape(-1).view(np.uint8))  # its bytes, not a copy
            done = 0
            while done < len(view):
                done += os.pwrite(fd, view[done:], offset + done)
            offset += array.nbytes + (-array.nbytes % _ALIGN)
    finally:
        os.close(fd)
    return layouts, at[0]


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


class _Slots:
    """The memory files of a pool's tasks, each used again once no array refers to its last contents.

    The parent maps each file once, for reading only (an array written to in place would be an error,
    not a change that the next task's records would find), and maps it again only when it grew. Slots are
    taken when tasks are submitted and given back, from whatever thread drops the last view of a task's
    records (the writer's), by a finalizer; a slot of a task that failed is not used again."""

    def __init__(self, folder: Path):
        self._folder = folder
        self._made = itertools.count()
        self._free: list[Path] = []
        self._mapped: dict[Path, mmap.mmap] = {}
        # reentrant: the garbage collector may run a finalizer (``_give_back``) while this thread holds it
        self._lock = threading.RLock()

    def take(self) -> Path:
        with self._lock:
            return self._free.pop() if self._free else self._folder / f"{next(self._made)}.bin"

    def open(self, path: Path, size: int) -> np.ndarray:
        """The first ``size`` bytes of ``path``, which is free again when they and their views are gone."""
        if not size:
            self._give_back(path)
            return np.zeros(0, np.uint8)
        with self._lock:
            mapped = self._mapped.get(path)
            if mapped is None or len(mapped) < size:
                with open(path, "rb") as file:
                    mapped = self._mapped[path] = mmap.mmap(file.fileno(), size, access=mmap.ACCESS_READ)
        data = np.frombuffer(mapped, np.uint8, size)  # views of it keep it, not the mapping, as their base
        weakref.finalize(data, self._give_back, path)
        return data

    def _give_back(self, path: Path) -> None:
        with self._lock:
            self._free.append(path)

    def close(self) -> None:
        """Let go of the mappings: each is unmapped once the last array viewing it is gone."""
        with self._lock:
            self._mapped.clear()


def _rebuild(layout: tuple, data: np.ndarray):
    kind = layout[0]
    if kind == "dataclass":
        return layout[1](**{name: _rebuild(item, data) for name, item in layout[2].items()})
    if kind == "array":
        dtype, shape, offset = np.dtype(layout[1]), layout[2], layout[3]
        size = int(np.prod(shape, dtype=np.int64)) * dtype.itemsize
        array = data[offset:offset + size].view(dtype).reshape(shape)
        return array.copy() if size < _COPIED else array
    return layout[1]
