"""Rule packages: the kit's eight .rpk files opened, their start rules, assets, the packages kept in the
cache, and the temporary files."""

import gc
import json
import os
import sys
from pathlib import Path

import pytest

from grammarc.errors import UsageError
from grammarc.io.rpk import open_rpk, start_rule_of
from grammarc.ir.asset_names import resolve_asset

py7zr = pytest.importorskip("py7zr")

KIT = Path(__file__).resolve().parents[2].parent / "shared" / "prt"
needs_kit = pytest.mark.skipif(not (KIT / "rpk").is_dir(), reason="PRT kit (../shared/prt) absent")


@pytest.fixture(autouse=True)
def own_cache(tmp_path_factory, monkeypatch):
    """A cache folder of the test's own, where packages are kept (``io.kept_packages``)."""
    cache = tmp_path_factory.mktemp("cache")
    monkeypatch.setenv("XDG_CACHE_HOME", str(cache))
    return cache / "grammarc" / "rpk"

#: Start rules as read from the CGA sources; PRT names them "Default$" + the rule (reference.json).
START_RULES = {
    "candler": "Footprint",
    "extrusion_rule": "Footprint",
    "extrude_color": "Init",
    "translateModel": "Lot",
    "reporting": "Lot",
    "genattrs": "Init",
    "massing": "Lot",
    "complexpatterns": "Lot",
}


@pytest.fixture(scope="module")
def reference():
    return json.loads((KIT / "reference.json").read_text(encoding="utf-8"))


@needs_kit
@pytest.mark.parametrize("name", sorted(START_RULES))
def test_kit_package(name, reference):
    info = reference["rpks"][name]
    with open_rpk(KIT / "rpk" / f"{name}.rpk") as rpk:
        assert list(rpk.rules) == sorted(info["cga_sources"])
        assert rpk.start_rule == START_RULES[name]
        assert info["start_rules"] == [f"Default${rpk.start_rule}"]
        assert rpk.main_rule_file.stem == Path(info["main_cgb"]).stem
        assert rpk.compiled == [info["main_cgb"]]
        assert all(path.is_file() for path in rpk.rules.values())
        lines = sum(len(p.read_text(encoding="utf-8").splitlines()) for p in rpk.rules.values())
        assert lines == info["cga_lines"]
        has_assets = (rpk.root / "assets").is_dir()
        assert rpk.assets_root == (rpk.root / "assets" if has_assets else rpk.root)
        assert rpk.asset_roots[-1] == rpk.root


@needs_kit
def test_candler_assets_resolve_in_assets_folder():
    # Candler inserts i("facade/windows/win.single.05.sashwindow.obj"): CityEngine finds it in assets/.
    with open_rpk(KIT / "rpk" / "candler.rpk") as rpk:
        resolved = resolve_asset("facade/windows/win.single.05.sashwindow.obj", list(rpk.asset_roots))
        assert resolved.path == rpk.root / "assets" / "facade" / "windows" / "win.single.05.sashwindow.obj"
        assert rpk.rules["rules/Candler Building.cga"] == rpk.main_rule_file


@needs_kit
def test_temporary_files_removed(tmp_path):
    with open_rpk(KIT / "rpk" / "extrude_color.rpk", tmpdir=tmp_path) as rpk:
        root = rpk.root
        assert root.parent == tmp_path and root.is_dir() and not rpk.closed
    assert rpk.closed and not root.exists()
    rpk.close()  # idempotent

    dropped = open_rpk(KIT / "rpk" / "extrude_color.rpk", tmpdir=tmp_path)
    root = dropped.root
    del dropped
    gc.collect()
    assert not root.exists()
    assert list(tmp_path.iterdir()) == []


def make_rpk(path: Path, files: dict[str, str]) -> Path:
    """A 7-zip archive holding ``files`` (name in the archive -> text)."""
    with py7zr.SevenZipFile(path, "w") as archive:
        for name, text in files.items():
            archive.writestr(text.encode(), name)
    return path


