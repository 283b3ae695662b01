"""frontend/parsers.py and user_cache.py: the parsers' tables are cached in the user's own cache folder, never as a pickle in
the shared temp folder, and a cache that others could have written is not loaded."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _run(code: str, tmp_path: Path, **env) -> subprocess.CompletedProcess:
    """``code`` in a fresh Python (the parsers are cached per process), with its own temp and cache
    folders."""
    environment = {**os.environ, "TMPDIR": str(tmp_path / "tmp"), "XDG_CACHE_HOME": str(tmp_path / "cache"),
                   "PYTHONPATH": str(ROOT), **env}
    (tmp_path / "tmp").mkdir(exist_ok=True)
    return subprocess.run([sys.executable, "-c", code], env=environment, capture_output=True, text=True,
                          check=True)


PARSE = ("from grammarc.diagnostics import Diagnostics; from grammarc.frontend.parse import parse_source; "
         "print(parse_source('Lot --> A', 'g.cga', Diagnostics(), 'cityengine').rules[0].symbol)")


def test_no_pickle_in_the_temp_folder_and_a_private_cache(tmp_path):
    assert _run(PARSE, tmp_path).stdout.strip() == "Lot"
    assert list((tmp_path / "tmp").iterdir()) == []  # lark's cache=True writes .lark_cache_*.tmp here
    folder = tmp_path / "cache" / "grammarc"
    assert folder.stat().st_mode & 0o777 == 0o700
    (cached,) = folder.glob("*.lark")
    assert cached.name.startswith("cityengine-") and cached.stat().st_mode & 0o077 == 0
    # the second process loads it, and parses alike
    before = cached.stat().st_mtime_ns
    assert _run(PARSE, tmp_path).stdout.strip() == "Lot"
    assert cached.stat().st_mtime_ns == before


def _plant(path: Path) -> Path:
    """A pickle that writes a file when it is loaded; returns that file's path."""
    proof = path.parent / "ran"
    payload = f"import pickle, os\nclass P:\n    def __reduce__(self):\n" \
              f"        return (os.system, ('touch {proof}',))\nopen({str(path)!r}, 'wb').write(pickle.dumps(P()))\n"
    subprocess.run([sys.executable, "-c", payload], check=True)
    return proof


@pytest.mark.parametrize("mode", [0o770, 0o707])
def test_a_cache_folder_others_can_write_is_not_used(tmp_path, mode):
    _run(PARSE, tmp_path)  # the cache file's name
    folder = tmp_path / "cache" / "grammarc"
    (cached,) = folder.glob("*.lark")
    proof = _plant(cached)
    folder.chmod(mode)
    assert _run(PARSE, tmp_path).stdout.strip() == "Lot"
    assert not proof.exists()


def test_a_cache_file_others_can_write_is_not_loaded(tmp_path):
    _run(PARSE, tmp_path)
    (cached,) = (tmp_path / "cache" / "grammarc").glob("*.lark")
    proof = _plant(cached)
    cached.chmod(0o666)
    assert _run(PARSE, tmp_path).stdout.strip() == "Lot"
    assert not proof.exists()


def test_a_broken_cache_file_is_rebuilt(tmp_path):
    _run(PARSE, tmp_path)
    (cached,) = (tmp_path / "cache" / "grammarc").glob("*.lark")
    cached.write_bytes(b"\x80\x05 not a pickle")
    assert _run(PARSE, tmp_path).stdout.strip() == "Lot"
