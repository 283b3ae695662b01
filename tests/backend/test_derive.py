"""Derivation semantics on the paper's own figures and examples (section 2 and 4 of the CGA paper).

Lots made by ``make_lots`` are map rectangles (0,0)-(w,h): their scope has x = world +x, y up, z = world +z
and origin (0, 0, -h), so a scope translation (tx, ty, tz) lands at world (tx, ty, tz - h).
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import LOT_ZOO, make_lots

from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar
from grammarc.errors import LimitError
from grammarc.io.lots import lots_from_polygons


def rect(w, h):
    return [np.array([[0, 0], [w, 0], [w, h], [0, h]], float)]


def run(write, text, polygons, **options):
    grammar = compile_grammar(write("g.cga", text))
    lots = lots_from_polygons(polygons, attrs=options.pop("lot_attrs", None))
    return derive(grammar, lots, BuildOptions(**options))


def of_symbol(records, name):
    """Rows of the records whose symbol is ``name``."""
    return records["symbol"] == list(records["symbols"]).index(name)


def test_subdiv_relative_sizes_on_widths_12_and_10(write):
    """Paper section 2: Subdiv("X",2,1r,1r,2) gives 2,4,4,2 on width 12 and 2,3,3,2 on width 10."""
    r = run(write, 'floor ~> S(1r, 3, 1r) Subdiv("X",2,1r,1r,2){ B | A | A | B }\n'
                   'A ~> I("cube")\nB ~> I("cube")\n', [rect(12, 5), rect(10, 5)])
    for lot, want in ((0, [2, 4, 4, 2]), (1, [2, 3, 3, 2])):
        rows = r["lot"] == lot
        order = np.argsort(r["xform"][rows, 0, 3])
        np.testing.assert_allclose(r["xform"][rows, 0, 0][order], want)
        np.testing.assert_allclose(r["xform"][rows, 0, 3][order], np.cumsum([0, *want[:-1]]))
    # B at both ends, A in the middle
    rows = r["lot"] == 0
    symbols = r["symbols"][r["symbol"][rows][np.argsort(r["xform"][rows, 0, 3])]]
    assert list(symbols) == ["B", "A", "A", "B"]


def test_subdiv_facade_of_12_8(write):
    """Paper section 2: Subdiv("Y",3.5,0.3,3,3,3) on a facade 12.8 high: four floors and a ledge."""
    r = run(write, 'lot ~> S(1r, 12.8, 1r) Comp("sideface", 0){ fac }\n'
                   'fac ~> Subdiv("Y",3.5,0.3,3,3,3){ floor | ledge | floor | floor | floor }\n',
            [rect(10, 10)])
    heights = r["xform"][:, 1, 1]
    bottoms = r["xform"][:, 1, 3]
    order = np.argsort(bottoms)
    np.testing.assert_allclose(heights[order], [3.5, 0.3, 3, 3, 3])
    np.testing.assert_allclose(bottoms[order], [0, 3.5, 3.8, 6.8, 9.8])
    assert list(r["symbols"][r["symbol"][order]]) == ["floor", "ledge", "floor", "floor", "floor"]
    # leaves of a flat scope are quads
    assert set(r["assets"][r["asset"]]) == {"builtin:quad"}


@pytest.mark.parametrize("width, count", [(12, 6), (11, 6), (10.5, 6), (2, 1), (0.5, 1)])
def test_repeat_counts_ceil(write, width, count):
    """Paper section 2: Repeat("X",2) makes ceil(Scope.sx/2) elements of equal, adjusted size."""
    r = run(write, 'floor ~> S(1r, 3, 1r) Repeat("X", 2){ B }\nB ~> I("cube")\n', [rect(width, 4)])
    assert len(r["asset"]) == count
    np.testing.assert_allclose(r["xform"][:, 0, 0], width / count)
    np.testing.assert_allclose(np.sort(r["xform"][:, 0, 3]), np.arange(count) * width / count, atol=1e-5)


def test_repeat_xy_grid_and_alternating_parts(write):
    r = run(write, 'f ~> S(1r, 4, 1r) Comp("sideface", 0){ g }\ng ~> Repeat("XY", 2, 1){ A | B }\n',
            [rect(6, 6)])
    assert len(r["asset"]) == 3 * 4
    assert of_symbol(r, "A").sum() == 6 and of_symbol(r, "B").sum() == 6


def test_mass_model_of_figure_3(write):
    """Paper section 2: A ~> [T(0,0,6) S(8,10,18) I(cube)] T(6,0,0) S(7,13,18) I(cube) T(0,0,16) ..."""
    r = run(write, 'A ~> [ T(0,0,6) S(8,10,18) I("cube") ] T(6,0,0) S(7,13,18) I("cube") '
                   'T(0,0,16) S(8,15,8) I("cylinder")\n', [rect(30, 20)])
    assert list(r["assets"][r["asset"]]) == ["builtin:cube", "builtin:cube", "builtin:cylinder"]
    x = r["xform"]
    np.testing.assert_allclose(np.diagonal(x[:, :, :3], axis1=1, axis2=2), [[8, 10, 18], [7, 13, 18],
                                                                            [8, 15, 8]])
    np.testing.assert_allclose(x[:, :, 3], [[0, 0, 6 - 20], [6, 0, 0 - 20], [6, 0, 16 - 20]])


SECTION_4 = """
attr building_height = 14
attr window_spacing = 3
attr window_width = 1.2
attr window_height = 1.6
attr window_depth = 0.25
attr door_width = 1.5
attr door_height = 2.4
attr door_depth = 0.3
PRIORITY 1:
1: footprint ~> S(1r,building_height,1r) facades
PRIORITY 2:
2: facades ~> Comp("sidefaces"){ facade }
3: facade : Scope.sx > 12
     ~> Subdiv("X",1r,door_width*1.5){ tiles | entrance } : 0.5
     ~> Subdiv("X",door_width*1.5,1r){ entrance | tiles } : 0.5