def test_main_rule_file_choice(tmp_path):
    # No compiled rules: the one .cga with a @StartRule is the main file.
    package = make_rpk(tmp_path / "two.rpk", {
        "rules/lib.cga": "Helper --> X\n",
        "rules/main.cga": '/* @StartRule Fake --> */\n@StartRule\n@Description("a) b")\nLot(h) -->\n X\n',
    })  # fmt: skip
    with open_rpk(package) as rpk:
        assert rpk.main_rule_file.name == "main.cga"
        assert rpk.start_rule == "Lot"
        assert rpk.assets_root == rpk.root
    # The .cga named as the compiled rule file wins, even without @StartRule.
    package = make_rpk(tmp_path / "cgb.rpk", {
        "rules/a.cga": "@StartRule\nA --> X\n", "rules/b.cga": "B --> X\n", "bin/b.cgb": "",
    })  # fmt: skip
    with open_rpk(package) as rpk:
        assert rpk.main_rule_file.name == "b.cga" and rpk.start_rule is None
    # No sources at all.
    with open_rpk(make_rpk(tmp_path / "bin.rpk", {"bin/x.cgb": ""})) as rpk:
        assert rpk.rules == {} and rpk.main_rule_file is None and rpk.start_rule is None


def test_start_rule_of(write):
    text = "// @StartRule\nA --> X\n@StartRule Footprint --> B\n"
    assert start_rule_of(write("a.cga", text)) == "Footprint"
    assert start_rule_of(write("b.cga", 'attr s = "// @StartRule"\nA --> X\n')) is None
    assert start_rule_of(write("c.cga", "@StartRule\n@Hidden\n\n  Init -->\n")) == "Init"


def test_errors(tmp_path, monkeypatch):
    with pytest.raises(UsageError, match="does not exist"):
        open_rpk(tmp_path / "missing.rpk")
    (tmp_path / "text.rpk").write_text("not an archive")
    with pytest.raises(UsageError, match="cannot read rule package"):
        open_rpk(tmp_path / "text.rpk")
    (tmp_path / "evil.cga").write_text("A --> X\n")
    with py7zr.SevenZipFile(tmp_path / "evil.rpk", "w") as archive:
        archive.write(tmp_path / "evil.cga", arcname="../evil.cga")  # writestr refuses this name
    (tmp_path / "evil.cga").unlink()
    (tmp_path / "out").mkdir()
    with pytest.raises(UsageError, match="leaves the package"):
        open_rpk(tmp_path / "evil.rpk", tmpdir=tmp_path / "out")
    assert not (tmp_path / "evil.cga").exists() and list((tmp_path / "out").iterdir()) == []
    monkeypatch.setitem(sys.modules, "py7zr", None)  # import py7zr now raises ImportError
    with pytest.raises(UsageError, match=r"grammarc\[rpk\]"):
        open_rpk(tmp_path / "text.rpk")


@needs_kit
def test_a_package_builds_to_the_same_bytes_each_time(tmp_path):
    """The package is extracted to a new temporary folder each run; the record must not name it."""
    from grammarc.build import build

    outputs = [tmp_path / f"run{k}.npz" for k in range(2)]
    for out in outputs:
        build(KIT / "rpk" / "complexpatterns.rpk", out)
    assert outputs[0].read_bytes() == outputs[1].read_bytes()


@needs_kit
def test_a_package_is_its_own_workspace():
    """Workspace paths of a package's rules are looked up in its `.ws` folder and in the package, never
    in the folders around the extracted package."""
    from grammarc.frontend.imports import find_roots

    with open_rpk(KIT / "rpk" / "candler.rpk") as rpk:
        assert rpk.workspace == rpk.root / ".ws"
        roots = find_roots(rpk.main_rule_file, rpk.workspace)
        assert roots.project == rpk.root.resolve() and rpk.root.parent.resolve() not in roots.folders


