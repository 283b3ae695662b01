"""frontend/lowered_cache.py: a file's lowering is kept, and given back only for the same text, name,
dialect and first site; files with errors are not kept; the folder keeps the files used last."""

from __future__ import annotations

import pytest

from grammarc.diagnostics import Diagnostics
from grammarc.frontend import lowered_cache, parse
from grammarc.frontend.sites import Sites
from grammarc.ir.printer import print_module

TEXT = 'version "2023.0"\n@Odd\nattr height = rand(3, 9)\nLot --> extrude(height) split(y){ 3 : Floor }*\n'


@pytest.fixture(autouse=True)
def cache_home(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    return tmp_path / "cache" / "grammarc" / "lowered"


def _parse(text: str = TEXT, file: str = "g.cga", sites: Sites | None = None):
    diags = Diagnostics()
    return parse.parse_source(text, file, diags, "cityengine", sites=sites), diags


def test_a_kept_lowering_gives_the_same_module_and_warnings_without_parsing(monkeypatch, cache_home):
    first, said = _parse()
    assert len(list(cache_home.iterdir())) == 1 and [d.code for d in said] == ["annotation"]
    monkeypatch.setattr(parse, "_lower", lambda *args: pytest.fail("parsed again"))
    again, said_again = _parse()
    assert print_module(again) == print_module(first) and said_again == said


@pytest.mark.parametrize("change", ["text", "file", "site"])
def test_another_text_name_or_first_site_is_lowered_anew(monkeypatch, cache_home, change):
    from_one = Sites()
    _parse(sites=from_one)
    lowered = []
    real = parse._lower
    monkeypatch.setattr(parse, "_lower", lambda *args: (lowered.append(1), real(*args))[1])
    sites = Sites(7) if change == "site" else None
    _parse(TEXT + "Floor --> X\n" if change == "text" else TEXT,
           "h.cga" if change == "file" else "g.cga", sites)
    assert lowered == [1] and len(list(cache_home.iterdir())) == 2
    if change == "site":  # its random sites are numbered from 7: kept apart from those numbered from 1
        assert sites.next_site - 7 == from_one.next_site - 1


def test_a_file_with_an_error_is_not_kept(cache_home):
    _, said = _parse("Lot --> extrude(\n")
    assert said.has_errors and not list(cache_home.iterdir())


def test_the_files_used_last_are_kept_and_old_temporary_files_go(monkeypatch, cache_home):
    import os

    monkeypatch.setattr(lowered_cache, "MAX_FILES", 2)
    _parse()
    left, fresh = cache_home / "x.pickle123.tmp", cache_home / "y.pickle456.tmp"  # a killed store's, another's
    left.write_bytes(b"")
    fresh.write_bytes(b"")
    os.utime(left, (0, 0))
    for k in range(3):
        _parse(TEXT + f"A{k} --> X\n")
    assert len(list(cache_home.glob("*.pickle"))) == 2 and not left.exists() and fresh.exists()
