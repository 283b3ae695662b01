"""Packages kept in the cache: one entry whoever makes it, a changed entry replaced, unused entries removed."""

import json
import os
import subprocess
import sys
import time

import pytest

from grammarc.errors import UsageError
from grammarc.io import kept_packages


@pytest.fixture
def entry(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    archive = tmp_path / "p.rpk"
    archive.write_bytes(b"the archive's bytes")
    return kept_packages.entry_of(archive)


def extract(text):
    def write(folder):
        (folder / "rules").mkdir(parents=True)
        (folder / "rules" / "a.cga").write_text(text)
    return write


def test_an_entry_is_named_by_the_archives_bytes(entry, tmp_path):
    other = tmp_path / "q.rpk"
    other.write_bytes(b"the archive's bytes")
    assert kept_packages.entry_of(other) == entry
    other.write_bytes(b"exported again")
    assert kept_packages.entry_of(other) != entry


def test_an_entry_made_by_another_process_meanwhile_is_taken_and_nothing_else_is_left(entry):
    made = kept_packages.keep(entry, extract("Lot --> X\n"), 1000)
    assert kept_packages.keep(entry, extract("Lot --> X\n"), 1000) == made
    assert sorted(p.name for p in entry.parent.iterdir()) == [entry.name]
    assert kept_packages.kept(entry, 1000) == made and (made / "rules" / "a.cga").read_text() == "Lot --> X\n"


def test_an_entry_whose_files_changed_is_not_used_and_is_replaced(entry):
    made = kept_packages.keep(entry, extract("Lot --> X\n"), 1000)
    (made / "rules" / "a.cga").write_text("Lot --> Y, a longer rule\n")
    assert kept_packages.kept(entry, 1000) is None
    assert kept_packages.keep(entry, extract("Lot --> X\n"), 1000) == made
    assert (made / "rules" / "a.cga").read_text() == "Lot --> X\n"
    assert sorted(p.name for p in entry.parent.iterdir()) == [entry.name]


def test_an_entry_larger_than_the_limit_is_not_used(entry):
    kept_packages.keep(entry, extract("Lot --> X\n"), 1000)
    assert kept_packages.kept(entry, 10) == entry / "package" and kept_packages.kept(entry, 9) is None


def test_a_failed_extraction_leaves_nothing(entry):
    def refused(folder):
        extract("Lot --> X\n")(folder)
        raise UsageError("too large")

    with pytest.raises(UsageError):
        kept_packages.keep(entry, refused, 1000)
    assert list(entry.parent.iterdir()) == []


def test_entries_unused_for_long_and_extractions_of_dead_processes_go_at_the_next_extraction(entry, tmp_path):
    old = kept_packages.keep(entry, extract("Lot --> X\n"), 1000).parent
    recent = entry.parent / "0123456789abcdef0123456789abcdef"
    kept_packages.keep(recent, extract("Lot --> Y\n"), 1000)
    past = time.time() - (kept_packages.UNUSED_DAYS + 1) * 86400
    os.utime(old / "files.json", (past, past))
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True, check=True).stdout.strip()
    (entry.parent / f"grammarc-rpk-{dead}-abcd1234" / "package").mkdir(parents=True)  # a SIGKILLed build's
    kept_packages.keep(entry.parent / "fedcba9876543210fedcba9876543210", extract("Lot --> Z\n"), 1000)
    assert sorted(p.name for p in entry.parent.iterdir()) == sorted([recent.name, "fedcba9876543210fedcba9876543210"])
    assert json.loads((recent / "files.json").read_text())["bytes"] == len("Lot --> Y\n")


def test_two_processes_extracting_one_package_at_once_both_build_and_one_entry_stays(tmp_path):
    """Real processes, started together on an empty cache: each extracts, one entry is renamed into place and
    the other process takes it."""
    py7zr = pytest.importorskip("py7zr")
    archive = tmp_path / "p.rpk"
    with py7zr.SevenZipFile(archive, "w") as package:
        package.writestr(b"@StartRule\nLot --> X\n" * 2000, "rules/a.cga")
        package.writestr(b"v 0 0 0\n" * 20000, "assets/a.obj")
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path / "cache")}
    script = ("import sys\nfrom grammarc.io.rpk import open_rpk\n"
              "with open_rpk(sys.argv[1]) as rpk:\n    print(rpk.root, rpk.start_rule)\n")
    runs = [subprocess.Popen([sys.executable, "-c", script, str(archive)], env=env, stdout=subprocess.PIPE,
                             text=True) for _ in range(2)]
    said = [run.communicate(timeout=120)[0].split() for run in runs]
    assert [run.returncode for run in runs] == [0, 0]
    assert said[0] == said[1] and said[0][1] == "Lot"
    cache = tmp_path / "cache" / "grammarc" / "rpk"
    assert [p.name for p in cache.iterdir()] == [os.path.basename(os.path.dirname(said[0][0]))]