def test_a_record_of_a_package_loads_the_package_assets_again(own_cache, tmp_path, capsys):
    """The record names the .rpk, not the folder it was extracted to: ``info`` and ``render`` extract it
    again and load the package's own assets (they said "not loaded" and drew boxes)."""
    from grammarc.build import build
    from grammarc.cli import main
    from grammarc.io.npz import load_record
    from grammarc.io.rpk import record_asset_roots
    from grammarc.io.summary import summarize

    package = make_rpk(tmp_path / "posts.rpk", {
        "rules/posts.cga": '@StartRule\nLot --> extrude(2) i("props/post.obj")\n',
        "assets/props/post.obj": "v 0 0 0\nv 1 0 0\nv 1 3 0\nv 0 3 1\nf 1 2 3\nf 1 3 4\n",
    })  # fmt: skip
    (tmp_path / "lot.geojson").write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [
            [[0, 0], [4, 0], [4, 4], [0, 4], [0, 0]]]}}]}))
    build(package, tmp_path / "posts.npz", lots_path=tmp_path / "lot.geojson")
    meta = load_record(tmp_path / "posts.npz")["meta"]
    with record_asset_roots(meta) as roots:
        assert (roots[0] / "props" / "post.obj").is_file() and roots[-1] == tmp_path
    assert roots[0].parent.parent.parent == own_cache  # the package kept by the build
    with record_asset_roots({"grammar": str(tmp_path / "x.cga")}, [tmp_path]) as roots:
        assert roots == [tmp_path]  # not a package: the roots as given
    info = summarize(tmp_path / "posts.npz")
    assert info["assets"]["props/post.obj"] == {"instances": 1, "polygons": 2, "triangles": 2}
    assert not info["problems"]
    assert main(["render", str(tmp_path / "posts.npz"), "-o", str(tmp_path / "posts.png")]) == 0
    assert "drawn as boxes" not in capsys.readouterr().err


@pytest.fixture(scope="module")
def bomb(tmp_path_factory):
    """A package of 5 KB whose asset decompresses to 32 MiB of zeros (a zip bomb, small)."""
    path = tmp_path_factory.mktemp("bomb") / "bomb.rpk"
    with py7zr.SevenZipFile(path, "w", filters=[{"id": py7zr.FILTER_LZMA2, "preset": 1}]) as archive:
        archive.writestr(b"Lot --> X\n", "rules/a.cga")
        archive.writestr(b"\0" * (32 << 20), "assets/zero.bin")
    return path


def test_a_package_that_extracts_to_more_than_a_thousand_times_its_size_is_refused(bomb, tmp_path):
    assert bomb.stat().st_size < 10_000
    with pytest.raises(UsageError, match=r"bomb.rpk` extracts to more than [\d,]+ bytes \(at `assets/zero.bin`\)"):
        open_rpk(bomb, tmpdir=tmp_path)
    assert list(tmp_path.iterdir()) == []  # nothing left of the extraction


def test_a_package_past_max_package_size_is_refused(tmp_path):
    package = make_rpk(tmp_path / "p.rpk", {"rules/a.cga": "Lot --> X\n" * 10, "assets/a.obj": "v 0 0 0\n" * 50})
    with open_rpk(package, max_size=600) as rpk:
        assert rpk.main_rule_file.read_text() == "Lot --> X\n" * 10
    with pytest.raises(UsageError, match="extracts to more than 499 bytes"):  # 100 + 400
        open_rpk(package, max_size=499)


