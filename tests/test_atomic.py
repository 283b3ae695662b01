"""atomic.py: a file written through ``replacing`` is complete or unchanged, and nothing is left beside it."""

from __future__ import annotations

import pytest

from grammarc.atomic import replacing


def test_the_new_contents_replace_the_file_with_nothing_left_beside_it(tmp_path):
    path = tmp_path / "city.reports.json"
    path.write_text("old")
    with replacing(path) as tmp:
        assert tmp.parent != tmp_path and tmp.name == path.name  # beside it, its own name (writers read the suffix)
        tmp.write_text("new")
        assert path.read_text() == "old"  # not yet
    assert path.read_text() == "new" and [p.name for p in tmp_path.iterdir()] == ["city.reports.json"]


def test_a_failed_write_leaves_the_file_as_it_was(tmp_path):
    path = tmp_path / "city.png"
    path.write_text("old")
    with pytest.raises(RuntimeError), replacing(path) as tmp:
        tmp.write_text("half")
        raise RuntimeError("the writer failed")
    assert path.read_text() == "old" and [p.name for p in tmp_path.iterdir()] == ["city.png"]