4: facade ~> tiles
5: tiles ~> Repeat("X",window_spacing){ tile }
6: tile ~> Subdiv("X",1r,window_width,1r){ wall |
      Subdiv("Y",2r,window_height,1r){ wall | window | wall } | wall }
8: window ~> S(1r,1r,window_depth) I("win.obj")
9: entrance ~> Subdiv("X",1r,door_width,1r){ wall |
      Subdiv("Y",door_height,1r){ door | wall } | wall }
10: door ~> S(1r,1r,door_depth) I("door.obj")
11: wall ~> I("wall.obj")
"""


def test_section_4_building_on_concave_footprint_with_hole(write):
    """Paper section 4 rules 1-11 (occlusion and visibility guards replaced) on an L with a courtyard."""
    l_with_hole = [
        np.array([[0, 0], [30, 0], [30, 12], [14, 12], [14, 24], [0, 24]], float),
        np.array([[3, 3], [3, 9], [9, 9], [9, 3]], float),
    ]
    r = run(write, SECTION_4, [l_with_hole, rect(20, 10)])
    assets = r["assets"][r["asset"]]
    assert {"win.obj", "door.obj", "wall.obj"} <= set(assets)
    # one facade per edge, hole edges included: 6 + 4 on the L, 4 on the rectangle
    lot0 = r["lot"] == 0
    facade_normals = set()
    for rows in (lot0 & (assets == "win.obj"),):
        n = np.cross(r["xform"][rows, :, 0], r["xform"][rows, :, 1])
        facade_normals |= {tuple(np.round(v / np.linalg.norm(v), 3)) for v in n}
    assert len(facade_normals) == 4  # windows face +x, -x, +z, -z (hole walls face inwards)
    # every instance stays within the footprint's box and the building height
    lo = r["xform"][:, :, 3].min(axis=0)
    assert lo[1] >= -1e-4 and r["xform"][:, 1, 3].max() <= 14 + 1e-4
    # doors only on facades longer than 12 m, one per such facade
    # the L's outer edges are 30, 12, 16, 12, 14 and 24 long, the hole's 6: four are longer than 12
    assert (lot0 & (assets == "door.obj")).sum() == 4
    # windows: Repeat ceil(width/3) tiles per facade minus the entrance parts, each one window
    assert (assets == "win.obj").sum() > 20
    assert not r["bad"]


def test_parametric_recursion_with_guards_and_lot_attributes(write):
    text = """
