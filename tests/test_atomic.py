"""atomic.py: a file written through ``replacing`` is complete or unchanged, and nothing is left beside it."""

from __future__ import annotations

import pytest

from grammarc.atomic import replace_folder, replacing


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


#: Above Linux's largest process id (2^22): never a running process.
GONE = 4_194_305


def test_the_temporary_folders_of_dead_runs_go_at_the_next_run(tmp_path):
    import os

    from grammarc.atomic import private_folder

    dead = tmp_path / f".city.npz.tmp{GONE}-abc"
    alive = tmp_path / f".city.npz.tmp{os.getpid()}-def"
    other = tmp_path / f".town.npz.tmp{GONE}-ghi"  # another output's: not this one's to judge
    for folder in (dead, alive, other):
        folder.mkdir()
        (folder / "part").write_bytes(b"x")
    new = private_folder(tmp_path / "city.npz")
    assert not dead.exists() and alive.exists() and other.exists()
    assert new.startswith(str(tmp_path / f".city.npz.tmp{os.getpid()}-"))


def test_an_output_of_the_longest_legal_name_has_a_legal_temporary_folder(tmp_path):
    path = tmp_path / ("x" * 251 + ".npz")  # 255 bytes, the longest name Linux allows
    with replacing(path) as tmp:
        tmp.write_text("new")
    assert path.read_text() == "new" and [p.name for p in tmp_path.iterdir()] == [path.name]


def test_a_folder_replaces_the_old_one_whole(tmp_path):
    target, new, aside = tmp_path / "city.obj.textures", tmp_path / "staged", tmp_path / "aside"
    for folder, name in ((target, "old.png"), (new, "new.png")):
        (folder / "sub").mkdir(parents=True)
        (folder / "sub" / name).write_text(name)
    replace_folder(new, target, aside)
    assert [p.name for p in target.rglob("*.png")] == ["new.png"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["city.obj.textures"]
    (tmp_path / "again").mkdir()
    replace_folder(tmp_path / "again", tmp_path / "fresh", aside)  # nothing there before
    assert (tmp_path / "fresh").is_dir() and not (tmp_path / "again").exists()
