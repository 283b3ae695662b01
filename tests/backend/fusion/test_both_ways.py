"""Fused kernels and the interpreter give the same records: every build of ``tools/replay.py`` whose grammar
has fused regions (examples, benchmark grammars, the tests' grammars, rule packages) is derived both ways and
its digest compared (records, reports, bad lots)."""

from __future__ import annotations

import atexit
import importlib.util
import shutil
import tempfile
from pathlib import Path

import pytest
from test_fused import fused_always  # noqa: F401 - an autouse fixture: kernels for every batch

from grammarc.backend.fusion.regions import SWITCH
from grammarc.backend.plan import make_plan
from grammarc.build import compile_source, grammar_source

ROOT = Path(__file__).resolve().parents[3]


def _replay():
    spec = importlib.util.spec_from_file_location("replay", ROOT / "tools" / "replay.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


REPLAY = _replay()
#: The replay's lots, written when the cases are collected (the parameters need them), removed at exit.
LOTS = Path(tempfile.mkdtemp(prefix="grammarc-fusion-lots-"))
atexit.register(shutil.rmtree, LOTS, True)


def _plan(grammar: Path, options):
    """The plan of ``grammar`` (a rule file, or a package's main one) as a build makes it."""
    with grammar_source(grammar, options) as (source, display, resolved):
        return make_plan(compile_source(source, display, resolved))


def _fused_cases():
    fused = {}
    for name, grammar, lots, options in REPLAY.cases(LOTS):
        if grammar not in fused:
            fused[grammar] = bool(_plan(grammar, options).fused)
        if fused[grammar]:
            yield pytest.param(grammar, lots, options, id=name)


@pytest.mark.parametrize(("grammar", "lots", "options"), list(_fused_cases()))
def test_fused_and_interpreted_records_are_the_same(grammar, lots, options, tmp_path, monkeypatch):
    fused = REPLAY.digest(grammar, lots, options, tmp_path)
    monkeypatch.setenv(SWITCH, "off")
    assert not _plan(grammar, options).fused
    assert REPLAY.digest(grammar, lots, options, tmp_path) == fused