attr height = 10
attr floor_h = 3
lot ~> S(1r, height, 1r) stack(height)
stack(h) : h >= 2 * floor_h ~> Subdiv("Y", floor_h, 1r){ floor | stack(h - floor_h) }
stack(h) ~> floor
floor ~> I("cube")
"""
    heights = [10.0, 30.0, 7.0, float("nan")]
    r = run(write, text, [rect(10, 10)] * 4, lot_attrs={"height": heights})
    per_lot = np.bincount(r["lot"], minlength=4)
    # lot 3 has no height: the default 10 applies
    np.testing.assert_array_equal(per_lot, [3, 10, 2, 3])
    top = r["xform"][:, 1, 3] + r["xform"][:, 1, 1]
    np.testing.assert_allclose([top[r["lot"] == i].max() for i in range(4)], [10, 30, 7, 10])


def test_attr_override_beats_lot_and_default(write):
    text = 'attr height = 10\nlot ~> S(1r, height, 1r) I("cube")\n'
    r = run(write, text, [rect(5, 5)] * 2, lot_attrs={"height": [4.0, float("nan")]},
            attrs={"height": 7.0})
    np.testing.assert_allclose(r["xform"][:, 1, 1], [7, 7])
    r = run(write, text, [rect(5, 5)] * 2, lot_attrs={"height": [4.0, float("nan")]})
    np.testing.assert_allclose(r["xform"][:, 1, 1], [4, 10])


def test_string_attributes_select_rules(write):
    """Puuc rules 20-21: the frieze rule chosen by a string control parameter read per lot."""
    text = """
attr frieze_decoration = "none"
lot : frieze_decoration == "none" ~> plain
lot : frieze_decoration == "colonettes" ~> S(1r, 1, 1r) Repeat("X", 1){ colonette }
lot ~> other
colonette ~> I("cylinder")
"""
    r = run(write, text, [rect(4, 4)] * 3, lot_attrs={"frieze_decoration": ["colonettes", None, "x"]})
    assert list(r["symbols"][r["symbol"][r["lot"] == 0]]) == ["colonette"] * 4
    assert list(r["symbols"][r["symbol"][r["lot"] == 1]]) == ["plain"]
    assert list(r["symbols"][r["symbol"][r["lot"] == 2]]) == ["other"]


STOCHASTIC = """
lot ~> a : 0.5
    ~> b : 0.3
    ~> c(rand(2, 4)) : 0.2
