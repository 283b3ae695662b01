"""Generated modules in the user's cache folder: named by their text's digest, imported only as written,
their code kept beside them, compiled once enough shapes came."""

from __future__ import annotations

import builtins
import hashlib
import importlib.util
import marshal
import os
import subprocess
import sys

import pytest

from grammarc.backend.fusion import compiled

TEXT = '''"""A stand-in for a generated module."""
import numpy as np
from numba import njit


@njit(cache=True)
def derive(x):
    return x + 1
'''


@pytest.fixture(autouse=True)
def own_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    return tmp_path / "grammarc" / "fusion"


def test_a_module_is_written_under_its_digest_and_imported_from_there(own_cache):
    module, path = compiled.load(TEXT)
    assert path == own_cache / f"region_{compiled.digest(TEXT)}.py"
    assert path.read_text() == TEXT and oct(path.stat().st_mode & 0o777) == "0o600"
    assert module.derive(1) == 2


def test_a_file_that_does_not_hold_the_text_is_written_again(own_cache):
    _, path = compiled.load(TEXT)
    path.write_text(TEXT.replace("x + 1", "x + 2"))
    module, again = compiled.load(TEXT)
    assert again == path and path.read_text() == TEXT and module.derive(1) == 2


def _counting_compiles(monkeypatch, path) -> list:
    """The compilations of the module at ``path`` from now on."""
    compiles, compile_ = [], builtins.compile

    def counting(source, filename, *args, **kwargs):
        if filename == str(path):
            compiles.append(filename)
        return compile_(source, filename, *args, **kwargs)

    monkeypatch.setattr(builtins, "compile", counting)
    return compiles


def _written(folder) -> list:
    """The files in ``folder`` but for numba's cache (``__pycache__``, which it makes when a kernel is
    defined)."""
    return sorted(p for p in folder.iterdir() if p.name != "__pycache__")


def _kept(path):
    return path.with_name(f"{path.stem}.{sys.implementation.cache_tag}.code")


def test_a_modules_code_is_kept_beside_it_and_not_compiled_again(own_cache, monkeypatch):
    """A second load takes the kept code object (Python keeps none where bytecode may not be written), which
    names the generated file: numba's cache finds the kernel's machine code by its file and line."""
    path = own_cache / f"region_{compiled.digest(TEXT)}.py"
    compiles = _counting_compiles(monkeypatch, path)
    first, _ = compiled.load(TEXT)
    assert compiles == [str(path)]
    assert _written(own_cache) == [_kept(path), path]  # nothing else
    assert oct(_kept(path).stat().st_mode & 0o777) == "0o600"
    first.derive(1)  # compiled by numba, its machine code cached
    again, _ = compiled.load(TEXT)
    assert compiles == [str(path)]  # not compiled again
    assert again.derive(1) == 2 and again.derive.py_func.__code__.co_filename == str(path)
    assert again.derive.stats.cache_hits and not again.derive.stats.cache_misses


@pytest.mark.parametrize("damage", ["empty", "truncated", "flipped", "another Python", "another text",
                                    "another file", "not code"])
