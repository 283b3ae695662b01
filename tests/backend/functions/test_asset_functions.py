"""backend/functions/assets.py: an asset's size and position, and assets chosen by how they fit the scope.

Values from the CGA reference's pages (``assetInfo``'s unit cube, ``assetNamingInfo``'s tree) and from
the ``ce.lib`` definitions of the choosers. A lot w x h has the scope w x 0 x h, so the choosers compare
by ``xz``.
"""

from __future__ import annotations

import pytest
import trimesh
from function_derivations import box_obj, derived, rectangles, reported, write_files

#: The reference's example asset: 0.2 x 0.3 x 0.4, its lowest corner at (0.5, 0.55, 0.6).
CUBE = box_obj((0.2, 0.3, 0.4), (0.5, 0.55, 0.6))
INFO = {"sx": 0.2, "sy": 0.3, "sz": 0.4, "tx": 0.5, "ty": 0.55, "tz": 0.6}
#: Assets 1, 2 and 4 wide and deep; and of x : z ratios 1, 2 and 4.
SIZES = {"assets/a.obj": box_obj((1, 1, 1)), "assets/b.obj": box_obj((2, 1, 2)), "assets/c.obj": box_obj((4, 1, 4))}
RATIOS = {"assets/r1.obj": box_obj((1, 1, 1)), "assets/r2.obj": box_obj((2, 1, 1)), "assets/r4.obj": box_obj((4, 1, 1))}


def exported(size, corner, file_type: str) -> bytes:
    """A box of ``size`` with its lowest corner at ``corner``, as trimesh writes it (``glb``, ``dae``)."""
    mesh = trimesh.creation.box(extents=size)
    mesh.apply_translation([c + s / 2 for c, s in zip(corner, size)])
    data = mesh.export(file_type=file_type)
    return data if isinstance(data, bytes) else data.encode()


@pytest.mark.parametrize("asset", ["assets/unitCube.obj", "assets/unitCube.glb", "assets/unitCube.dae"])
def test_asset_info_is_the_size_and_lowest_corner_in_the_assets_units(tmp_path, asset):
    """Every format gives the same answer (FBX and 3DS bounds: ``tests/model/test_assets.py``)."""
    write_files(tmp_path, {"assets/unitCube.obj": CUBE, **{
        f"assets/unitCube.{kind}": exported((0.2, 0.3, 0.4), (0.5, 0.55, 0.6), kind) for kind in ("glb", "dae")}})
    reports = " ".join(f'report("{k}", assetInfo("{asset}", {k})) report("q{k}", assetInfo("{asset}", "{k}"))'
                       for k in INFO)
    r = derived(tmp_path, f"Lot --> {reports}", rectangles((1, 1)))
    for key, want in INFO.items():
        assert reported(r, key) == [pytest.approx(want)] and reported(r, "q" + key) == [pytest.approx(want)]


def test_asset_info_of_a_missing_asset_is_zero(tmp_path):
    r = derived(tmp_path, 'Lot --> report("s", assetInfo("assets/none.obj", sx))', rectangles((1, 1)))
    assert reported(r, "s") == [0.0]


def test_assets_sort_size_orders_by_the_scaling_and_keeps_those_within_the_error(tmp_path):
    write_files(tmp_path, SIZES)
    r = derived(tmp_path, 'Lot --> report("all", assetsSortSize(fileSearch("assets/*"), xz, 0)) '
                          'report("near", assetsSortSize(fileSearch("assets/*"), xz, 0.6)) '
                          'report("none", assetsSortSize(fileSearch("assets/*"), xz, 0.01))',
                rectangles((2, 2), (3.5, 3.5)))
    assert reported(r, "all") == ["assets/b.obj;assets/c.obj;assets/a.obj;", "assets/c.obj;assets/b.obj;assets/a.obj;"]
    assert reported(r, "near") == ["assets/b.obj;assets/c.obj;", "assets/c.obj;"]
    assert reported(r, "none") == ["assets/b.obj;", ""]


