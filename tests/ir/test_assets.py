"""ir/passes/assets.py: the names ``I()`` and ``i()`` give become asset ids on the module."""

from __future__ import annotations

from dataclasses import replace

from grammarc.diagnostics import Diagnostics
from grammarc.frontend.parse import parse_source
from grammarc.ir.passes import assets as assets_pass
from grammarc.ir.pipeline import run_passes

FILE = "g.cga"
VERSION = 'version "2022.0"\n'


def resolved(text: str, roots, dialect=None):
    diags = Diagnostics()
    module = replace(parse_source(text, FILE, diags, dialect), roots=roots)
    return run_passes(module, diags, check=True), diags


def test_assets_are_numbered_after_the_leaf_cube_and_quad(tmp_path):
    (tmp_path / "win.obj").write_text("v 0 0 0\n")
    module, diags = resolved('a ~> I("win.obj") b\nb ~> I("quad") I("./win.obj") I("cylinder")', (tmp_path,))
    assert not diags
    assert module.assets == ("builtin:cube", "builtin:quad", "win.obj", "builtin:cylinder")
    assert module.asset_ids == (("win.obj", 2), ("quad", 1), ("./win.obj", 2), ("cylinder", 3))


def test_a_computed_asset_name_resolves_every_string_constant_that_names_a_file(tmp_path):
    (tmp_path / "a.obj").write_text("v 0 0 0\n")
    text = VERSION + 'const kind = "a.obj"\nLot --> i(kind) X\nX --> case p(0.5) : i("b.OBJ") else : i(kind + "")\n'
    module, diags = resolved(text, (tmp_path,), "cityengine")
    assert dict(module.asset_ids) == {"b.OBJ": 2, "a.obj": 3}
    assert [(d.code, d.span.line) for d in diags] == [("start-rule", 3), ("asset", 4)]  # b.OBJ is missing


def test_errors_and_warnings_at_the_name(tmp_path):
    module, diags = resolved('a ~> I("../up.obj") I("gone.obj")', (tmp_path / "g",))
    assert [(d.code, d.severity.value, d.span.col) for d in diags] == [
        ("asset", "error", 6), ("asset", "warning", 21)]
    assert dict(module.asset_ids) == {"gone.obj": 2}


def test_a_module_lowered_outside_the_compiler_keeps_its_names_unresolved():
    module, diags = resolved('a ~> I("/etc/passwd")', None)
    assert not diags and module.assets == () and module.asset_ids == ()


def test_a_nul_byte_in_an_asset_name_is_an_error_at_the_name(tmp_path):
    """It crashed `check` with `ValueError: embedded null byte`."""
    _, diags = resolved('a ~> I("w\0.obj")', (tmp_path,))
    assert [(d.code, d.severity.value, d.span.col, d.message) for d in diags] == [
        ("asset", "error", 6, "asset path `w\\0.obj` holds a NUL byte")]


def test_one_file_named_from_two_roots_is_one_asset(tmp_path):
    """A project's root lies inside its workspace: `assets/x.obj` and `/Proj/assets/x.obj` are one file."""
    project = tmp_path / "Proj"
    (project / "assets").mkdir(parents=True)
    (project / "assets" / "x.obj").write_text("v 0 0 0\n")
    module, diags = resolved('a ~> I("assets/x.obj") I("/Proj/assets/x.obj")', (project, tmp_path))
    assert not diags
    assert module.assets == ("builtin:cube", "builtin:quad", "assets/x.obj")
    assert dict(module.asset_ids) == {"assets/x.obj": 2, "/Proj/assets/x.obj": 2}


def files(root, *names):
    for name in names:
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text("v 0 0 0\n")


def test_a_computed_insert_may_insert_what_a_constant_search_finds_in_sorted_order(tmp_path):
    files(tmp_path, "assets/trees/oak.glb", "assets/trees/elm.obj", "assets/trees/notes.txt", "w.obj")
    text = VERSION + 'Lot --> i("w.obj") T\nT --> i(fileRandom("assets/trees/*"))\n'
    module, diags = resolved(text, (tmp_path,), "cityengine")
    assert module.assets == ("builtin:cube", "builtin:quad", "w.obj", "assets/trees/elm.obj", "assets/trees/oak.glb")
    assert dict(module.asset_ids) == {"w.obj": 2, "assets/trees/elm.obj": 3, "assets/trees/oak.glb": 4}
    assert [d.code for d in diags] == ["start-rule"]


