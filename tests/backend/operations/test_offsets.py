"""backend/operations/offsets.py in derivations: offset (of faces, of an offset's pieces, of roofs), footprint,
rectify."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from conftest import LOT_ZOO
from derivations import (
    face_area,
    mesh_faces,
    names,
    per_lot,
    rect,
    run,
    totals,
)


def test_offset_inside_and_border_faces(write):
    """offset(-2) comp(f){ border | inside } on the L: a ring with an L-shaped hole and the inset L."""
    r = run(write, "Lot --> offset(-2) comp(f){ border : B. | inside : I. }\n", [LOT_ZOO["concave_L"]])
    mesh = r["mesh"]
    names = list(r["symbols"][mesh.symbol])
    assert sorted(zip(names, np.diff(mesh.face_offsets))) == [("B", 2), ("I", 1)]

    def area(face):

        rings = [mesh.vertices[mesh.ring_offsets[k]:mesh.ring_offsets[k + 1]][:, [0, 2]]
                 for k in range(mesh.face_offsets[face], mesh.face_offsets[face + 1])]
        return shapely.Polygon(rings[0], rings[1:]).area

    inside, border = area(names.index("I")), area(names.index("B"))
    # the L of 400 m2 (arms 10 wide) shrunk by 2: arms 6 wide, 26 and 16 long
    assert inside == pytest.approx(26 * 6 + 10 * 6, rel=1e-6)
    assert inside + border == pytest.approx(400, rel=1e-6)


def test_offset_inside_face_runs_along_its_first_edge(write):
    """comp(f)'s faces of an offset get x along their first edge: a lot whose edge 0 (a 0.42 m chamfer,
    at 45 degrees) the offset makes vanish has its inset start at the next edge, and its scope turns
    with it (PRT turned massing's footprint split so on such a lot)."""
    chamfered = [np.array([[0, 0.3], [0.3, 0], [20, 0], [20, 10], [0, 10]], float)]
    text = 'Lot --> offset(-1) comp(f){ inside : I }\nI --> report("x", scope.sx) report("z", scope.sz)\n'
    t = totals(run(write, text, [chamfered]))
    assert (t["x_sum"], t["z_sum"]) == (pytest.approx(18), pytest.approx(8))


def test_offset_inset_without_the_last_edge_starts_where_edge_0_ends(write):
    """An L whose arm, and with it the last edge (the arm's end) and vertex 0, the offset makes vanish:
    PRT starts the inset where edge 0's moved line ends (vertex 1's mitre), so its first edge is the
    moved edge 1 and comp(f) turns the scope along it, though the inset is a rectangle (massing's
    footprints on the harness's L.7030 and H.3034 split along that edge)."""
    arm = [np.array([[-30, 0], [0, 0], [0, 12], [-7, 12], [-7, 4], [-30, 4]], float)]
    text = 'Lot --> offset(-2.5) comp(f){ inside : I }\nI --> report("x", scope.sx) report("z", scope.sz)\n'
    t = totals(run(write, text, [arm]))
    assert (t["x_sum"], t["z_sum"]) == (pytest.approx(7), pytest.approx(2))


def test_offset_inset_beside_a_thin_hole_starts_at_vertex_0s_mitre(write):
    """A thin hole near edge 3 whose far side lies nearer the inset's left side than edge 3 does: that
    side is still edge 3 moved in (the hole's side lies beyond it, on the hole's side), so the inset
    starts at vertex 0's mitre and split(x) cuts a strip along edge 3's side, in two by the grown hole's
    notch, as PRT's massing splits its footprint on such lots (holes.11067; was: the inset started at
    vertex 1's mitre and the strip ran along edge 0)."""
    lot = [np.array([[0, 0], [30, 0], [30, 30], [0, 30]], float),
           np.array([[4, 10], [4, 20], [5.5, 20], [5.5, 10]], float)]
    text = ('Lot --> offset(-3) comp(f){ inside : I }\nI --> split(x){ 1 : A | ~1 : B }\n'
            'A --> report("a", geometry.area)\n')
    assert totals(run(write, text, [lot]))["a_sum"] == pytest.approx(8)


def test_offset_inset_that_a_hole_cuts_in_two_starts_each_piece_at_its_first_edges_end(write):
    """A hole across the lot parts the inset in two: the piece with vertex 0's mitre starts there, the
    other where its first outer edge left ends (vertex 2's mitre, so its scope x runs along the slanted
    edge 2), though a run along the last edge ends in it too, at the hole: PRT on massing's courtyards
    and holes.11067 (was: that end, with x along the hole's side)."""
    lot = [np.array([[0, 0], [30, 0], [30, 30], [0, 40]], float),
           np.array([[2, 12], [2, 18], [28, 18], [28, 12]], float)]
    text = 'Lot --> offset(-3) comp(f){ inside : I }\nI --> report("x", scope.sx)\n'
    # the bottom piece 24 m along edge 0, the top one 27.46 m along edge 2 (were 24 m along the hole)
    assert totals(run(write, text, [lot]))["x_sum"] == pytest.approx(24 + 27.4605, abs=1e-4)


def test_offset_inside_of_a_rectangle_stays_a_box_path_rectangle(write):
    r = run(write, "Lot --> offset(-1, inside) extrude(2) X.\n", [rect(12, 8)])
    np.testing.assert_allclose(np.diagonal(np.abs(r["xform"][0, :, :3])), [10, 2, 6])
    np.testing.assert_allclose(r["xform"][0, :, 3], [1, 0, -7])


def test_offset_on_its_own_keeps_the_inside_and_the_border_as_the_faces_of_one_shape(write):
    """The reference's ``offset(d)`` without a selector is ``all``: the inset and the ring around it, one
    shape whose faces ``comp(f)`` splits; extruded, its faces make one solid without inner walls."""
    text = 'Lot --> offset(-2) report("a", geometry.area) report("n", geometry.nFaces) comp(f){ all : F }\n' \
        'F --> report("f", geometry.area)\n'
    t = totals(run(write, text, [LOT_ZOO["concave_L"]]))
    assert (t["a_sum"], t["n_sum"], t["f_n"]) == (pytest.approx(400), 2, 2)
    r = run(write, "Lot --> offset(-1) extrude(3) comp(f){ side : S }\nS --> report(\"s\", geometry.area)\n",
            [rect(12, 8)])
    assert not r["bad"] and totals(r)["s_sum"] == pytest.approx(3 * 40)


#: Two 10 x 10 squares joined by a bridge 2 wide: an inset of 1.5 leaves two disjoint squares of 7 x 7.
DUMBBELL = [np.array([[0, 0], [10, 0], [10, 4], [14, 4], [14, 0], [24, 0], [24, 10], [14, 10], [14, 6],
                      [10, 6], [10, 10], [0, 10]], float)]


def test_offset_of_an_offsets_pieces_offsets_each_piece(write):
    """CityEngine offsets every face of a shape's geometry: the second inset of the two squares left by
    the first is two squares of 5 x 5 in one shape (candler's pipes on a courtyard's roof)."""
    r = run(write, "Lot --> offset(-1.5, inside) offset(-1, inside) X.\n", [DUMBBELL])
    got = mesh_faces(r)
    assert names(r) == [] and len(got) == 2
    assert [face_area(f) for f in got] == [pytest.approx(25), pytest.approx(25)]
    xs = sorted(round(float(f[0][:, 0].min()), 6) for f in got)
    assert xs == [2.5, 16.5]


def test_offset_border_of_several_pieces_rings_each(write):
    r = run(write, 'Lot --> offset(-1.5, inside) offset(-1, border) report("a", geometry.area) X.\n',
            [DUMBBELL])
    assert totals(r)["a_sum"] == pytest.approx(2 * (49 - 25))


def test_offset_that_leaves_nothing_keeps_the_shape_as_it_was(write):
    """An inset of 1.4 of a face 2.4 wide leaves nothing: PRT ignores such an offset ("no face selected,
    ignoring operation") and goes on with the face (candler's roof pipes on a tiny lot, 2160.7 m2 in PRT
    where dropping the roof gave 1141.5); in one batch with a face wide enough, each shape its own way."""
    text = 'Lot --> offset(-1.4, inside) report("a", geometry.area) report("x", scope.sx) extrude(0.7) X.\n'
    lots = per_lot(run(write, text, [rect(2.4, 6), rect(12, 8)]))
    assert [(t["a_sum"], t["x_sum"]) for _, t in sorted(lots.items())] == [
        (pytest.approx(2.4 * 6), pytest.approx(2.4)), (pytest.approx(9.2 * 5.2), pytest.approx(9.2))]
    roofs = per_lot(run(write, text.replace("Lot --> ", "Lot --> roofPyramid(45) "), [rect(2.4, 2.4)]))
    assert roofs[0]["a_sum"] == pytest.approx(2.4 ** 2 * (1 + np.sqrt(2)))


def test_offset_that_nearly_collapses_keeps_its_sliver(write):
    """candler's roof on fuzz lot candler.tiny.44289 (its largest inscribed circle 0.8217 m in radius):
    ``offset(-0.8, inside)`` leaves a triangle of 3.36 dm2, which PRT keeps (its roof pipes stand on it) and
    GEOS's buffer alone finds empty; a deeper inset leaves nothing and keeps the face as it was."""
    roof = [np.array([(0.31, 0.143), (0, 1.739), (0.712, 1.89), (3.777, 0.367), (2.814, 0), (0.751, 0)], float)]
    text = 'Lot --> offset(-{d}, inside) report("a", geometry.area) X.\n'
    sliver = shapely.Polygon([(0.98553707, 0.86075826), (0.99733849, 0.8), (1.10781159, 0.8)]).area
    assert totals(run(write, text.format(d=0.8), [roof]))["a_sum"] == pytest.approx(sliver, rel=1e-5)
    assert totals(run(write, text.format(d=0.83), [roof]))["a_sum"] == pytest.approx(shapely.Polygon(roof[0]).area)


def _pyramid_offsets(d):
    """A 45-degree pyramid roof over a 10 m square offset by -d, face by face in its own plane: the
    bottom's inset and each triangle's (a similar triangle, scaled by (r - d) / r for its inradius r)."""
    side, slant = 10.0, 5.0 * np.sqrt(2)
    triangle, edge = side * slant / 2, np.sqrt(3 * 5.0 ** 2)
    r = triangle / ((side + 2 * edge) / 2)
    inside = (side - 2 * d) ** 2 + 4 * triangle * ((r - d) / r) ** 2
    return inside, side ** 2 + 4 * triangle - inside


@pytest.mark.parametrize("select", ["inside", "border", "all"])
def test_offset_of_a_roof_offsets_each_face_in_its_plane(write, select):
    """CityEngine offsets every face of a geometry: a roof's faces each in its own plane, one shape of
    them all."""
    t = totals(run(write, f'Lot --> roofPyramid(45) offset(-1, {select}) report("a", geometry.area) X.\n',
                   [rect(10, 10)]))
    inside, border = _pyramid_offsets(1.0)
    assert t["a_n"] == 1
    assert t["a_sum"] == pytest.approx({"inside": inside, "border": border, "all": inside + border}[select])


def test_offset_of_a_roof_with_comp_of_its_pieces_fails_its_lot_by_name(write):
    records = run(write, "Lot --> roofHip(30) offset(-1) comp(f){ inside: I. | border: B. }\n", [rect(10, 8)])
    (bad,) = records["bad"]
    assert bad.reason.startswith("`offset` of a roof is not supported yet (split the roof into faces")


def test_offset_of_roofs_and_faces_in_one_batch(write):
    """A roof and a face at the same offset: each offset its way, each lot's shapes in their order."""
    text = ('Lot --> split(x){ 10: roofPyramid(45) A | ~1: A }\n'
            'A --> offset(-1, inside) report("a", geometry.area) X.\n')
    lots = per_lot(run(write, text, [rect(20, 10), rect(25, 10)]))
    inside, _ = _pyramid_offsets(1.0)
    assert [(t["a_n"], t["a_sum"]) for _, t in sorted(lots.items())] == [
        (2, pytest.approx(inside + 8 * 8)), (2, pytest.approx(inside + 13 * 8))]


def test_footprint_is_the_geometry_seen_from_above(write):
    """The reference's example extrudes the footprint of an inserted building again: here of a hip roof
    (its outline), of a holed solid (the courtyard keeps its hole), and of a cube (its box); a wall, seen
    along its own scope y (up the wall), covers no area and is left out."""
    text = ('Lot --> {} footprint() report("a", geometry.area) report("y", scope.sy) '
            'extrude(3) report("v", geometry.volume) X.\n')
    for before, lot, area in [("roofHip(30)", LOT_ZOO["concave_L"], 400), ("extrude(8)", LOT_ZOO["courtyard"], 1200),
                              ('s(4, 5, 6) i("builtin:cube")', rect(10, 8), 24)]:
        t = totals(run(write, text.format(before), [lot]))
        assert (t["a_sum"], t["y_sum"], t["v_sum"]) == (pytest.approx(area), 0, pytest.approx(3 * area))
    r = run(write, "Lot --> extrude(8) comp(f){ side : footprint() W. | top : T. }\n", [rect(10, 8)])
    assert names(r) == ["T"]


def test_footprint_that_falls_apart_is_one_shape_of_its_parts(write):
    """A courtyard's offset border, two rings (around the lot and around the hole) of one shape, extruded:
    its footprint is a mesh of the two rings in one scope."""
    text = ('Lot --> offset(-2, border) extrude(1) footprint() report("n", geometry.nFaces) '
            'report("a", geometry.area) comp(f){ all : F. }\n')
    t = totals(run(write, text, [LOT_ZOO["courtyard"]]))
    assert (t["n_sum"], t["a_sum"], t["a_n"]) == (2, pytest.approx(40 * 40 - 36 * 36 + 24 * 24 - 20 * 20), 1)


def test_rectify_snaps_edges_near_the_scope_axes(write):
    """The reference's example: a face whose edges lean a few degrees off its scope's axes becomes
    rectangular with ``rectify(15)`` (the lot's scope runs along its first edge); with an angle below the
    lean it stays as it was; a face that leans more is left out of the snap."""
    lot = [np.array([[0, 0], [20, 0], [20.5, 12], [-0.4, 11.6]], float)]
    text = ('Lot --> rectify({}) report("r", geometry.isRectangular(0.01)) report("n", geometry.nVertices) '
            'report("x", scope.sx) X.\n')
    t = totals(run(write, text.format(15), [lot]))
    assert (t["r_sum"], t["n_sum"]) == (True, 4) and 20 < t["x_sum"] < 20.5
    t = totals(run(write, text.format(1), [lot]))
    assert (t["r_sum"], t["x_sum"]) == (False, pytest.approx(20.9))
    (bad,) = run(write, "Lot --> extrude(3) rectify(10) X.\n", [rect(10, 8)])["bad"]
    assert bad.reason.startswith("`rectify` of a solid is not supported yet")


@pytest.mark.parametrize("select", ["", "comp(f){ inside : I. | border : B. }", "Roof.", "setback", "shapeL"])
def test_an_offset_or_setback_beyond_any_coordinate_fails_its_lot(write, select):
    """An outline moved out by more than float32 holds (GEOS raised on 1e308) fails its lot; moved in that
    far, or by -inf (GEOS raised on it), nothing is left of it, which is no error."""
    body = {"Roof.": "extrude(3) comp(f){ top : roofHip(30) offset(d) Roof. }",
            "setback": "setback(d){ front : A. | remainder : B. }",
            "shapeL": "shapeL(d, 2){ shape : A. | remainder : B. }"}.get(select, f"offset(d) {select or 'A.'}")
    what = "setback" if select in ("setback", "shapeL") else "offset"
    r = run(write, f"attr d = -1\nLot --> {body}\n", [rect(10, 10)] * 4,
            lot_attrs={"d": np.array([-1.0, 1e308, -1e308, -np.inf])})
    reasons = [(b.index, b.reason.split(" in rule")[0]) for b in r["bad"]]
    assert reasons == [(1, f"`{what}` by 1e+308, beyond any coordinate")]


def test_an_offset_of_a_geometry_scaled_beyond_any_coordinate_fails_its_lot(write):
    """As the build fuzz test found it: a lot scaled by -1e308 has faces GEOS takes no ring of (it raised
    and stopped the build); the scale fails it (``Context.refuse_far``), before the offset."""
    r = run(write, "attr z = 0\nLot --> s(1, 1, z) A\nA --> offset(-0.1, inside) B.\n",
            [rect(10, 10)] * 2, lot_attrs={"z": np.array([0.0, -1e308])})
    assert [(b.index, b.reason.split(" in rule")[0]) for b in r["bad"]] == [
        (1, "a scope sized or placed beyond any coordinate (1e+308)")]


def test_an_offset_by_a_distance_that_is_not_a_number_fails_its_lot(write):
    """0/0 (GEOS raised on it): the lot is named, the others derived."""
    r = run(write, "attr d = 1\nLot --> offset(-d / d) A.\n", [rect(10, 10)] * 2,
            lot_attrs={"d": np.array([1.0, 0.0])})
    assert [(b.index, b.reason.split(" in rule")[0]) for b in r["bad"]] == [
        (1, "`offset` by a distance that is not a number")]


@pytest.mark.parametrize("text", ["Lot --> roofShed(1) offset(0, inside) X.\n",
                                  "Lot --> roofShed(1) comp(f){ all : F }\nF --> offset(-0.1, inside) X.\n"])
def test_offset_of_a_face_that_crosses_itself_takes_its_valid_parts(write, text):
    """A shed roof over a concave outline has a side face that crosses itself under the reflex corner (a bow
    tie 2.5 cm high), which GEOS's overlay refused ("side location conflict": the build stopped with a
    traceback, found by the build fuzz); its valid parts are offset, and every face makes its pieces."""
    concave = [np.array([[0.0, -2.0], [1.0, -1.0], [3.0, 0.0], [0.0, 0.0]])]
    r = run(write, text, [concave])
    assert not r["bad"] and len(mesh_faces(r)) >= 4