def test_the_command_refuses_a_bomb_in_one_line_exit_2(bomb, tmp_path, capsys):
    from grammarc.cli import main

    assert main(["build", str(bomb), "--emit", str(tmp_path / "c.npz"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "extracts to more than" in err and "--max-package-size" in err
    assert main(["check", str(bomb), "--max-package-size", "1K"]) == 2


def test_a_bomb_is_refused_with_little_memory(bomb, tmp_path):
    """Decompressed a few MiB at a time: the 32 MiB member is not held whole before it is refused."""
    import subprocess

    # the peak resident memory of the process (VmHWM: ru_maxrss would be the forking pytest's), in KiB
    peak = "int(open('/proc/self/status').read().split('VmHWM:')[1].split()[0])"
    script = ("import py7zr\nfrom grammarc.io.rpk import open_rpk\n"
              f"before = {peak}\n"
              f"try:\n    open_rpk({str(bomb)!r}, tmpdir={str(tmp_path)!r})\nexcept Exception:\n    pass\n"
              f"print({peak} - before)")
    grown = int(subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout)
    assert grown < 24 << 10


@needs_kit
def test_extracting_a_package_leaves_no_file_open():
    """py7zr given the archive's path extracts the blocks of an archive of several (candler's) in threads
    that each leave it open: a ResourceWarning each."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with open_rpk(KIT / "rpk" / "candler.rpk"):
            pass
        gc.collect()
    assert [w for w in caught if issubclass(w.category, ResourceWarning)] == []


@needs_kit
def test_an_extraction_whose_process_died_goes_at_the_next_open(tmp_path):
    import subprocess

    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True, check=True).stdout.strip()
    left = tmp_path / f"grammarc-rpk-{dead}-candler-abcd1234"  # a SIGKILLed build's
    running = tmp_path / f"grammarc-rpk-{os.getpid()}-candler-efgh5678"
    for folder in (left, running):
        (folder / "rules").mkdir(parents=True)
    with open_rpk(KIT / "rpk" / "extrude_color.rpk", tmpdir=tmp_path) as rpk:
        assert rpk.root.name.startswith(f"grammarc-rpk-{os.getpid()}-extrude_color-")
        assert not left.exists() and running.is_dir()


def test_a_package_is_extracted_once_and_kept_in_the_cache(own_cache, tmp_path, monkeypatch):
    import grammarc.io.rpk as rpk_module

    package = make_rpk(tmp_path / "p.rpk", {"rules/a.cga": "@StartRule\nLot --> X\n", "assets/a.obj": "v 0 0 0\n"})
    with open_rpk(package) as first:
        root = first.root
        assert root.is_relative_to(own_cache) and first.start_rule == "Lot"
    assert first.closed and (root / "assets" / "a.obj").is_file()  # kept, not removed

    def no_extraction(*args):
        raise AssertionError("extracted again")

    monkeypatch.setattr(rpk_module, "_extract", no_extraction)
    with open_rpk(package) as again:
        assert again.root == root and list(again.rules) == ["rules/a.cga"]


def test_a_kept_package_whose_files_changed_is_extracted_again(tmp_path):
    package = make_rpk(tmp_path / "p.rpk", {"rules/a.cga": "@StartRule\nLot --> X\n"})
    with open_rpk(package) as rpk:
        rule = rpk.main_rule_file
    rule.write_text("@StartRule\nLot --> Y\n")
    with open_rpk(package) as rpk:
        assert rpk.main_rule_file.read_text() == "@StartRule\nLot --> X\n"
    (rule.parent / "extra.cga").write_text("Z --> X\n")
    with open_rpk(package) as rpk:
        assert list(rpk.rules) == ["rules/a.cga"]


def test_without_a_cache_folder_a_package_is_extracted_for_the_block_only(tmp_path, monkeypatch):
    import tempfile

    (tmp_path / "not-a-folder").write_text("")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "not-a-folder"))
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    (tmp_path / "tmp").mkdir()
    package = make_rpk(tmp_path / "p.rpk", {"rules/a.cga": "@StartRule\nLot --> X\n"})
    with open_rpk(package) as rpk:
        assert rpk.root.parent == tmp_path / "tmp"
    assert list((tmp_path / "tmp").iterdir()) == []
