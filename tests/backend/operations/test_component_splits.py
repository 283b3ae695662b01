"""backend/operations/component_splits.py in derivations: the paper's Comp and CityEngine's
comp(f) on boxes and prisms, selectors, ``comp.sel``, ``comp.index`` and ``comp.total``."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from derivations import (
    assets,
    make_lots_polys,
    names,
    paper,
    quad_centres,
    quad_normals,
    rect,
    rows,
    run,
    totals,
)

from grammarc.backend.chunk import Frames, TrimPlanes


def test_comp_front_side_top_on_a_box(write):
    r = run(write, "Lot --> extrude(10) Mass\nMass --> comp(f){ front : A | side : B | top : C }\n",
            [rect(12, 8)])
    assert set(assets(r)) == {"builtin:quad"}
    assert Counter(names(r)) == {"A": 1, "B": 3, "C": 1}  # the bottom matches nothing: dropped
    n, c = quad_normals(r), quad_centres(r)
    a, b, top = rows(r, "A"), rows(r, "B"), rows(r, "C")
    # front is the mass scope's +z: world +z, the face at z = 0
    np.testing.assert_allclose(n[a], [[0, 0, 1]], atol=1e-6)
    np.testing.assert_allclose(c[a], [[6, 5, 0]], atol=1e-6)
    np.testing.assert_allclose(sorted(map(tuple, np.round(n[b], 6))), [(-1, 0, 0), (0, 0, -1), (1, 0, 0)])
    np.testing.assert_allclose(n[top], [[0, 1, 0]], atol=1e-6)
    np.testing.assert_allclose(c[top], [[6, 10, -4]], atol=1e-6)
    # the quads span their faces: 12 x 10 front, 12 x 8 top
    x = r["xform"]
    assert np.linalg.norm(x[a][0, :, 0]) * np.linalg.norm(x[a][0, :, 1]) == pytest.approx(120)
    assert np.linalg.norm(x[top][0, :, 0]) * np.linalg.norm(x[top][0, :, 1]) == pytest.approx(96)


def test_comp_faces_go_to_the_first_selector_they_match(write):
    r = run(write, "Lot --> extrude(10) comp(f){ side : B | front : A }\n", [rect(12, 8)])
    assert Counter(names(r)) == {"B": 4}


@pytest.mark.parametrize("selectors, want", [
    ("all : X", {"X": 6}),
    ("vertical : V | horizontal : H", {"V": 4, "H": 2}),
    ("bottom : Bottom", {"Bottom": 1}),
    ("top : NIL | all : X", {"X": 5}),
    ("left : L | right : R | back : K", {"L": 1, "R": 1, "K": 1}),
])
def test_comp_selectors(write, selectors, want):
    r = run(write, f"Lot --> extrude(10) comp(f){{ {selectors} }}\n", [rect(12, 8)])
    assert Counter(names(r)) == want
    n = quad_normals(r)
    expected = {"Bottom": (0, -1, 0), "L": (-1, 0, 0), "R": (1, 0, 0), "K": (0, 0, -1)}
    for name, normal in expected.items():
        if name in want:
            np.testing.assert_allclose(n[rows(r, name)], [normal], atol=1e-6)
    if "H" in want:
        np.testing.assert_allclose(sorted(n[rows(r, "H")][:, 1]), [-1, 1], atol=1e-6)
        np.testing.assert_allclose(n[rows(r, "V")][:, 1], 0, atol=1e-6)


def test_comp_sel_names_the_selector_that_took_the_face(write):
    r = run(write, 'Lot --> extrude(4) comp(f){ left : Side | right : Side | side : Other }\n'
                   'Side -->\n    case comp.sel == "left" : L\n    else : R\n'
                   'Other --> report("sel", comp.sel)\n', [rect(12, 8)])
    assert Counter(names(r)) == {"L": 1, "R": 1, "Other": 2}
    np.testing.assert_allclose(quad_normals(r)[rows(r, "L")], [[-1, 0, 0]], atol=1e-6)
    assert totals(r)["sel_sum"] == "side" and totals(r)["sel_n"] == 2


def test_comp_index_and_total_are_per_selector(write):
    r = run(write, 'Lot --> extrude(4) comp(f){ front : F | side : S }\n'
                   'F --> report("f.index", comp.index) report("f.total", comp.total)\n'
                   'S --> report("s.index", comp.index) report("s.total", comp.total)\n', [rect(12, 8)])
    t = totals(r)
    assert (t["f.index_max"], t["f.total_max"]) == (0, 1)
    assert (t["s.index_min"], t["s.index_max"], t["s.index_sum"], t["s.total_max"]) == (0, 2, 3, 3)


def test_world_and_object_face_selectors(write):
    """world.* classifies by the world's axes, object.* by the lot's scope (x along the first edge)."""
    r = run(write, "Lot --> extrude(4) comp(f){ world.front : WF | object.front : OF | world.top : T }\n",
            [rect(12, 8)])
    normals = quad_normals(r)
    np.testing.assert_allclose(normals[rows(r, "WF")], [[0, 0, 1]], atol=1e-6)
    np.testing.assert_allclose(normals[rows(r, "T")], [[0, 1, 0]], atol=1e-6)
    assert Counter(names(r)) == {"WF": 1, "T": 1}  # map rectangles: the lot's front is the world's front


@pytest.mark.parametrize("name, normal", [
    ("world.south", [0, 0, 1]), ("world.north", [0, 0, -1]), ("world.east", [1, 0, 0]),
    ("world.west", [-1, 0, 0]), ("world.up", [0, 1, 0]), ("world.down", [0, -1, 0]),
])
def test_world_compass_face_selectors(write, name, normal):
    """The reference's world.south, north, east, west, up, down: the world's z south, x east, y up. The
    lot is turned so that its own front is not south."""
    r = run(write, f"Lot --> rotateScope(0, 90, 0) extrude(4) comp(f){{ {name} : A }}\n", [rect(12, 8)])
    assert names(r) == ["A"]
    np.testing.assert_allclose(quad_normals(r), [normal], atol=1e-6)


def test_index_selectors_take_the_component_of_that_number(write):
    """The reference's ``comp(f){ 3 : B }``: an extrusion's bottom is face 0, its sides follow the
    footprint's edges, its top is last; a face is taken by the first part that selects it, so ``side``
    after ``1`` takes the other three sides. Edges and vertices are numbered along the outline."""
    r = run(write, "Lot --> extrude(4) comp(f){ 0 : Bottom | 5 : Top | 1 : First | side : Side | 9 : None }\n",
            [rect(12, 8)])
    assert Counter(names(r)) == {"Bottom": 1, "Top": 1, "First": 1, "Side": 3}
    normals = quad_normals(r)
    np.testing.assert_allclose(normals[rows(r, "Bottom")], [[0, -1, 0]], atol=1e-6)
    np.testing.assert_allclose(normals[rows(r, "Top")], [[0, 1, 0]], atol=1e-6)
    np.testing.assert_allclose(normals[rows(r, "First")], [[0, 0, 1]], atol=1e-6)  # the edge along x at y = 0
    r = run(write, "Lot --> comp(e){ 2 : E }\nE --> report(\"len\", scope.sx)\n", [rect(12, 8)] * 2)
    assert totals(r)["len_n"] == 2 and totals(r)["len_sum"] == pytest.approx(24)  # the third edge, 12 long
    r = run(write, 'Lot --> comp(v){ 0 : V | 3 : W }\nV --> report("v", 1)\nW --> report("w", 1)\n',
            [rect(12, 8)])
    assert (totals(r)["v_n"], totals(r)["w_n"]) == (1, 1)


def test_vertical_edges_of_a_prism_look_along_the_corners_bisector(write):
    """The reference: an edge's z points along the mean of its faces' normals, so a prism's corner edge
    looks out along the corner's bisector. Candler's pipe edges on a roof 1.2 m square: cubes 2.9 deep
    along z, shifted 0.13 in, reach 1.62 / sqrt(2) beyond each side, as in PRT (along the side faces'
    normals they reached 1.32)."""
    text = ("Lot --> extrude(0.7) comp(e){ vertical : s('1, 0.6, 2.9) center(yz) t(0, 0, -0.13) "
            "primitiveCube() C. }\n")
    r = run(write, text, [rect(1.2, 1.2)])
    x = r["xform"].astype(float)
    assert len(x) == 4
    corners = np.array(list(np.ndindex(2, 2, 2)), float)
    world = np.einsum("nij,kj->nki", x[:, :, :3], corners) + x[:, None, :, 3]
    reach = 1.62 / np.sqrt(2)
    np.testing.assert_allclose(world.min(axis=(0, 1))[[0, 2]], [-reach, -1.2 - reach], atol=1e-6)
    np.testing.assert_allclose(world.max(axis=(0, 1))[[0, 2]], [1.2 + reach, reach], atol=1e-6)


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
    r = paper(write, 'lot ~> S(1r, 7, 1r) Comp("top"){ roof } Comp("bottom"){ floor }\n', make_lots_polys(lot))
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
    r = paper(write, 'lot ~> S(1r, 5, 1r) Comp("faces"){ f }\n', make_lots_polys("courtyard"))
    # 8 side faces (4 outer, 4 facing the hole) are quads; top and bottom are polygons with a hole
    assert len(r["asset"]) == 8 and len(r["mesh"].lot) == 2
    assert list(np.diff(r["mesh"].face_offsets)) == [2, 2]
    quad_area = np.linalg.norm(np.cross(r["xform"][:, :, 0], r["xform"][:, :, 1]), axis=1).sum()
    np.testing.assert_allclose(quad_area, (160 + 80) * 5, rtol=1e-6)



NOTCHED_COURTYARD = [np.array([[0, 0], [28, 0], [28, 12], [34, 12], [34, 0], [40, 0], [40, 20], [0, 20]], float),
                     np.array([[10, 3], [10, 12], [20, 12], [20, 3]], float)]
DEEP_COURTYARD = [np.array([[0, 0], [30, 0], [30, 20], [0, 20]], float),
                  np.array([[10, 8], [10, 16], [20, 16], [20, 8]], float)]


@pytest.mark.parametrize("lot, want", [
    # the cut's three parts: x down (from the top of the part's start) after an outer edge or the first
    # hole's, up (from the bottom of its end) before one: the first of the two in the solid's face order;
    # the hole's and the notch's walls that face the same way keep x along them
    (NOTCHED_COURTYARD, [(0, 10, -5.8, "down"), (20, 28, -5.8, "up"), (34, 40, -5.8, "down"),
                         (10, 20, -12, "along"), (28, 34, -12, "along")]),
    # the cut misses the hole: x along it
    (DEEP_COURTYARD, [(0, 30, -5.8, "along"), (10, 20, -16, "along")]),
])
def test_faces_a_split_cuts_through_a_courtyard_start_on_the_first_side_face(write, lot, want):
    """complexpatterns' top floor on courtyard lots (PRT through PyPRT, complexpatterns.rpk with the
    attributes of conformance case courtyard.42990 on these two lots): ``split(z)`` cuts the building through
    its courtyard, and the front of the part behind the cut, the cut's face in three parts, is laid out with
    its x up or down the wall (the tiles' frames say so), where grammarc laid every part's x along the cut.
    A cut that misses the courtyard keeps x along it."""
    r = run(write, "Lot --> extrude(5) split(z){ ~1 : Back | 5.8 : Front }\n"
                   "Back --> comp(f){ front : Face }\n", [lot])
    got = []
    for xform in r["xform"][rows(r, "Face")]:
        corners = xform[:, 3:4] + xform[:, :2] @ np.array([[0, 1, 0, 1], [0, 0, 1, 1]])
        np.testing.assert_allclose([corners[1].min(), corners[1].max()], [0, 5], atol=1e-6)
        np.testing.assert_allclose(quad_normals({"xform": xform[None]})[0], [0, 0, 1], atol=1e-6)
        x = np.round(xform[:, 0], 6)
        turn = "up" if x[1] > 0 else "down" if x[1] < 0 else "along" if x[0] > 0 else "back"
        got.append((round(corners[0].min(), 6), round(corners[0].max(), 6), round(corners[2, 0], 5), turn))
    assert sorted(got, key=lambda g: (-g[2], g[0])) == want

def test_a_solid_extruded_from_a_face_cut_through_its_hole_has_no_turned_faces(write):
    """massing on the kit's courtyard lot splits its (flat) inset through the courtyard and extrudes a piece:
    the cut of a face makes no faces of its own, and the solid's side faces have x along their edges (its
    facades' floors, split along y, are 118 faces so, 114 with the cut edges' faces turned; PRT's 122)."""
    r = run(write, "Lot --> split(z){ ~1 : Back | 5.8 : Front }\n"
                   "Back --> extrude(5) comp(f){ front : Face }\n", [NOTCHED_COURTYARD])
    x = r["xform"][rows(r, "Face")][:, :, 0]
    assert len(x) == 5 and (np.abs(x[:, 1]) < 1e-9).all() and (x[:, 0] > 0).all()


def test_index_selectors_given_by_expressions_take_the_component_they_evaluate_to(write):
    """``comp(f){ n + 1 : A | k : B }`` with a constant and an attribute (public files index the faces of
    their assets so), evaluated per shape: the lot's attribute picks another face on each lot."""
    r = run(write, "const n = 2\nattr k = 1\n"
                   "Lot --> extrude(4) comp(f){ n + 1 : A | k : B | 5 : C | k + 20 : None }\n",
            [rect(12, 8)] * 2, lot_attrs={"k": [1.0, 4.0]})
    assert Counter(names(r)) == {"A": 2, "B": 2, "C": 2}
    normals, lot = quad_normals(r), r["lot"]
    b = rows(r, "B")
    np.testing.assert_allclose(normals[b & (lot == 0)], [[0, 0, 1]], atol=1e-6)  # face 1: the first side
    np.testing.assert_allclose(normals[b & (lot == 1)], [[-1, 0, 0]], atol=1e-6)  # face 4: the last side
    np.testing.assert_allclose(normals[rows(r, "A")], [[0, 0, -1]] * 2, atol=1e-6)  # face 3: the back


ROOF_EDGES = "comp(e){ eave : Eave | ridge : Ridge | hip : Hip | valley : Valley | all : Other }\n" + "".join(
    f'{name} --> report("{name}", scope.sx)\n' for name in ("Eave", "Ridge", "Hip", "Valley", "Other"))


@pytest.mark.parametrize("roof, lot, want", [
    ("roofHip(30)", "rect", {"Eave": 4, "Hip": 4, "Ridge": 1}),
    ("roofPyramid(30)", "rect", {"Eave": 4, "Hip": 4}),
    # the gable's triangles: their bottom edges and rakes are none of the four
    ("roofGable(30)", "rect", {"Eave": 2, "Ridge": 1, "Other": 6}),
    ("roofShed(20)", "rect", {"Eave": 1, "Other": 8}),
    ("roofHip(30)", "concave_L", {"Eave": 6, "Hip": 5, "Valley": 1, "Ridge": 2}),
    ("roofGable(30)", "concave_L", {"Eave": 4, "Hip": 1, "Valley": 1, "Ridge": 2, "Other": 6}),
    ("extrude(3)", "rect", {"Other": 12}),  # a box has no roof edges
    # a roof on a mass's top face: the face's z is up, not the scope's y
    ("extrude(4) comp(f){ top : Top }\nTop --> roofGable(30)", "rect", {"Eave": 2, "Ridge": 1, "Other": 6}),
])
def test_roof_edges_are_eaves_ridges_hips_and_valleys(write, roof, lot, want):
    """``comp(e){ eave | ridge | hip | valley }`` on roofs: the eaves along the base, the ridges on top,
    hips where two slopes meet outward, valleys where they meet inward (an L's inner corner)."""
    polygons = [rect(12, 8)] if lot == "rect" else make_lots_polys(lot)
    r = run(write, f"Lot --> {roof} {ROOF_EDGES}", polygons)
    assert {k[:-2]: v for k, v in totals(r).items() if k.endswith("_n")} == want
    if roof == "roofHip(30)" and lot == "rect":
        t = totals(r)
        assert t["Eave_sum"] == pytest.approx(40) and t["Ridge_sum"] == pytest.approx(4)  # 12 - 2 * 4


def test_comp_sel_names_every_kind_of_selector_as_written(write):
    """``comp.sel`` of an index, an index expression, a world selector and a roof edge selector: the text of
    the selector that took the component (a selector outside the plain face names used to be unknown)."""
    r = run(write, "const n = 1\nLot --> extrude(4) comp(f){ n + 1 : A | 1 : B | world.up : C }\n"
                   'A --> report("a", comp.sel == "(@n + 1)")\nB --> report("b", comp.sel == "1")\n'
                   'C --> report("c", comp.sel == "world.up") roofHip(30) comp(e){ eave : E }\n'
                   'E --> report("e", comp.sel == "eave")\n', [rect(12, 8)])
    t = totals(r)
    assert (t["a_n"], t["b_n"], t["c_n"], t["e_n"]) == (1, 1, 1, 4)
    assert t["a_min"] and t["b_min"] and t["c_min"] and t["e_min"]


@pytest.mark.parametrize("body, want", [
    ("comp(f){ inside : I | border : B }", {"B": 1}),  # a flat shape: its one face has only border edges
    ("comp(e){ inside : I | border : B }", {"B": 4}),
    ("comp(v){ border : B }", {"B": 4}),
    ("extrude(3) comp(f){ border : B | inside : I }", {"I": 6}),  # a closed solid: all inside
    ("extrude(3) comp(e){ border : B | inside : I }", {"I": 12}),
    # a roof is closed by its bottom face: its 5 faces, 9 edges (4 eaves, 4 hips, a ridge), 6 vertices
    ("roofHip(30) comp(f){ border : B | inside : I }", {"I": 5}),
    ("roofHip(30) comp(e){ border : B | inside : I }", {"I": 9}),
    ("roofHip(30) comp(v){ border : B | inside : I }", {"I": 6}),
    # an envelope is closed too: its bottom, 4 walls and 4 slopes (the sides as the front)
    ("envelope(world.up, 20, 2, 45, 1, 30) comp(f){ border : B | inside : I }", {"I": 9}),
])
def test_border_and_inside_of_shapes_no_offset_made(write, body, want):
    """The reference's ``border`` (an edge meeting one face, a face or vertex touching such an edge) and
    ``inside`` on faces, solids and roofs."""
    r = run(write, f"Lot --> {body}\n" + "".join(f'{n} --> report("{n}", 1)\n' for n in "IB"), [rect(12, 8)])
    assert {k[:-2]: v for k, v in totals(r).items() if k.endswith("_n")} == want


def test_components_of_a_scope_beyond_any_geometry_fail_its_lot(write):
    """``s(1, 1, -1e290)``: its faces' axes cannot be normalized (squares overflow); the lot fails by name
    (where the scale makes the scope: ``Context.refuse_far``) instead of carrying frames of NaN, and the
    other lot builds."""
    r = run(write, 'attr d = 3\nLot --> s(1, 1, d) comp(f){ top : i("builtin:cube") | side : X }\n',
            [rect(12, 8), rect(12, 8)], lot_attrs={"d": [-1e290, np.nan]})
    (bad,) = r["bad"]
    assert bad.index == 0 and bad.reason.startswith("a scope sized or placed beyond any coordinate (1e+290)")
    assert np.isfinite(r["xform"]).all() and set(r["lot"].tolist()) == {1}


def test_the_same_face_of_boxes_in_one_frame_shares_a_frame_row(write, monkeypatch):
    """Twelve boxes split from one mass keep its frame: each of their six faces is one new frame row,
    shared by the twelve (``chunk.Frames.turned``), not a row per face."""
    added = []
    add = Frames.add

    def counted(self, axes):
        added.append(len(axes))
        return add(self, axes)

    monkeypatch.setattr(Frames, "add", counted)
    r = run(write, "Lot --> extrude(10) Mass\nMass --> split(x){ ~1 : Box }*\nBox --> comp(f){ all : F. }\n",
            [rect(12, 8)])
    assert Counter(names(r)) == {"F": 12 * 6}
    assert sum(added) == 1 + 6  # the lot's frame, then one per face
    assert len(np.unique(np.round(quad_normals(r), 6), axis=0)) == 6


def test_comp_f_gives_each_face_with_planes_a_row_that_its_pieces_share(write, monkeypatch):
    """A box's four side faces get a row of trim planes each in the chunk's table (``chunk.TrimPlanes``), its
    top, whose edges are not steep, none (row 0); the pieces split from a side face hold that face's id, and
    the cubes inserted on them are cut by its row."""
    added, gathered = [], []
    add, gather = TrimPlanes.add, TrimPlanes.__getitem__

    def counted(self, rows):
        added.append(rows.copy())
        return add(self, rows)

    def seen(self, ids):
        gathered.append(np.array(ids))
        return gather(self, ids)

    monkeypatch.setattr(TrimPlanes, "add", counted)
    monkeypatch.setattr(TrimPlanes, "__getitem__", seen)
    cube = "s('1, '1, 1) i(\"builtin:cube\")"
    r = run(write, f"Lot --> extrude(10) comp(f){{ side : split(y){{ ~5 : {cube} X }}* | top : {cube} T }}\n",
            [rect(12, 8)])
    assert Counter(names(r)) == {"X": 8, "T": 1}
    assert [rows.shape for rows in added] == [(4, 8)] and not np.isnan(added[0][:, [0, 4]]).any()
    assert sorted(np.concatenate(gathered).tolist()) == [0, 1, 1, 2, 2, 3, 3, 4, 4]
