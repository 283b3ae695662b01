"""backend/functions/files.py: file searches in a grammar's folders, a file picked per shape, paths taken apart.

Values from the CGA reference's pages (``fileSearch``, ``fileRandom``, the ``ce.lib`` file functions).
"""

from __future__ import annotations

import numpy as np
import pytest
from function_derivations import box_obj, derived, rectangles, reported, write_files

from grammarc.backend.functions.table import groups

TREES = {f"assets/trees/{name}": box_obj((1, 1, 1)) for name in ("oak.obj", "elm.obj", "fir.obj")}
PICKS = sorted(TREES)
LOTS = rectangles(*[(1, 1)] * 60)


def test_file_random_picks_a_match_per_shape_from_its_stream(tmp_path):
    write_files(tmp_path, {**TREES, "assets/trees/readme.txt": "", "assets/other.obj": box_obj((1, 1, 1))})
    picks = reported(derived(tmp_path, 'Lot --> report("f", fileRandom("assets/trees/*.obj"))', LOTS), "f")
    assert set(picks) == set(PICKS)  # every match, and only matches, over 60 shapes


def test_file_random_does_not_depend_on_chunks_and_follows_the_seed(tmp_path):
    write_files(tmp_path, TREES)
    text = 'Lot --> report("f", fileRandom("assets/trees/*.obj"))'
    whole = reported(derived(tmp_path, text, LOTS), "f")
    assert reported(derived(tmp_path, text, LOTS, chunk_size=7), "f") == whole
    assert reported(derived(tmp_path, text, LOTS, seed=1), "f") != whole


def test_each_call_draws_its_own_pick(tmp_path):
    write_files(tmp_path, TREES)
    r = derived(tmp_path, 'Lot --> report("a", fileRandom("assets/trees/*")) '
                          'report("b", fileRandom("assets/trees/*"))', LOTS)
    assert reported(r, "a") != reported(r, "b")


def test_file_random_of_no_match_is_empty(tmp_path):
    r = derived(tmp_path, 'Lot --> report("f", fileRandom("assets/*.obj"))', LOTS[:2])
    assert reported(r, "f") == ["", ""]


def test_an_insert_of_a_picked_file_inserts_it(tmp_path):
    write_files(tmp_path, TREES)
    text = 'Lot --> extrude(1) T(fileRandom("assets/trees/*.obj"))\nT(f) --> report("f", f) i(f)'
    r = derived(tmp_path, text, LOTS)
    inserted = [str(r["assets"][a]) for a in r["asset"][r["lot"].argsort(kind="stable")]]
    assert inserted == reported(r, "f") and set(inserted) == set(PICKS)
    r2 = derived(tmp_path, text, LOTS, chunk_size=5)
    assert [str(r2["assets"][a]) for a in r2["asset"][r2["lot"].argsort(kind="stable")]] == inserted


def test_an_insert_of_a_computed_search_inserts_from_its_folder(tmp_path):
    write_files(tmp_path, {**TREES, "assets/bushes/box.obj": box_obj((1, 1, 1))})
    r = derived(tmp_path, 'attr kind = "bushes"\nLot --> extrude(1) T\n'
                          'T --> i(fileRandom("assets/" + kind + "/*.obj"))', LOTS[:3])
    assert [str(r["assets"][a]) for a in r["asset"]] == ["assets/bushes/box.obj"] * 3


def test_file_search_is_the_sorted_string_list_of_the_matches(tmp_path):
    write_files(tmp_path, TREES)
    r = derived(tmp_path, 'Lot --> report("all", fileSearch("assets/trees/*")) report("none", fileSearch("*.png"))',
                LOTS[:1])
    assert reported(r, "all") == ["".join(f"{name};" for name in PICKS)]
    assert reported(r, "none") == [";"]  # as the reference's examples 2 and 5 show


def test_files_search_is_a_string_array(tmp_path):
    write_files(tmp_path, TREES)
    r = derived(tmp_path, 'Lot --> report("n", size(filesSearch("assets/trees/*"))) '
                          'report("first", filesSearch("assets/trees/*")[0]) report("none", size(filesSearch("*.x")))',
                LOTS[:2])
    assert reported(r, "n") == [3, 3] and reported(r, "first") == [PICKS[0]] * 2 and reported(r, "none") == [0, 0]


def test_searches_find_nothing_outside_the_grammars_folders(tmp_path):
    root = tmp_path / "project"
    write_files(tmp_path, {"secret.obj": box_obj((1, 1, 1)), "project/assets/a.obj": box_obj((1, 1, 1))})
    r = derived(root, 'Lot --> report("up", fileSearch("../*")) report("host", fileSearch("/etc/*")) '
                      'report("abs", fileRandom("/tmp/*"))', LOTS[:1])
    assert (reported(r, "up"), reported(r, "host"), reported(r, "abs")) == ([";"], [";"], [""])


@pytest.mark.parametrize("function, path, want", [
    ("fileName", "assets/obj/mygeometry.01.obj", "mygeometry.01.obj"),  # the reference's examples
    ("fileBasename", "assets/obj/mygeometry.01.obj", "mygeometry.01"),
    ("fileDirectory", "assets/obj/mygeometry.01.obj", "assets/obj/"),
    ("fileExtension", "assets/obj/mygeometry.01.obj", "obj"),
    ("fileName", "assets\\\\win.obj", "win.obj"),
    ("fileDirectory", "assets\\\\win.obj", "assets\\"),
    ("fileName", "plain", "plain"),
    ("fileBasename", "v1.2/plain", "plain"),
    ("fileExtension", "plain", ""),
    ("fileDirectory", "plain", ""),
])
def test_paths_taken_apart(tmp_path, function, path, want):
    r = derived(tmp_path, f'Lot --> report("v", {function}("{path}"))', LOTS[:1])
    assert reported(r, "v") == [want]


def test_file_exists_searches_as_an_insert_does(tmp_path):
    write_files(tmp_path, TREES)
    r = derived(tmp_path, 'Lot --> report("yes", fileExists("assets/trees/oak.obj")) '
                          'report("no", fileExists("assets/trees/ash.obj")) report("up", fileExists("../g.cga"))',
                LOTS[:1])
    assert (reported(r, "yes"), reported(r, "no"), reported(r, "up")) == ([True], [False], [False])


def test_an_insert_of_a_search_that_found_nothing_fails_its_lot(tmp_path):
    write_files(tmp_path, TREES)
    r = derived(tmp_path, 'attr kind = "trees"\nLot --> extrude(1) T\n'
                          'T --> i(fileRandom("assets/" + kind + "/*.glb"))', LOTS[:2])
    assert [b.index for b in r["bad"]] == [0, 1]
    assert "`i` of ``, a file search that found nothing" in r["bad"][0].reason


@pytest.mark.parametrize("high", [10, 2**40])  # small and large ids
def test_groups_number_each_shapes_tuple(high):
    rng = np.random.default_rng(0)
    a = rng.integers(0, 5, 200) * (high // 5)
    b = rng.integers(0, 3, 200)
    found = dict(groups(200, a, b))
    assert sorted(found) == sorted(set(zip(a.tolist(), b.tolist())))
    assert all((a[rows] == key[0]).all() and (b[rows] == key[1]).all() for key, rows in found.items())
    assert sum(len(rows) for rows in found.values()) == 200
    assert sorted(dict(groups(200, a, 7))) == [(v, 7) for v in sorted(set(a.tolist()))]