c(x) ~> S(x, 1, 1) I("cube")
"""


def test_stochastic_frequencies_over_10k_lots(write):
    r = run(write, STOCHASTIC, [rect(1, 1)] * 10_000)
    counts = {s: int(of_symbol(r, s).sum()) for s in ("a", "b", "c")}
    # binomial standard deviations: 50, 46, 40; allow 4 of them
    assert abs(counts["a"] - 5000) < 200 and abs(counts["b"] - 3000) < 184 and abs(counts["c"] - 2000) < 160
    widths = r["xform"][of_symbol(r, "c"), 0, 0]
    assert 2 <= widths.min() and widths.max() <= 4 and abs(widths.mean() - 3) < 0.05


def _same(a, b):
    for key in ("asset", "xform", "lot", "symbol"):
        np.testing.assert_array_equal(a[key], b[key])
    for key in ("vertices", "ring_offsets", "face_offsets", "lot", "symbol"):
        np.testing.assert_array_equal(getattr(a["mesh"], key), getattr(b["mesh"], key))


def test_same_seed_same_records_and_chunking_does_not_matter(write):
    """The door side of rule 3 is random: records depend on the seed, never on the chunking."""
    polygons = [LOT_ZOO[n] for n in ("square", "concave_L", "courtyard", "rect_12x8")] * 5
    base = run(write, SECTION_4, polygons, seed=7)
    _same(base, run(write, SECTION_4, polygons, seed=7))
    _same(base, run(write, SECTION_4, polygons, seed=7, chunk_size=1))
    _same(base, run(write, SECTION_4, polygons, seed=7, chunk_size=3))
    _same(base, run(write, SECTION_4, polygons, seed=7, chunk_size=2, workers=2))
    other = run(write, SECTION_4, polygons, seed=8)
    assert not np.array_equal(base["xform"], other["xform"])


def test_chunk_split_on_budget_keeps_records(write):
    polygons = [rect(12, 8)] * 6
    base = run(write, SECTION_4, polygons)
    _same(base, run(write, SECTION_4, polygons, chunk_budget=50))


def test_negative_size_lot_is_reported_and_skipped(write):
    r = run(write, 'lot ~> S(Scope.sx - 11, 1, 1r) I("cube")\n', [rect(12, 5), rect(10, 5), rect(20, 5)])
    assert list(np.unique(r["lot"])) == [0, 2]
    on_threads = run(write, 'lot ~> S(Scope.sx - 11, 1, 1r) I("cube")\n', [rect(12, 5), rect(10, 5), rect(20, 5)],
                     chunk_size=1, workers=2)
    _same(r, on_threads)
    assert on_threads["bad"] == r["bad"]
    assert len(r["bad"]) == 1 and r["bad"][0].index == 1
    assert "negative or NaN size" in r["bad"][0].reason and "g.cga:1" in r["bad"][0].reason


def test_nan_split_size_lot_is_reported(write):
    r = run(write, 'lot ~> S(1r, 2, 1r) Subdiv("X", 1, sqrt(Scope.sx - 11)){ a | b }\n',
            [rect(12, 5), rect(10, 5)])
    assert list(np.unique(r["lot"])) == [0]
    assert r["bad"][0].index == 1 and "Subdiv" in r["bad"][0].reason


def test_runaway_branching_recursion_stops_with_the_rule(write):
    with pytest.raises(LimitError, match=r"`grow`.*--max-shapes"):
        run(write, "grow ~> T(0,1,0) grow grow\n", [rect(5, 5)])


def test_runaway_linear_recursion_stops_at_depth(write):
    with pytest.raises(LimitError, match=r"--max-depth 256 at rule `grow`"):
        run(write, "grow ~> T(0,1,0) grow\n", [rect(5, 5)])


def test_push_pop_and_rotation(write):
    r = run(write, 'A ~> [ Rz(90) S(2, 1, 1) I("cube") ] R(0, 90, 0) S(3, 1, 1) I("cube")\n', [rect(5, 5)])
    x = r["xform"]
    # Rz(90): scope x turns to world +y, y to world -x
    np.testing.assert_allclose(x[0, :, 0], [0, 2, 0], atol=1e-12)
    np.testing.assert_allclose(x[0, :, 1], [-1, 0, 0], atol=1e-12)
    # Ry(90): x turns towards -z
    np.testing.assert_allclose(x[1, :, 0], [0, 0, -3], atol=1e-6)
    np.testing.assert_allclose(x[0, :, 3], x[1, :, 3])


def test_leaf_face_is_a_quad_facing_outwards(write):
    r = run(write, 'lot ~> S(1r, 3, 1r) Comp("sidefaces"){ wall }\n', make_lots_polys("square"))
    assert set(r["assets"][r["asset"]]) == {"builtin:quad"}
    normals = np.cross(r["xform"][:, :, 0], r["xform"][:, :, 1])
    centres = r["xform"][:, :, 3] + (r["xform"][:, :, 0] + r["xform"][:, :, 1]) / 2
    middle = np.array([5, 1.5, -5])
    assert (np.einsum("ij,ij->i", normals, centres - middle) > 0).all()


def test_polygon_leaves_go_to_the_mesh_table(write):
    r = run(write, 'lot ~> S(1r, 3, 1r) mass\n', make_lots_polys("concave_L", "square"))
    mesh = r["mesh"]
    # the L prism: bottom, top and 6 sides; the square is a box: one cube instance
    assert list(mesh.lot) == [0] * 8 and list(r["lot"]) == [1]
    assert len(r["asset"]) == 1 and r["assets"][r["asset"][0]] == "builtin:cube"


def make_lots_polys(*names):
    return [LOT_ZOO[n] for n in names]


def test_bad_lots_from_input_are_listed(write):
    r = run(write, 'lot ~> S(1r, 3, 1r) I("cube")\n',
            [rect(5, 5), [np.array([[0, 0], [2, 2], [2, 0], [0, 2]], float)], rect(4, 4)])
    assert list(np.unique(r["lot"])) == [0, 2]
    assert [b.index for b in r["bad"]] == [1]


def test_zoo_lots_all_derive(write):
    lots = make_lots("square", "rect_12x8", "concave_L", "courtyard", "sliver")
    grammar = compile_grammar(write("g.cga", SECTION_4))
    r = derive(grammar, lots)
    assert set(np.unique(r["lot"])) == {0, 1, 2, 3, 4}


def test_lot_attribute_of_the_wrong_type_makes_its_lot_bad(write):
    text = 'attr height = 10\nlot ~> S(1r, height, 1r) I("cube")\n'
    r = run(write, text, [rect(5, 5)] * 3, lot_attrs={"height": ["12", "tall", None]})
    np.testing.assert_allclose(r["xform"][:, 1, 1], [12, 10])
    assert [b.index for b in r["bad"]] == [1]
    assert 'attribute `height` is "tall", not a num' in r["bad"][0].reason


def _face_area_normal(mesh, face):
    """Signed area vector (Newell) of a mesh face: its outline minus its holes."""
    total = np.zeros(3)
    for ring in range(mesh.face_offsets[face], mesh.face_offsets[face + 1]):
        p = mesh.vertices[mesh.ring_offsets[ring]:mesh.ring_offsets[ring + 1]].astype(np.float64)
        total += np.cross(p, np.roll(p, -1, axis=0)).sum(axis=0) / 2
    return total


@pytest.mark.parametrize("lot, area", [("concave_L", 400.0), ("courtyard", 1200.0)])
def test_polygon_top_and_bottom_faces(write, lot, area):
    """Comp("top"/"bottom") of a prism on a concave or holed lot: polygon faces at the right height,
    with the footprint's area, facing up and down."""
    r = run(write, 'lot ~> S(1r, 7, 1r) Comp("top"){ roof } Comp("bottom"){ floor }\n', make_lots_polys(lot))
    mesh = r["mesh"]
    names = r["symbols"][mesh.symbol]
    assert sorted(names) == ["floor", "roof"] and len(r["asset"]) == 0
    for face, name in enumerate(names):
        vector = _face_area_normal(mesh, face)
        np.testing.assert_allclose(np.linalg.norm(vector), area, rtol=1e-6)
        y = mesh.vertices[mesh.ring_offsets[mesh.face_offsets[face]]:
                          mesh.ring_offsets[mesh.face_offsets[face + 1]], 1]
        np.testing.assert_allclose(y, 7.0 if name == "roof" else 0.0, atol=1e-5)
        assert np.sign(vector[1]) == (1 if name == "roof" else -1)


def test_comp_faces_of_a_courtyard_prism(write):
    r = run(write, 'lot ~> S(1r, 5, 1r) Comp("faces"){ f }\n', make_lots_polys("courtyard"))
    # 8 side faces (4 outer, 4 facing the hole) are quads; top and bottom are polygons with a hole
    assert len(r["asset"]) == 8 and len(r["mesh"].lot) == 2
    assert list(np.diff(r["mesh"].face_offsets)) == [2, 2]
    quad_area = np.linalg.norm(np.cross(r["xform"][:, :, 0], r["xform"][:, :, 1]), axis=1).sum()
    np.testing.assert_allclose(quad_area, (160 + 80) * 5, rtol=1e-6)