def test_the_best_size_the_approximate_and_the_fitting_ones(tmp_path):
    write_files(tmp_path, SIZES)
    lots = rectangles(*[(2, 2)] * 40, (3.5, 3.5))
    r = derived(tmp_path, 'Lot --> report("best", assetBestSize("assets/*.obj", "xz")) '
                          'report("one", assetApproxSize("assets/*.obj", "xz", 1)) '
                          'report("two", assetApproxSize("assets/*.obj", "xz", 2)) '
                          'report("zero", assetApproxSize("assets/*.obj", "xz", 0)) '
                          'report("fit", assetFitSize("assets/*.obj", "xz", 0.6)) '
                          'report("any", assetFitSize("assets/*.obj", "xz", 0))', lots)
    assert reported(r, "best") == ["assets/b.obj"] * 40 + ["assets/c.obj"]
    assert reported(r, "one") == reported(r, "best")  # the reference: approx of 1 is the best
    assert set(reported(r, "two")[:40]) == {"assets/b.obj", "assets/c.obj"}
    assert set(reported(r, "zero")) == {""}
    assert set(reported(r, "fit")[:40]) == {"assets/b.obj", "assets/c.obj"} and reported(r, "fit")[40] == "assets/c.obj"
    assert set(reported(r, "any")) == set(SIZES)


def test_an_unknown_size_selector_compares_all_axes(tmp_path):
    """The ce.lib's `else` branch: anything but x, y, z, xy, xz, yz is xyz (the lot's y is 0: a's 1 is
    the least scaling down to it)."""
    write_files(tmp_path, {"assets/a.obj": box_obj((2, 1, 2)), "assets/b.obj": box_obj((2, 4, 2))})
    r = derived(tmp_path, 'Lot --> report("xz", assetBestSize("assets/*", "xz")) '
                          'report("xyz", assetBestSize("assets/*", "diagonal"))', rectangles((2, 2)))
    assert (reported(r, "xz"), reported(r, "xyz")) == (["assets/a.obj"], ["assets/a.obj"])


def test_the_best_ratio_and_the_approximate_ones(tmp_path):
    write_files(tmp_path, RATIOS)
    lots = rectangles(*[(4, 2)] * 40, (1, 1))
    r = derived(tmp_path, 'Lot --> report("best", assetBestRatio("assets/*.obj", "xz")) '
                          'report("two", assetApproxRatio("assets/*.obj", "xz", 2)) '
                          'report("sorted", assetsSortRatio(fileSearch("assets/*.obj"), xz))', lots)
    assert reported(r, "best") == ["assets/r2.obj"] * 40 + ["assets/r1.obj"]
    # a ratio of 2 is as far from 1 as from 4: the tie keeps the list's order, r1 before r4
    assert set(reported(r, "two")[:40]) == {"assets/r1.obj", "assets/r2.obj"}
    assert reported(r, "sorted")[40] == "assets/r1.obj;assets/r2.obj;assets/r4.obj;"


def test_choices_do_not_depend_on_chunks(tmp_path):
    write_files(tmp_path, SIZES)
    text = 'Lot --> report("f", assetFitSize("assets/*.obj", "xz", 0)) report("r", assetApproxRatio("assets/*", "xz", 3))'
    lots = rectangles(*[(2, 2)] * 30)
    whole = derived(tmp_path, text, lots)
    chunked = derived(tmp_path, text, lots, chunk_size=4)
    assert reported(whole, "f") == reported(chunked, "f") and reported(whole, "r") == reported(chunked, "r")


def test_an_inserted_choice_is_an_asset_of_the_grammar(tmp_path):
    write_files(tmp_path, SIZES)
    r = derived(tmp_path, 'Lot --> extrude(1) i(assetBestSize("assets/*.obj", "xz"))', rectangles((2, 2), (4, 4)))
    assert [str(r["assets"][a]) for a in r["asset"][r["lot"].argsort(kind="stable")]] == ["assets/b.obj", "assets/c.obj"]


def test_asset_naming_info_lists_groups_and_materials_in_order(tmp_path):
    head = "g trunk\nusemtl Foliage\ng crown\nusemtl Foliage__leafcard\ng trunk\nusemtl Bark\nusemtl Foliage\n"
    write_files(tmp_path, {"tree.obj": box_obj((1, 1, 1), head=head)})
    r = derived(tmp_path, 'Lot --> report("m", assetNamingInfo("tree.obj", m)) report("g", assetNamingInfo("tree.obj", g))'
                          ' report("n", size(assetNamingInfos("tree.obj", m))) '
                          'report("bark", assetNamingInfos("tree.obj", m)[2])', rectangles((1, 1)))
    assert reported(r, "m") == ["Foliage;Foliage__leafcard;Bark;"] and reported(r, "g") == ["trunk;crown;"]
    assert reported(r, "n") == [3] and reported(r, "bark") == ["Bark"]
