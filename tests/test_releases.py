"""``releases``: work run at once in a command's own process, kept until after the reply in a served one."""

import os
import sys

import pytest

from grammarc import releases


@pytest.fixture
def held():
    releases.hold()
    yield
    releases.release_all()


def test_a_release_runs_at_once_where_releases_are_not_held():
    done = []
    releases.later(lambda: done.append(1))
    assert done == [1] and not releases.holding()


def test_held_releases_run_in_order_at_release_all_and_a_failing_one_stops_none(held):
    done = []
    releases.later(lambda: done.append(1))
    releases.later(lambda: 1 / 0)
    releases.later(lambda: done.append(2))
    assert done == [] and releases.holding()
    releases.release_all()
    assert done == [1, 2] and not releases.holding()


def test_a_flush_runs_what_is_held_and_goes_on_holding(held):
    done = []
    releases.later(lambda: done.append(1))
    releases.flush()
    releases.later(lambda: done.append(2))
    assert done == [1] and releases.holding()
    releases.release_all()
    assert done == [1, 2]


def _deleted_but_open(inode: int) -> bool:
    """Whether this process holds a descriptor of the file ``inode`` that has no name any more."""
    for fd in os.listdir("/proc/self/fd"):
        try:
            status = os.fstat(int(fd))
        except OSError:
            continue
        if status.st_ino == inode and status.st_nlink == 0:
            return True
    return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/fd")
def test_a_replaced_file_is_freed_only_at_release_all_where_releases_are_held(tmp_path, held):
    path, new = tmp_path / "out.npz", tmp_path / "new.npz"
    path.write_bytes(b"old" * 1000)
    new.write_bytes(b"new")
    inode = path.stat().st_ino
    releases.replace(new, path)
    assert path.read_bytes() == b"new" and not new.exists()
    assert _deleted_but_open(inode)
    releases.release_all()
    assert not _deleted_but_open(inode)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/fd")
def test_a_replaced_file_is_freed_at_once_where_releases_are_not_held(tmp_path):
    path, new = tmp_path / "out.npz", tmp_path / "new.npz"
    path.write_bytes(b"old")
    new.write_bytes(b"new")
    inode = path.stat().st_ino
    releases.replace(new, path)
    assert path.read_bytes() == b"new" and not _deleted_but_open(inode)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="FIFOs")
def test_replacing_a_fifo_or_a_link_neither_blocks_nor_follows_it(tmp_path, held):
    fifo, link, target = tmp_path / "fifo", tmp_path / "link", tmp_path / "target"
    os.mkfifo(fifo)
    target.write_bytes(b"kept")
    link.symlink_to(target)
    for path in (fifo, link):
        new = tmp_path / "new"
        new.write_bytes(b"new")
        releases.replace(new, path)  # opening the FIFO to read would wait for a writer
        assert path.read_bytes() == b"new" and not path.is_symlink()
    assert target.read_bytes() == b"kept"