def test_a_damaged_or_stale_kept_code_is_compiled_again_and_replaced(own_cache, monkeypatch, damage):
    """Kept code that is cut short or garbled, of another Python (magic number), of another text, naming
    another file (a moved cache folder) or not code at all is not run: the text is compiled and kept anew."""
    _, path = compiled.load(TEXT)
    kept = _kept(path).read_bytes()
    header = kept[:len(importlib.util.MAGIC_NUMBER) + 32]
    other_file = compile(TEXT, str(path.with_name("moved.py")), "exec", dont_inherit=True)
    _kept(path).write_bytes({
        "empty": b"",
        "truncated": kept[:len(kept) // 2],
        "flipped": kept[:len(header)] + bytes(b ^ 0xFF for b in kept[len(header):]),
        "another Python": bytes([kept[0] ^ 1]) + kept[1:],
        "another text": importlib.util.MAGIC_NUMBER + hashlib.sha256(b"x").digest() + kept[len(header):],
        "another file": header + marshal.dumps(other_file),
        "not code": header + marshal.dumps("derive"),
    }[damage])
    compiles = _counting_compiles(monkeypatch, path)
    module, _ = compiled.load(TEXT)
    assert module.derive(1) == 2 and compiles == [str(path)]
    assert _kept(path).read_bytes() == kept  # replaced
    compiled.load(TEXT)
    assert compiles == [str(path)]


def test_kept_code_appears_whole_or_not_at_all(own_cache, monkeypatch):
    """The kept code is written to a temporary file and renamed onto its name: a process loading the same
    region meanwhile finds no file (and compiles) or the whole of it, never a part."""
    path = own_cache / f"region_{compiled.digest(TEXT)}.py"
    renames, replace = [], os.replace

    def renaming(source, target):
        if target == _kept(path):
            assert not os.path.exists(target)
            with open(source, "rb") as file:
                data = file.read()
            renames.append(marshal.loads(data[len(importlib.util.MAGIC_NUMBER) + 32:]).co_filename)
        replace(source, target)

    monkeypatch.setattr(os, "replace", renaming)
    compiled.load(TEXT)
    assert renames == [str(path)]
    assert _written(own_cache) == [_kept(path), path]  # no temporary file is left


def test_a_kernel_is_ready_once_enough_shapes_came_or_once_compiled(own_cache):
    text = TEXT.replace("stand-in", "second stand-in")
    assert not compiled.ready(text, 6_000, 10_000)
    assert compiled.ready(text, 6_000, 10_000)  # 12,000 in all
    other = TEXT.replace("stand-in", "third stand-in")
    _, path = compiled.load(other)
    path.with_suffix(".compiled").touch(mode=0o600)
    assert compiled.ready(other, 1, 10_000)


def test_a_module_the_cache_cannot_take_goes_to_a_private_folder_removed_at_exit(tmp_path):
    """A cache folder that others may write is not used: the module is imported from a folder of the
    process's own in the temp folder, which is gone once the process (or a forked worker) ends, as are
    those of processes that were killed."""
    shared, temp = tmp_path / "shared", tmp_path / "temp"
    (shared / "grammarc").mkdir(parents=True)
    (shared / "grammarc").chmod(0o777)
    temp.mkdir()
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True, check=True).stdout.strip()
    (temp / f"grammarc-fusion-{dead}-stale").mkdir()
    script = f"""
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from grammarc.backend.fusion import compiled
def in_worker(_):
    module, path = compiled.load({TEXT!r}.replace("stand-in", "worker's stand-in"))
    return str(path.parent)
module, path = compiled.load({TEXT!r})
assert module.derive(1) == 2 and str(path.parent.parent) == {str(temp)!r}, path
compiled._private_folder.cache_clear()  # as a worker forked before the folder was made
with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("fork")) as pool:  # as workers.py
    print(pool.submit(in_worker, 0).result(), path.parent)
"""
    env = {**os.environ, "XDG_CACHE_HOME": str(shared), "TMPDIR": str(temp)}
    run = subprocess.run([sys.executable, "-c", script], check=False, env=env, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    worker, own = run.stdout.split()
    assert worker != own and list(temp.iterdir()) == []


def test_the_modules_of_compiled_kernels_are_imported_for_a_warm_server(own_cache, monkeypatch):
    monkeypatch.setattr(compiled, "_KERNELS", {})
    marked, unmarked = TEXT.replace("stand-in", "marked stand-in"), TEXT.replace("stand-in", "unmarked stand-in")
    for text in (marked, unmarked):
        compiled.load(text)
    (own_cache / f"region_{compiled.digest(marked)}.compiled").touch(mode=0o600)
    stale = own_cache / f"region_{compiled.digest('another text')}"  # a mark whose module holds another text
    stale.with_suffix(".py").write_text(TEXT)
    stale.with_suffix(".compiled").touch(mode=0o600)
    assert compiled.import_compiled() == 1
    assert list(compiled._KERNELS) == [marked] and compiled._KERNELS[marked](1) == 2
    assert compiled.import_compiled() == 0  # imported once
