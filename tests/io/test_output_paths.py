"""output_paths.py: every path a build will write is checked before it derives, one reason each."""

from __future__ import annotations

import os

import pytest

from grammarc.errors import UsageError
from grammarc.io import written_paths
from grammarc.io.output_paths import check_writable


def test_a_folder_above_that_is_missing_is_fine_and_a_good_path_passes(tmp_path):
    check_writable([tmp_path / "new" / "deeper" / "city.npz", tmp_path / "city.npz"], [tmp_path / "x.tiles"])


def _folder(tmp_path):
    (tmp_path / "city.npz").mkdir()
    return tmp_path / "city.npz"


def _under_a_file(tmp_path):
    (tmp_path / "file").write_text("x")
    return tmp_path / "file" / "city.npz"


@pytest.mark.parametrize("make, reason", [
    (_folder, "it is a folder"),
    (_under_a_file, "is a file, not a folder"),
    (lambda tmp_path: tmp_path / ("x" * 252 + ".npz"), "256 bytes long, longer than the 255 a file name may have"),
])
def test_a_path_that_cannot_be_written_is_refused_naming_it(tmp_path, make, reason):
    path = make(tmp_path)
    with pytest.raises(UsageError, match=reason) as error:
        check_writable([path])
    assert str(path) in str(error.value) and "\n" not in str(error.value)


def test_the_tile_folder_of_usd_counts_with_its_digest(tmp_path):
    files, folders = written_paths(tmp_path / "c.usdc")
    assert files == [tmp_path / "c.usdc"] and folders[0].name.startswith("c.usdc.tiles-")
    legal = "x" * 250 + ".usdc"  # 255 bytes, its tile folder's name longer
    with pytest.raises(UsageError, match=r"\.tiles-0+`: its name is"):
        check_writable(*written_paths(tmp_path / legal))


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes to any folder")
def test_a_folder_that_is_not_writable_is_refused(tmp_path):
    folder = tmp_path / "locked"
    folder.mkdir(mode=0o555)
    with pytest.raises(UsageError, match="is not writable"):
        check_writable([folder / "city.npz"])
