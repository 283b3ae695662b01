"""Generated modules in the user's cache folder: named by their text's digest, imported only as written,
compiled once enough shapes came."""

from __future__ import annotations

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


def test_a_kernel_is_ready_once_enough_shapes_came_or_once_compiled(own_cache):
    text = TEXT.replace("stand-in", "second stand-in")
    assert not compiled.ready(text, 6_000, 10_000)
    assert compiled.ready(text, 6_000, 10_000)  # 12,000 in all
    other = TEXT.replace("stand-in", "third stand-in")
    _, path = compiled.load(other)
    path.with_suffix(".compiled").touch(mode=0o600)
    assert compiled.ready(other, 1, 10_000)
