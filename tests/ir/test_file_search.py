"""ir/file_search.py: CityEngine's file search queries answered in the asset roots, sorted, never outside them.

The workspace is the one of the CGA reference's ``fileSearch`` examples: a rule file in ``MyProject/rules``,
textures and a tower in ``MyProject/assets``, glass and brick in ``OtherProject/assets``. The reference
returns workspace paths; grammarc returns each file's path relative to the first root holding it.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from grammarc.errors import AssetError
from grammarc.frontend.imports import find_roots
from grammarc.ir import file_search
from grammarc.ir.asset_names import locate
from grammarc.ir.file_search import constant_folder, search

FILES = ("MyProject/assets/textures/1.png", "MyProject/assets/textures/2.png", "MyProject/assets/textures/4.png",
         "MyProject/assets/tower.png", "MyProject/assets/tower.obj", "MyProject/rules/rule.cga",
         "OtherProject/assets/glass.png", "OtherProject/assets/brick.obj")
TEXTURES = ("textures/1.png", "textures/2.png", "textures/4.png")


@pytest.fixture
def workspace(tmp_path) -> tuple[Path, tuple[Path, ...]]:
    """The reference's workspace and the roots of its rule file (rules, assets, project, workspace)."""
    for name in reversed(FILES):  # made in reverse: the results must not follow the file system's order
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text("v 0 0 0\n")
    roots = find_roots(tmp_path / "MyProject/rules/rule.cga").asset_roots()
    return tmp_path, roots


@pytest.mark.parametrize("query, want", [
    ("*.png", ("OtherProject/assets/glass.png", *TEXTURES, "tower.png")),  # example 1: every project
    ("?.png", ()),                                                          # 2: no one-letter name at a root
    ("*/?.png", TEXTURES),                                                  # 3
    ("textures/*", TEXTURES),                                               # 4
    ("$[12].png", ()),                                                      # 5
    ("$textures/[12].png", TEXTURES[:2]),                                   # 6
    ("$.*/[12].png", TEXTURES[:2]),                                         # 7
    ("$textures/[2-5].png", TEXTURES[1:]),                                  # 8
    ("$textures/[12].png|.*.obj", ("OtherProject/assets/brick.obj", *TEXTURES[:2], "tower.obj")),  # 9
    ("Name=1.png", TEXTURES[:1]),                                           # 10
    ("Project=OtherProject Ext=obj", ("OtherProject/assets/brick.obj",)),   # 11: whitespace is AND
])
def test_the_reference_examples(workspace, query, want):
    assert search(query, workspace[1]) == want


def test_names_resolve_back_to_the_files_found(workspace):
    folder, roots = workspace
    for name in search("*", roots):
        assert locate(name, roots)[1].relative_to(folder.resolve()).as_posix() in FILES


def test_a_workspace_path_is_searched_in_the_workspace_and_named_as_any_other(workspace):
    roots = workspace[1]
    assert search("/MyProject/assets/textures/*", roots) == TEXTURES
    assert search("/OtherProject/assets/*.obj", roots) == ("OtherProject/assets/brick.obj",)


def test_a_workspace_path_in_a_lone_project_drops_the_project(tmp_path):
    """A rule package flattens its workspace: `/Proj/assets/x.obj` is its `assets/x.obj`."""
    (tmp_path / "assets").mkdir()
    (tmp_path / "assets" / "x.obj").write_text("")
    assert search("/Proj/assets/*.obj", (tmp_path,)) == ("assets/x.obj",)


def test_double_star_stands_for_any_folders_or_none(tmp_path):
    for name in ("assets/a.obj", "assets/x/y/b.obj", "other/c.obj"):
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text("")
    assert search("assets/**/*.obj", (tmp_path,)) == ("assets/a.obj", "assets/x/y/b.obj")
    assert search("*.obj", (tmp_path,)) == ("assets/a.obj", "assets/x/y/b.obj", "other/c.obj")


def test_one_file_under_two_roots_is_found_once_by_its_first_name(workspace):
    roots = workspace[1]
    assert search("*tower.obj", roots) == ("tower.obj",)  # not assets/tower.obj, MyProject/assets/tower.obj


def test_nothing_outside_the_roots_is_listed(tmp_path):
    root = tmp_path / "root"
    (root / "assets").mkdir(parents=True)
    (root / "assets" / "in.obj").write_text("")
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "secret.obj").write_text("")
    os.symlink(outside / "secret.obj", root / "assets" / "link.obj")
    os.symlink(outside, root / "assets" / "linked")
    (root / ".hidden").mkdir()
    (root / ".hidden" / "h.obj").write_text("")
    roots = (root,)
    assert search("*", roots) == ("assets/in.obj",)
    for query in ("../*", "../outside/*", "/etc/*", "/etc/passwd", "$\\.\\./.*", "*secret*", "assets/linked/*"):
        assert search(query, roots) == (), query


def test_a_link_inside_its_root_is_a_file_of_it(tmp_path):
    (tmp_path / "a.obj").write_text("")
    os.symlink(tmp_path / "a.obj", tmp_path / "b.obj")
    assert search("*.obj", (tmp_path,)) == ("a.obj",)  # one file: its first name


def test_a_bad_regular_expression_is_an_asset_error(tmp_path):
    with pytest.raises(AssetError, match="regular expression"):
        search("$[", (tmp_path,))


def test_a_search_lists_at_most_max_listed_files(tmp_path, monkeypatch):
    for i in range(5):
        (tmp_path / f"{i}.obj").write_text("")
    monkeypatch.setattr(file_search, "MAX_LISTED", 3)
    with pytest.raises(AssetError, match="more than 3 files"):
        search("*.obj", (tmp_path,))


@pytest.mark.parametrize("prefix, folder", [
    ("assets/", "assets/"), ("assets/trees/", "assets/trees/"), ("assets/tr", "assets/"), ("assets/*/x", "assets/"),
    ("tree", ""), ("$assets/", ""), ("Name=x", ""), ("", ""),
])
def test_the_constant_folder_of_a_computed_query(prefix, folder):
    assert constant_folder(prefix) == folder
