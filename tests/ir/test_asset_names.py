"""ir/asset_names.py: built-in names, and file names resolved inside the asset roots, never outside."""

from __future__ import annotations

import pytest

from grammarc.ir.asset_names import (
    LEAF_CUBE,
    LEAF_QUAD,
    builtin_name,
    primitive_asset,
    resolve_asset,
    segment_counts,
)


@pytest.mark.parametrize("bare, builtin", [
    ("cube", True), ("quad", True), ("cylinder", True), ("L", True), ("T", True), ("cylinder3", True),
    ("cylinder256", True), ("cylinder2", False), ("cylinder257", False), ("cylinderx", False),
    ("sphere", False), ("cube.obj", False), ("cone8", True), ("cone", False), ("sphere8x4", True),
    ("sphere8", False), ("sphere8x2", False), ("sphere8x4x2", False),
])
def test_builtin_names(bare, builtin):
    assert builtin_name(bare) is builtin


@pytest.mark.parametrize("kind, values, asset", [
    ("cylinder", (8,), "builtin:cylinder8"), ("cone", (2.5,), "builtin:cone3"), ("cone", (300,), "builtin:cone256"),
    ("sphere", (7.5, 4.4), "builtin:sphere8x4"), ("disk", (6,), None), ("cube", (), None),
])  # fmt: skip
def test_a_primitive_names_the_builtin_of_its_rounded_segment_counts(kind, values, asset):
    assert primitive_asset(kind, segment_counts(values)) == asset


def test_the_leaf_assets_are_builtins():
    assert resolve_asset(LEAF_CUBE, []).name == LEAF_CUBE and resolve_asset("quad", []).name == LEAF_QUAD


def test_a_builtin_is_canonical_with_or_without_its_prefix():
    assert resolve_asset("cylinder12", []) == resolve_asset("builtin:cylinder12", [])
    assert resolve_asset("cylinder12", []).name == "builtin:cylinder12"
    assert "unknown built-in asset" in resolve_asset("builtin:sphere", []).problem


def test_cityengine_cube_without_texture_coordinates_is_the_cube():
    assert resolve_asset("builtin:cube:notex", []).name == "builtin:cube"
    assert resolve_asset("builtin:quad:notex", []).problem


def test_a_file_is_named_relative_to_the_first_root_that_holds_it(tmp_path):
    first, second = tmp_path / "grammar", tmp_path / "kit"
    (first / "sub").mkdir(parents=True)
    second.mkdir()
    (first / "sub" / "door.obj").write_text("v 0 0 0\n")
    (second / "win.obj").write_text("v 0 0 0\n")
    door = resolve_asset("./sub/door.obj", [first, second])
    assert (door.name, door.path, door.problem, door.missing) == ("sub/door.obj", first / "sub" / "door.obj",
                                                                   "", False)
    assert resolve_asset("win.obj", [first, second]).path == second / "win.obj"
    assert resolve_asset("sub\\door.obj", [first]).name == "sub/door.obj"


def test_a_file_no_root_holds_is_missing_and_keeps_its_name(tmp_path):
    missing = resolve_asset("facade/./win.obj", [tmp_path])
    assert (missing.name, missing.path, missing.problem, missing.missing) == ("facade/win.obj", None, "", True)


@pytest.mark.parametrize("name, problem", [
    ("C:/x.obj", "is absolute"), ("../x.obj", "leaves the asset folders"),
    ("a/../../x.obj", "leaves the asset folders"),
])
def test_a_name_outside_every_root_is_refused(tmp_path, name, problem):
    resolved = resolve_asset(name, [tmp_path / "g"])
    assert problem in resolved.problem and resolved.path is None


def test_a_nul_byte_in_a_name_is_refused_not_a_crash(tmp_path):
    resolved = resolve_asset("win\0.obj", [tmp_path])
    assert resolved.problem == "asset path `win\\0.obj` holds a NUL byte" and resolved.path is None


def test_workspace_paths_resolve_in_a_workspace_or_in_the_project_they_name(tmp_path):
    (tmp_path / "Proj" / "assets").mkdir(parents=True)
    (tmp_path / "Proj" / "assets" / "x.obj").write_text("v 0 0 0\n")
    in_workspace = resolve_asset("/Proj/assets/x.obj", [tmp_path / "Proj", tmp_path])
    assert (in_workspace.name, in_workspace.path) == ("Proj/assets/x.obj", tmp_path / "Proj" / "assets" / "x.obj")
    # a package (or a lone project) is the project its paths name, whatever its name was
    exported = resolve_asset("/Tutorial_09/assets/x.obj", [tmp_path / "Proj"])
    assert (exported.name, exported.problem) == ("assets/x.obj", "")
    # a workspace path no root holds is missing, as a relative name is; nothing outside the roots is read
    gone = resolve_asset("/Proj/assets/gone.obj", [tmp_path])
    assert (gone.name, gone.path, gone.problem, gone.missing) == ("/Proj/assets/gone.obj", None, "", True)
    host = resolve_asset("/etc/passwd", [tmp_path / "g"])
    assert (host.path, host.problem, host.missing) == (None, "", True)
