"""Worker processes: records shipped through memory files come back equal; bad lots come back named."""

import multiprocessing
import os

import numpy as np
import pytest

from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar
from grammarc.io.lots import lots_from_polygons
from grammarc.model.records import MeshChunk, TerminalChunk
from grammarc.workers import _rebuild, _ship, _Slots


def _chunk(rows: int, seed: int) -> TerminalChunk:
    mesh = MeshChunk(vertices=np.arange(12, dtype=np.float32).reshape(4, 3), ring_offsets=np.array([0, 4]),
                     face_offsets=np.array([0, 1]), lot=np.array([1], np.int32), symbol=np.array([0], np.int32))
    rng = np.random.default_rng(seed)
    return TerminalChunk(asset=rng.integers(0, 5, rows, dtype=np.int32),
                         xform=rng.normal(size=(rows, 3, 4)).astype(np.float32),
                         lot=np.sort(rng.integers(0, 3, rows)).astype(np.int32), symbol=np.zeros(rows, np.int32),
                         mesh=mesh)


def _assert_equal(back: TerminalChunk, chunk: TerminalChunk) -> None:
    assert back.color is None and back.mesh.color is None
    for name in ("asset", "xform", "lot", "symbol"):
        np.testing.assert_array_equal(getattr(back, name), getattr(chunk, name))
        assert getattr(back, name).dtype == getattr(chunk, name).dtype
    for name in ("vertices", "ring_offsets", "face_offsets", "lot", "symbol"):
        np.testing.assert_array_equal(getattr(back.mesh, name), getattr(chunk.mesh, name))


def test_shipped_chunks_come_back_equal_and_their_slot_is_used_again_once_they_are_dropped(tmp_path):
    slots = _Slots(tmp_path)
    first, second = _chunk(30_000, 0), _chunk(10, 1)  # xform: 1.4 MB, shipped; 480 bytes, copied
    slot = slots.take()
    layouts, size = _ship([first, second], slot)
    data = slots.open(slot, size)
    back = [_rebuild(layout, data) for layout in layouts]
    _assert_equal(back[0], first)
    _assert_equal(back[1], second)
    del data
    assert slots.take() != slot  # views of its records are alive: not free
    kept, small = back[0].xform, back[1].xform
    del back
    assert slots.take() != slot  # one view is enough to keep it
    assert small.flags.owndata  # small arrays are copies, which do not keep it
    del kept
    assert slots.take() == slot
    for rows in (25_000, 40_000):  # written over: a smaller and a larger task (the parent maps it again)
        chunk = _chunk(rows, rows)
        layouts, size = _ship([chunk], slot)
        back = _rebuild(layouts[0], slots.open(slot, size))
        _assert_equal(back, chunk)
        assert not back.xform.flags.writeable and os.path.getsize(slot) == size
        del back
        assert slots.take() == slot


def test_lots_failed_in_a_worker_come_back_as_bad_lots(write):
    grammar = compile_grammar(write("g.cga", "lot ~> grow\ngrow ~> S(1r, 1r, 1r) grow\n"))
    lots = lots_from_polygons([[np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)]] * 4)
    bad = derive(grammar, lots, BuildOptions(workers=2, chunk_size=1))["bad"]
    assert [b.index for b in bad] == [0, 1, 2, 3] and all("--max-depth 256 in rule `grow`" in b.reason for b in bad)


def test_a_pool_removes_the_shared_memory_that_killed_builds_left():
    import tempfile
    from pathlib import Path

    from grammarc.workers import worker_pool

    shared = Path("/dev/shm") if Path("/dev/shm").is_dir() else Path(tempfile.gettempdir())
    stale = shared / "grammarc-records-4194305-zz"  # above Linux's largest pid: a dead run's
    stale.mkdir(exist_ok=True)
    (stale / "0.bin").write_bytes(b"records")
    with worker_pool(lambda lots: ([], []), 2) as submit:
        assert not stale.exists()
        assert submit([]).result() == ([], [])


def test_a_worker_killed_by_sigkill_fails_the_build_with_one_line():
    """What the out-of-memory killer does: no traceback, a DerivationError naming the lots in flight."""
    import os
    import signal

    from grammarc.errors import DerivationError
    from grammarc.workers import worker_pool

    lots = lots_from_polygons([[np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)]] * 3)
    parent = os.getpid()

    def work(lots):
        return ([], []) if os.getpid() == parent else os.kill(os.getpid(), signal.SIGKILL)

    with (worker_pool(work, 2) as submit,
          pytest.raises(DerivationError, match=r"worker process was killed while deriving lots #0-#2")):
        assert submit(lots).result() == ([], [])  # the first task, here
        submit(lots).result(timeout=60)


def test_a_chunk_given_up_by_a_stopped_build_is_dropped_without_a_traceback(caplog):
    """Ctrl-C cancels the chunks in flight; when their workers finish later, nothing is logged (it was a
    traceback from the pool's callback)."""
    import time

    from grammarc.workers import worker_pool

    with worker_pool(lambda lots: (time.sleep(0.5), ([], []))[1], 2) as submit:
        assert submit([]).done()  # the first task ran here
        in_flight = submit([])
        assert in_flight.cancel()
    assert in_flight.cancelled() and not [r for r in caplog.records if r.levelname == "ERROR"]


