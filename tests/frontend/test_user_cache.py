"""frontend/user_cache.py's code stamp: the files it covers are the package's sources and grammars, in the
order of their paths, past the ``__pycache__`` folders."""

from grammarc.frontend.user_cache import _sources


def test_sources_are_the_py_and_lark_files_in_path_order(tmp_path):
    for name in ("a.py", "a/b.py", "a/c.lark", "a.lark", "b/__pycache__/x.py", "b/y.pyc", "b/z.txt", "ab/d.py"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(name)
    found = sorted(_sources(str(tmp_path), ()))
    listed = ["/".join(parts) for parts, _ in found]
    rglob = sorted([*tmp_path.rglob("*.py"), *tmp_path.rglob("*.lark")])
    assert listed == [p.relative_to(tmp_path).as_posix() for p in rglob if "__pycache__" not in p.parts]
    assert listed == ["a/b.py", "a/c.lark", "a.lark", "a.py", "ab/d.py"]
    assert [info.st_size for _, info in found] == [len(name) for name in listed]


def test_the_code_stamp_is_the_same_whichever_name_started_python(monkeypatch, tmp_path):
    """``python3``, ``python`` and the ``grammarc`` script's interpreter are one program: a server started
    by one serves a command started by another."""
    import sys

    from grammarc.frontend.user_cache import code_stamp

    code_stamp = code_stamp.__wrapped__  # not the process's, which is kept once made
    stamp = code_stamp()
    other_name = tmp_path / "python-other-name"
    other_name.symlink_to(sys.executable)
    monkeypatch.setattr(sys, "executable", str(other_name))
    assert code_stamp() == stamp
    monkeypatch.setattr(sys, "prefix", str(tmp_path))  # another environment of the same interpreter
    assert code_stamp() != stamp