def test_a_query_held_by_a_constant_is_searched_and_not_taken_for_a_missing_asset(tmp_path):
    files(tmp_path, "assets/a.obj", "assets/b.dae")
    text = VERSION + 'attr pool = "assets/*.dae"\nLot --> i(fileRandom(pool))\n'
    module, diags = resolved(text, (tmp_path,), "cityengine")
    assert dict(module.asset_ids) == {"assets/b.dae": 2}
    assert [d.code for d in diags] == ["start-rule"]


def test_a_computed_query_may_find_any_asset_file_under_its_constant_folder(tmp_path):
    files(tmp_path, "assets/oak/1.obj", "assets/elm/2.fbx", "assets/elm/3.png", "other/4.obj")
    text = VERSION + 'attr kind = "oak"\nLot --> i(fileRandom("assets/" + kind + "/*.obj"))\n'
    module, diags = resolved(text, (tmp_path,), "cityengine")
    assert dict(module.asset_ids) == {"assets/elm/2.fbx": 2, "assets/oak/1.obj": 3}
    assert [d.code for d in diags] == ["start-rule"]


def test_a_computed_query_under_too_many_asset_files_is_an_error(tmp_path, monkeypatch):
    monkeypatch.setattr(assets_pass, "MAX_COMPUTED_MATCHES", 1)
    files(tmp_path, "assets/a/1.obj", "assets/b/2.obj")
    text = VERSION + 'attr kind = "a"\nLot --> i(assetBestSize("assets/" + kind + "/*.obj", "xz"))\n'
    _, diags = resolved(text, (tmp_path,), "cityengine")
    assert [(d.code, d.severity.value, d.span.line) for d in diags if d.code == "asset"] == [("asset", "error", 3)]
    assert "under `assets/` may find any of its 2 asset files, more than 1" in str(diags)


def test_a_search_that_finds_nothing_is_a_warning_at_the_query(tmp_path):
    text = VERSION + 'Lot --> i(fileRandom("assets/*.obj"))\n'
    _, diags = resolved(text, (tmp_path,), "cityengine")
    assert [(d.code, d.span.col) for d in diags if d.code == "asset"] == [("asset", 22)]


def test_without_a_computed_insert_searches_make_no_asset(tmp_path):
    files(tmp_path, "assets/a.obj")
    text = VERSION + 'Lot --> report("a", fileRandom("assets/*.obj")) i("assets/a.obj")\n'
    module, _ = resolved(text, (tmp_path,), "cityengine")
    assert module.assets == ("builtin:cube", "builtin:quad", "assets/a.obj")


def test_an_fbx_without_its_reader_is_an_error_at_the_insert(tmp_path, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "assimp_py", None)  # as if it were not installed
    (tmp_path / "mill.fbx").write_text("; FBX\n")
    (tmp_path / "post.glb").write_bytes(b"")
    _, diags = resolved(VERSION + 'Lot --> i("post.glb") X\nX --> i("mill.fbx", zUp)\n', (tmp_path,), "cityengine")
    (error,) = [d for d in diags if d.code == "asset"]
    assert error.severity.value == "error" and error.span.line == 3
    assert error.message.startswith("unsupported asset format: FBX (`mill.fbx`; pip install 'grammarc[fbx]'")


def test_a_primitive_registers_the_builtin_of_its_segments_a_number_or_a_declared_attribute(tmp_path):
    text = (VERSION + "const n = 6\nattr m = 5.6\n@StartRule\nLot --> primitiveCylinder(n) A(3)\n"
            "A(k) --> primitiveSphere(m, 4) primitiveDisk(7) primitiveCylinder()\n")
    module, diags = resolved(text, (tmp_path,), "cityengine")
    assert not diags
    assert module.assets == ("builtin:cube", "builtin:quad", "builtin:cylinder6", "builtin:sphere6x4",
                             "builtin:cylinder16")
    module, diags = resolved(text.replace("primitiveDisk(7)", "primitiveDisk(k)"), (tmp_path,), "cityengine")
    why = "unsupported: primitiveDisk with a computed number of segments (give a number or an attribute declared"
    assert [(d.code, d.span.line, d.message) for d in diags] == [("unsupported", 6, why + " as one)")]