LOADED: list[int] = []  # what a task loaded (a kernel's machine code), in the process that ran it


def _load_and_say(lots):
    LOADED.append(os.getpid())
    return [], (os.getpid(), list(LOADED))


def test_the_first_task_runs_here_and_the_workers_inherit_what_it_loaded():
    from grammarc.workers import worker_pool

    LOADED.clear()
    with worker_pool(_load_and_say, 2) as submit:
        _, (here, loaded) = submit([]).result()
        assert here == os.getpid() and loaded == [here]
        for _, (worker, loaded) in (f.result(timeout=60) for f in [submit([]), submit([])]):
            assert worker != here and loaded[0] == here  # forked after the first task: they have its load


def test_a_warm_process_gives_its_first_task_to_a_worker(monkeypatch):
    """A warm process (a server's child) has every kernel loaded: no task runs here for its workers to
    inherit what it loaded."""
    from grammarc import workers

    monkeypatch.setattr(workers, "_warm", True)
    assert workers.first_tasks(2) == 2 and workers.first_tasks(1) == 1
    LOADED.clear()
    with workers.worker_pool(_load_and_say, 2) as submit:
        _, (worker, loaded) = submit([]).result(timeout=60)
        assert worker != os.getpid() and loaded == [worker]


@pytest.mark.parametrize(("lots", "chunk_size", "forked"), [(3, 16384, False), (3, 2, True), (65, 16384, True)])
def test_only_builds_of_more_than_one_chunk_fork_workers(monkeypatch, write, lots, chunk_size, forked):
    """Forking workers for one chunk only makes it wait for them (the first chunk holds up to 64 lots)."""
    from grammarc import build

    asked = []
    real = build.worker_pool
    monkeypatch.setattr(build, "worker_pool", lambda work, workers: (asked.append(workers), real(work, workers))[1])
    grammar = compile_grammar(write("g.cga", "Lot --> extrude(3)\n"))
    square = [[np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)]]
    derive(grammar, lots_from_polygons(square * lots), BuildOptions(workers=2, chunk_size=chunk_size))
    assert asked == [2 if forked else 1]


def test_the_last_chunks_are_shared_out_among_the_workers():
    from grammarc.build import _last_share

    assert _last_share(107, 1000, 2) is None  # far from the end: chunks of the size records per lot give
    assert _last_share(107, 131, 2) == 66  # near it: an equal share for each worker
    assert _last_share(2, 3, 2) == 2  # never more than the size asked for (--chunk-size)
    assert _last_share(107, 131, 1) is None  # one process: nothing to share


@pytest.mark.parametrize(("warm", "lots", "expected"), [(False, 100, [16, 42, 42]), (True, 100, [50, 50]),
                                                        (True, 300, [64, 64, 86, 86])])
def test_chunks_of_a_build_with_workers_start_small_and_end_shared(monkeypatch, write, warm, lots, expected):
    """The first chunk (here, while the other core waits) is small, and the next are sized by the records a
    lot made in it: here the lots left are no more than a chunk for each worker, and are shared out. In a
    warm process each worker is given a first chunk of up to 64 lots at once: 100 lots are shared out at
    once."""
    import contextlib

    from grammarc import build, workers

    monkeypatch.setattr(workers, "_warm", warm)
    sizes = []
    real = build.worker_pool

    @contextlib.contextmanager
    def pool(work, workers):
        with real(work, workers) as submit:
            yield lambda lots: (sizes.append(len(lots)), submit(lots))[1]

    monkeypatch.setattr(build, "worker_pool", pool)
    grammar = compile_grammar(write("g.cga", "Lot --> extrude(3)\n"))
    square = [[np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)]]
    derive(grammar, lots_from_polygons(square * lots), BuildOptions(workers=2))
    assert sizes == expected


def test_where_releases_are_held_the_workers_and_their_memory_files_stay_until_release_all():
    """A served build replies before its workers exit and its shared memory goes (``releases``)."""
    from grammarc import releases, workers

    releases.hold()
    try:
        with workers.worker_pool(_load_and_say, 2) as submit:
            for future in [submit([]), submit([])]:
                future.result(timeout=60)
            children = set(multiprocessing.active_children())
            folders = set(_record_folders())
        assert children and all(child.is_alive() for child in children)
        assert folders and all(folder.is_dir() for folder in folders)
        with workers.worker_pool(_load_and_say, 2) as submit:  # a command that derives again (a search)
            assert not any(child.is_alive() for child in children)  # lets go of the pool before first
            assert not any(folder.exists() for folder in folders)
            submit([]).result(timeout=60)
            children = set(multiprocessing.active_children())
            folders = set(_record_folders())
    finally:
        releases.release_all()
    assert not any(child.is_alive() for child in children)
    assert not any(folder.exists() for folder in folders)


def _record_folders():
    import tempfile
    from pathlib import Path

    shared = Path("/dev/shm") if Path("/dev/shm").is_dir() else Path(tempfile.gettempdir())
    return shared.glob(f"grammarc-records-{os.getpid()}-*")
