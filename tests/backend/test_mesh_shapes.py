"""backend/mesh_shapes.py: roof and convex-part shapes in derivations - scopes as CityEngine sets them,
component splits, leaves, measures, errors - and cleanupGeometry of polygons and meshes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import shapely
from conftest import LOT_ZOO
from operations.derivations import assets, face_area, mesh_faces, names, per_lot, rect, run, totals

from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar
from grammarc.errors import GrammarError
from grammarc.io.lots import lots_from_polygons

TAN30 = np.tan(np.radians(30))
SIMPLE_BUILDING = Path(__file__).resolve().parents[1] / "frontend" / "grammars" / "simple_building.cga"


def shapely_area(rings):
    return shapely.Polygon(rings[0], rings[1:]).area


def test_roof_on_a_footprint_keeps_x_puts_y_up_and_fits_the_mesh(write):
    r = run(write, "Lot --> roofHip(30) Roof\nRoof --> primitiveCube()\n", [rect(12, 8)])
    [x] = r["xform"]
    np.testing.assert_allclose(x[:, 0], [12, 0, 0], atol=1e-6)
    np.testing.assert_allclose(x[:, 1], [0, 4 * TAN30, 0], atol=1e-6)
    np.testing.assert_allclose(x[:, 3], [0, 0, -8], atol=1e-6)


def test_roof_on_the_top_face_of_a_mass_sits_on_it_and_keeps_the_face_axes(write):
    text = ("Lot --> extrude(10) comp(f){ top : Top | all : NIL }\n"
            "Top --> roofGable(30) Roof\nRoof --> primitiveCube()\n")
    [x] = run(write, text, [rect(12, 8)])["xform"]
    # the top face's scope: x along the lot's x, y across it, z its normal (world +y); the roof keeps
    # them, as PRT keeps an envelope's, and rises along z
    np.testing.assert_allclose(x[:, 0], [12, 0, 0], atol=1e-6)
    np.testing.assert_allclose(np.abs(x[:, 1]), [0, 0, 8], atol=1e-6)
    np.testing.assert_allclose(x[:, 2], [0, 4 * TAN30, 0], atol=1e-6)
    assert x[1, 3] == pytest.approx(10.0)


def test_roof_leaf_is_its_faces_and_comp_selects_them_by_normal(write):
    r = run(write, "Lot --> roofGable(30) Roof\n", [rect(12, 8)])
    faces = mesh_faces(r)
    assert len(faces) == 5 and names(r) == []
    # bottom, two slopes of 12 x 4 / cos 30, two gable triangles of 8 x (4 tan 30) / 2
    total = sum(face_area(f) for f in faces)
    assert total == pytest.approx(96 + 96 / np.cos(np.radians(30)) + 8 * 4 * TAN30)
    text = ("Lot --> roofGable(30) comp(f){ bottom : B | top : T | side : S }\n"
            "B --> primitiveCube()\nT --> primitiveCube()\nS --> primitiveCube()\n")
    r = run(write, text, [rect(12, 8)])
    assert sorted(names(r)) == ["B", "S", "S", "T", "T"]


def test_roof_faces_have_eave_aligned_scopes_and_their_areas(write):
    text = "Lot --> roofHip(30) comp(f){ top : Plane }\nPlane --> report(\"a\", geometry.area) primitiveCube()\n"
    r = run(write, text, [rect(12, 8)])
    x = r["xform"].astype(float)
    # every roof plane: x along its eave (horizontal), y up the slope at 30 degrees
    assert np.abs(x[:, 1, 0]).max() < 1e-6
    rise = x[:, 1, 1] / np.linalg.norm(x[:, :, 1], axis=1)
    np.testing.assert_allclose(rise, np.sin(np.radians(30)), atol=1e-6)
    assert totals(r)["a_sum"] == pytest.approx(12 * 8 / np.cos(np.radians(30)))


def test_comp_v_of_a_roof_gives_each_vertex_once_with_y_along_its_mean_normal(write):
    text = ('Lot --> roofHip(30) comp(v){ all : V }\n'
            'V --> report("size", scope.sx + scope.sy + scope.sz) s(1, 1, 1) primitiveCube()\n')
    r = run(write, text, [rect(12, 8)])
    x = r["xform"].astype(float)
    np.testing.assert_allclose(np.sort(x[:, 1, 3]), [0, 0, 0, 0, 4 * TAN30, 4 * TAN30], atol=1e-5)
    assert totals(r)["size_max"] == 0  # points
    ridge = x[:, 1, 3] > 1
    assert (x[ridge, 1, 1] > 0.9).all()  # the ridge ends' y is nearly up: the mean of three planes


def test_geometry_volume_and_area_of_a_roof(write):
    text = ('Lot --> roofHip(30) report("v", geometry.volume) report("n", geometry.nFaces) '
            'report("k", geometry.nVertices)\n')
    r = run(write, text, [rect(12, 8)])
    h = 4 * TAN30
    assert totals(r)["v_sum"] == pytest.approx(12 * 8 * h / 2 - 64 * h / 6)
    assert totals(r)["n_sum"] == 5 and totals(r)["k_sum"] == 6


@pytest.mark.parametrize("op", ["roofHip(30)", "roofGable(30, 0.5)", "roofShed(15, 2)", "roofPyramid(byHeight, 4)",
                                "roofHip(byHeight, 3, 1)"])
def test_every_roof_on_every_zoo_lot_derives(write, op):
    r = run(write, f"Lot --> {op} comp(f){{ all : F }}\nF --> X\n",
            [LOT_ZOO[n] for n in ("square", "rect_12x8", "concave_L", "courtyard")])
    assert r["bad"] == () and set(r["mesh"].lot.tolist()) == {0, 1, 2, 3}


def test_paper_roof_covers_the_footprint_of_the_mass(write):
    text = 'lot ~> S(1r, 10, 1r) T(0, 10, 0) Roof("hipped", 30){ roof }\nroof ~> Comp("faces"){ I("cube") }\n'
    r = run(write, text, [rect(12, 8)], version=False)
    assert assets(r).count("builtin:cube") == 5
    assert r["xform"][:, 1, 3].min() == pytest.approx(10.0, abs=1e-5)


@pytest.mark.parametrize("lot", ["concave_L", "courtyard"])
@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_split_of_a_concave_roof_cuts_it_into_closed_slabs(write, lot, axis):
    """A hip roof over an L or a courtyard is concave: its slabs are closed by their sections (a ring
    with a hole where a horizontal cut crosses the courtyard roof), so their volumes add up to the
    roof's (the divergence theorem counts a missing cap)."""
    text = (f'Lot --> roofHip(30) [ report("whole", geometry.volume) ] split({axis}){{ ~{0.8 if axis == "y" else 1.3} : Slab }}*\n'
            'Slab --> report("v", geometry.volume)\n')
    r = run(write, text, [LOT_ZOO[lot]])
    assert r["bad"] == ()
    t = totals(r)
    assert t["v_n"] > 2 and t["v_sum"] == pytest.approx(t["whole_sum"], rel=1e-9)


def test_extrude_of_a_roof_makes_a_solid_of_each_face_along_its_normal(write):
    """As the reference's face.normal: the bottom slab hangs below the footprint, the planes' slabs stand
    out of them, each face's area times the height; the scope keeps its axes, fitted to the solids."""
    r = run(write, 'Lot --> roofHip(30) extrude(0.5) report("v", geometry.volume) report("y", scope.ty) '
                   'report("sx", scope.sx)\n', [rect(12, 8)])
    t = totals(r)
    assert r["bad"] == () and t["v_sum"] == pytest.approx(0.5 * (96 + 96 / np.cos(np.radians(30))))
    assert t["y_sum"] == pytest.approx(-0.5) and t["sx_sum"] > 12
    r = run(write, "Lot --> roofHip(30) extrude(world.up, 3)\n", [rect(12, 8)])
    assert "`extrude` along world.up of a roof is not supported yet" in r["bad"][0].reason


def test_split_of_a_convex_roof_cuts_it_into_closed_slabs(write):
    """A hip roof on a rectangle is convex: split across its ridge, the slabs are its pieces, closed by
    their cut faces (volumes add up to the roof's), and each slab's scope fits its piece."""
    text = ('Lot --> roofHip(45) split(x){ 3 : Slab | ~1 : Slab | 3 : Slab }\n'
            'Slab --> report("v", geometry.volume) report("sx", scope.sx) report("n", geometry.nFaces)\n')
    r = run(write, text, [rect(12, 8)])
    t = totals(r)
    height = 4.0  # 45 degrees over half the 8 m width
    assert t["v_sum"] == pytest.approx(12 * 8 * height / 2 - 64 * height / 6)
    assert t["v_n"] == 3 and t["sx_sum"] == pytest.approx(12)
    assert t["n_max"] == 7 and t["n_min"] == 5  # ends: 3 planes, bottom, cap; middle: 4 planes, bottom, 2 caps


def test_envelope_is_walls_and_slopes_cut_flat(write):
    """candler's ventilation housing: envelope(world.up, 0.6, 0.45, 45, ...) over a 10 x 4 face: 0.45 m
    walls, then 45 degree planes, cut at 0.6 m: a box and a frustum."""
    text = ('Lot --> envelope(world.up, 0.6, 0.45, 45, 0.45, 45, 0.45, 45) report("v", geometry.volume) '
            'report("sy", scope.sy) comp(f){ top : Top | all : NIL }\nTop --> report("top", geometry.area)\n')
    r = run(write, text, [rect(10, 4)])
    t = totals(r)
    frustum = sum((10 - 2 * s) * (4 - 2 * s) * 0.0015 for s in np.arange(0.00075, 0.15, 0.0015))
    assert t["v_sum"] == pytest.approx(18 + frustum, rel=1e-6) and t["sy_sum"] == pytest.approx(0.6)
    assert t["top_sum"] == pytest.approx(9.7 * 3.7)


def test_envelope_per_side_classifies_the_lots_edges(write):
    """The reference's forms: front and back (the sides as the front), front, back and sides, and
    front, back, right, left, on a 10 x 4 lot: 3 m walls at 45 degrees in front, 1 m at the back, and
    vertical sides give the profile (0, 0) (4, 0) (4, 1) (1, 4) (0, 3) of 11 m2 along 10 m."""
    def volume(call):
        r = run(write, f'Lot --> {call} report("v", geometry.volume) report("h", scope.sy)\n', [rect(10, 4)])
        assert not r["bad"]
        return totals(r)["v_sum"], totals(r)["h_sum"]

    assert volume("envelope(world.up, 20, 3, 45, 1, 45, 0, 90)") == (pytest.approx(110), pytest.approx(4))
    assert volume("envelope(normal, 20, 1, 45, 3, 45, 0, 90, 0, 90)") == (pytest.approx(110), pytest.approx(4))
    # front and back alike, the sides taking the front's: the one-pair form
    assert volume("envelope(world.up, 20, 2, 45, 2, 45)") == volume("envelope(world.up, 20, 2, 45)")
    # cut flat at 3 m: the profile's part below, (0, 0) (4, 0) (4, 1) (2, 3) (0, 3): 10 m2
    assert volume("envelope(world.up, 3, 3, 45, 1, 45, 0, 90)") == (pytest.approx(100), pytest.approx(3))


def test_envelope_angles_outside_0_to_90_are_reported(write):
    r = run(write, "Lot --> envelope(normal, 5, 1, 45, 2, 0)\n", [rect(10, 4)])
    assert "`envelope` with an angle outside (0, 90]" in r["bad"][0].reason


def test_rotate_scope_of_a_roof_turns_its_scope_around_the_same_mesh(write):
    text = ('Lot --> roofHip(30) rotateScope(0, 90, 0) report("sx", scope.sx) report("sz", scope.sz) '
            'report("a", geometry.area)\n')
    r = run(write, text, [rect(12, 8)])
    t = totals(r)
    assert (t["sx_sum"], t["sz_sum"]) == (pytest.approx(8), pytest.approx(12))
    assert t["a_sum"] == pytest.approx(96 + 96 / np.cos(np.radians(30)))


def test_roof_of_a_solid_and_overhang_y_are_reported(write):
    r = run(write, "Lot --> extrude(3) roofHip(30)\n", [rect(12, 8)])
    assert "of a solid" in r["bad"][0].reason
    r = run(write, "Lot --> roofGable(30, 1, 2)\n", [rect(12, 8)])
    assert "overhangY other than overhangX" in r["bad"][0].reason


def test_paper_roof_types_outside_the_known_set_are_errors(write):
    with pytest.raises(GrammarError, match='unknown roof type "gambril"'):
        run(write, 'lot ~> Roof("gambril", 30){ roof }\n', [rect(12, 8)], version=False)


@pytest.mark.parametrize("kind", ["mansard", "gambrel", "cross-gable", "cone", "shed", "pyramid"])
def test_every_paper_roof_type_derives_on_concave_footprints(write, kind):
    text = f'lot ~> S(1r, 6, 1r) T(0, 6, 0) Roof("{kind}", 30){{ roof }}\nroof ~> Comp("sidefaces"){{ I("cube") }}\n'
    r = run(write, text, [LOT_ZOO["concave_L"], LOT_ZOO["courtyard"]], version=False)
    assert r["bad"] == () and set(r["lot"].tolist()) == {0, 1}


def test_paper_comp_of_a_roof_gives_planes_hips_and_the_ridge(write):
    text = ('lot ~> Roof("hipped", 30){ roof }\n'
            'roof ~> Comp("sidefaces"){ plane } Comp("sideedges"){ hip } Comp("topedges"){ ridge }\n'
            'plane ~> I("cube")\nhip ~> I("cube")\nridge ~> I("cube")\n')
    r = run(write, text, [rect(12, 8)], version=False)
    count = {n: names(r).count(n) for n in ("plane", "hip", "ridge")}
    assert count == {"plane": 4, "hip": 4, "ridge": 1}
    ridge = r["xform"][np.array(names(r)) == "ridge"][0]
    assert np.linalg.norm(ridge[:, 0]) == pytest.approx(4.0)  # 12 - 8: the ridge of a hip roof
    assert ridge[1, 3] == pytest.approx(4 * TAN30, abs=1e-5)
    hips = r["xform"][np.array(names(r)) == "hip"]
    np.testing.assert_allclose(np.linalg.norm(hips[:, :, 0], axis=1), np.sqrt(32 + (4 * TAN30) ** 2), rtol=1e-6)


def test_cityengine_comp_e_of_a_roof_selects_edges_by_direction(write):
    text = "Lot --> roofGable(30) comp(e){ horizontal : H | aslant : A | all : V }\n"
    for sym in "HAV":
        text += f'{sym} --> report("{sym}", 1)\n'
    r = run(write, text, [rect(12, 8)])
    # 4 footprint edges and the ridge; 4 rafters at the gable ends; no vertical edge
    assert {k: v for k, v in totals(r).items() if k.endswith("_n")} == {"A_n": 4, "H_n": 5}


@pytest.mark.parametrize("lot", ["concave_L", "courtyard", "rect_12x8"])
def test_paper_section4_building_covers_its_hipped_roof_with_bricks(lot):
    """The simple building of the CGA paper (section 4, rules 1-13 less the two context rules) on concave
    footprints: bricks and roof edges lie on the roof, between the eaves and the ridge."""
    grammar = compile_grammar(SIMPLE_BUILDING)
    r = derive(grammar, lots_from_polygons([LOT_ZOO[lot]]), BuildOptions())
    assert r["bad"] == ()
    symbol = np.array(names(r))
    assert {"flatbrick", "roofedge", "window", "wall", "door"} <= set(symbol.tolist())  # rule 3: an entrance
    ridge = 5 * TAN30 if lot != "rect_12x8" else 4 * TAN30
    for name in ("flatbrick", "roofedge"):
        y = r["xform"][symbol == name][:, 1, 3]
        assert (y >= 9 - 1e-4).all() and (y <= 9 + ridge + 1e-4).all()
    # the roof planes are covered: bricks of 0.4 x 0.3 m at least fill the planes' rectangular parts
    bricks = r["xform"][symbol == "flatbrick"].astype(float)
    brick_area = np.linalg.norm(np.cross(bricks[:, :, 0], bricks[:, :, 1]), axis=1).sum()
    mesh = r["mesh"]
    pieces = sum(face_area(f) for f, s in zip(mesh_faces(r), mesh.symbol) if r["symbols"][s] == "flatbrick")
    footprint = shapely_area(LOT_ZOO[lot])
    assert brick_area + pieces == pytest.approx(footprint / np.cos(np.radians(30)), rel=1e-4)


@pytest.mark.parametrize("op", ["roofHip(30)", "roofGable(45)", "roofShed(10)", "roofPyramid(20)"])
def test_roofs_on_degenerate_footprints_derive_or_are_reported(write, op):
    """A sliver, repeated and collinear vertices, and a clockwise ring (the lot reader turns it)."""
    noisy = [np.array([[0, 0], [5, 0], [5, 0], [10, 0], [10, 6], [10, 6], [0, 6]], float)]
    clockwise = [LOT_ZOO["concave_L"][0][::-1].copy()]
    r = run(write, f"Lot --> {op} Roof.\n", [LOT_ZOO["sliver"], noisy, clockwise])
    assert r["bad"] == ()
    assert set(r["mesh"].lot.tolist()) == {0, 1, 2}
    # the noisy rectangle's roof is the clean rectangle's
    clean = run(write, f"Lot --> {op} Roof.\n", [rect(10, 6)])
    assert sum(face_area(f) for f, lot in zip(mesh_faces(r), r["mesh"].lot) if lot == 1) == pytest.approx(
        sum(face_area(f) for f in mesh_faces(clean)))


def test_convexify_makes_one_shape_whose_faces_are_the_convex_parts(write):
    text = ('Lot --> convexify() report("n", geometry.nFaces) comp(f){ all : Part }\n'
            'Part --> report("a", geometry.area) Kind\n'
            'Kind --> case geometry.isRectangular(0) : report("rect", 1)\n        else : report("other", 1)\n')
    r = run(write, text, [LOT_ZOO["concave_L"], LOT_ZOO["rect_12x8"]])
    t = per_lot(r)
    assert t[0]["n_sum"] == 2 and t[0]["a_n"] == 2 and t[0]["a_sum"] == pytest.approx(400)
    # an L is a rectangle and a piece that keeps the cut's end as a fifth corner (PRT's candler roof on
    # the kit's L: one ventilation, on the rectangle, none on the other arm)
    assert t[0]["rect_n"] == 1 and t[0]["other_n"] == 1
    assert t[1]["n_sum"] == 1 and t[1]["a_sum"] == pytest.approx(96)  # a convex face stays itself


def test_convexified_roof_of_a_z_lays_its_arms_along_their_long_sides(write):
    """candler.Z.11103's roof (inset by 0.8 m; arms of 3.27 by 13.48 m): PRT's ventilations run along the
    arms, whose scopes lie along their long sides (from where the cut of the Z's middle ends on them)."""
    z = [np.array([[8.1, 14.81], [5.61, 1.56], [-7.87, 4.1], [-11.32, -14.2], [-8.1, -14.81], [-5.61, -1.56],
                   [7.87, -4.1], [11.32, 14.2]])]
    text = ("Lot --> extrude(10) comp(f){ top : alignScopeToGeometry(yUp, 0, 0) convexify comp(f){ all : Part } }\n"
            'Part --> case geometry.isRectangular(1) : report("sx", scope.sx) report("sy", scope.sy)\n'
            "        else : NIL\n")
    t = per_lot(run(write, text, [z]))[0]
    assert t["sx_n"] == 2 and t["sx_sum"] == pytest.approx(2 * 13.48, abs=0.02)


@pytest.mark.parametrize("turn", [0.02, 8.0, 20.0])
def test_convexified_roof_with_a_nearly_straight_corner_keeps_its_large_piece(write, turn):
    """A 30 x 20 m lot dented at the middle of a long side by a corner turning a few degrees, as candler
    cuts its roof: PRT keeps one piece of over 200 m2 (one roof access) at 0.02, 8 and 20 degrees; the cut
    along an edge's line only shaves a sliver off it, where a cut across would halve it."""
    dent = 15 * np.tan(np.radians(turn / 2))
    lot = [np.array([[0, 0], [15, dent], [30, 0], [30, 20], [0, 20]])]
    text = ("Lot --> extrude(10) comp(f){ top : offset(-0.8) comp(f){ inside : alignScopeToGeometry(yUp, 0, 0) "
            "convexify comp(f){ all : Part } } }\n"
            'Part --> case geometry.area > 200 : report("large", 1)\n        else : report("small", 1)\n')
    t = per_lot(run(write, text, [lot]))[0]
    assert t["large_n"] == 1


def test_convexified_leaf_emits_its_parts(write):
    r = run(write, "Lot --> convexify()\n", [LOT_ZOO["courtyard"]])
    faces = mesh_faces(r)
    assert len(faces) == 4 and sum(face_area(f) for f in faces) == pytest.approx(1200)


def test_offset_that_parts_a_face_keeps_one_shape_of_its_pieces(write):
    """A dumbbell: two 10 x 10 squares joined by a 1 m neck; moving in by 1 m leaves the two squares."""
    dumbbell = [np.array([[0, 0], [10, 0], [10, 4.5], [20, 4.5], [20, 0], [30, 0], [30, 10], [20, 10],
                          [20, 5.5], [10, 5.5], [10, 10], [0, 10]], float)]
    text = ('Lot --> offset(-1, inside) report("n", geometry.nFaces) report("a", geometry.area) '
            'comp(f){ all : Part }\nPart --> report("part", geometry.area)\n')
    r = run(write, text, [dumbbell, rect(12, 8)])
    t = per_lot(r)
    assert t[0]["n_sum"] == 2 and t[0]["a_sum"] == pytest.approx(128) and t[0]["part_n"] == 2
    assert t[1]["n_sum"] == 1 and t[1]["a_sum"] == pytest.approx(60)


# ------------------------------------------------------------------------------------- cleanupGeometry

#: A 10 x 6 rectangle with a collinear vertex and one 1 mm off a corner.
NOISY = [np.array([[0, 0], [5, 0], [10, 0], [10, 6], [10.001, 6.001], [0, 6]], float)]
MEASURES = ('report("{0}v", geometry.nVertices) report("{0}f", geometry.nFaces) report("{0}a", geometry.area) '
            'report("{0}x", scope.sx) report("{0}z", scope.sz)')


def test_cleanup_geometry_joins_convex_parts_back_into_their_face(write):
    text = (f"Lot --> convexify() {MEASURES.format('before')} cleanupGeometry(all, 0) {MEASURES.format('after')} "
            "comp(f){ all : Part }\nPart --> report(\"part\", geometry.area)\n")
    r = run(write, text, [LOT_ZOO["concave_L"], LOT_ZOO["courtyard"]])
    for lot, (parts, vertices, area) in enumerate([(2, 6, 400), (4, 8, 1200)]):
        t = per_lot(r)[lot]
        assert t["beforef_sum"] == parts and t["afterf_sum"] == 1 and t["afterv_sum"] == vertices
        assert t["aftera_sum"] == pytest.approx(area) and t["part_n"] == 1 and t["part_sum"] == pytest.approx(area)
        assert (t["afterx_sum"], t["afterz_sum"]) == (t["beforex_sum"], t["beforez_sum"])
    # one face in its scope's plane is a polygon again, which face operations take
    r = run(write, 'Lot --> convexify() cleanupGeometry(edges, 0) extrude(3) report("v", geometry.volume)\n',
            [LOT_ZOO["concave_L"], LOT_ZOO["courtyard"]])
    assert r["bad"] == () and [t["v_sum"] for t in per_lot(r).values()] == pytest.approx([1200, 3600])


def test_cleanup_geometry_of_a_polygon_keeps_its_scope_and_an_unchanged_rectangle_its_quad(write):
    text = f"Lot --> cleanupGeometry(all, 0.01) {MEASURES.format('')}\n"
    r = run(write, text, [NOISY, rect(12, 8)])
    noisy, clean = per_lot(r)[0], per_lot(r)[1]
    assert noisy["v_sum"] == 4 and noisy["a_sum"] == pytest.approx(60, abs=0.01)
    assert (noisy["x_sum"], noisy["z_sum"]) == pytest.approx((10.001, 6.001))  # the scope stays as it was
    [face] = mesh_faces(r)
    assert len(face) == 1 and len(face[0]) == 4
    assert clean["v_sum"] == 4 and assets(r) == ["builtin:quad"]
    # tolerance 0: only exact matches go: the collinear vertex, not the one 1 mm off the corner
    r = run(write, "Lot --> cleanupGeometry(vertices, 0) Face.\n", [NOISY])
    assert [len(ring) for ring in mesh_faces(r)[0]] == [5]


def test_cleanup_geometry_of_a_prism_cleans_its_base(write):
    text = f"Lot --> extrude(3) cleanupGeometry(vertices, 0.01) {MEASURES.format('')} report(\"vol\", geometry.volume)\n"
    t = per_lot(run(write, text, [NOISY]))[0]
    assert t["v_sum"] == 8 and t["f_sum"] == 6 and t["vol_sum"] == pytest.approx(180, abs=0.1)


def test_cleanup_geometry_that_removes_the_face_keeps_the_shape_without_geometry(write):
    # the 0.05 m wide sliver collapses under a 0.1 m merge distance; the shape goes on in its scope
    text = ('Lot --> cleanupGeometry(vertices, 0.1) report("f", geometry.nFaces) report("x", scope.sx) '
            '[ i("builtin:cube") Box ] Empty\n')
    r = run(write, text, [LOT_ZOO["sliver"], rect(12, 8)])
    sliver = per_lot(r)[0]
    assert sliver["f_sum"] == 0 and sliver["x_sum"] == pytest.approx(50)
    assert sorted(names(r)) == ["Box", "Box", "Empty"]  # the sliver's Empty leaf has no geometry
    assert len(r["mesh"].lot) == 0


def test_cleanup_geometry_leaves_boxes_assets_and_clean_roofs_as_they_are(write):
    for body in ("extrude(3)", 'i("builtin:cube")', "roofHip(30)"):
        plain = run(write, f"Lot --> {body} Leaf\n", [rect(12, 8), LOT_ZOO["concave_L"]])
        cleaned = run(write, f"Lot --> {body} cleanupGeometry(all, 0) Leaf\n", [rect(12, 8), LOT_ZOO["concave_L"]])
        np.testing.assert_array_equal(cleaned["xform"], plain["xform"])
        np.testing.assert_allclose(cleaned["mesh"].vertices, plain["mesh"].vertices, atol=1e-5)


def test_cleanup_geometry_with_a_tolerance_that_is_not_finite_fails_its_lot(write):
    r = run(write, "Lot --> cleanupGeometry(all, ln(scope.sx - 12)) Face\n", [rect(12, 8), rect(20, 8)])
    assert [b.index for b in r["bad"]] == [0]
    assert "`cleanupGeometry` with a tolerance that is not finite" in r["bad"][0].reason


def test_roof_ridge_on_the_top_of_a_mass_runs_along_the_scope_x(write):
    """The reference's example: a 30 degree roofRidge on the top face of an extruded lot; the top's
    scope x is the lot's first edge (12 long), so the ridge runs along it over the middle of the 8."""
    text = ("Lot --> extrude(10) comp(f){ top : Top | side = Sides. }\nTop --> roofRidge(byAngle, 30) Roof.\n")
    r = run(write, text, [rect(12, 8)])
    got = mesh_faces(r)
    assert len(got) == 5
    vertices = r["mesh"].vertices
    assert vertices[:, 1].max() == pytest.approx(10 + 4 * TAN30)
    ridge = vertices[np.isclose(vertices[:, 1], 10 + 4 * TAN30)]
    np.testing.assert_allclose(np.ptp(ridge, axis=0), [12, 0, 0], atol=1e-6)
    assert sum(face_area(f) for f in got) == pytest.approx(96 + 2 * 12 * 4 / np.cos(np.radians(30))
                                                           + 8 * 4 * TAN30)


@pytest.mark.parametrize("index, ridge_along", [(0, 0), (1, 2), (2, 0), (5, 2)])
def test_roof_gable_with_an_edge_index_turns_its_ridge_along_the_edge(write, index, ridge_along):
    """On a 12 x 8 lot (edge 0 along world x, edge 1 along world z) the ridge follows edge index
    (modulo the edge count); the height is half the width across it times tan(angle)."""
    r = run(write, f"Lot --> roofGable(30, 0, 0, false, {index}) Roof.\n", [rect(12, 8)])
    vertices = r["mesh"].vertices
    width = 8 if ridge_along == 0 else 12
    top = vertices[:, 1].max()
    assert top == pytest.approx(width / 2 * TAN30)
    ridge = vertices[np.isclose(vertices[:, 1], top)]
    assert np.ptp(ridge[:, ridge_along]) == pytest.approx(20 - width)


def test_roof_gable_with_an_index_and_overhangs_grows_eaves_and_gable_ends(write):
    r = run(write, "Lot --> roofGable(30, 1, 0.5, false, 0) Roof.\n", [rect(12, 8)])
    vertices = r["mesh"].vertices
    cos30 = np.cos(np.radians(30))
    np.testing.assert_allclose(vertices.min(axis=0), [-0.5, -0.5, -8 - cos30], atol=1e-6)
    np.testing.assert_allclose(vertices.max(axis=0), [12.5, 4 * TAN30, cos30], atol=1e-6)


def test_roof_gable_with_an_index_on_a_concave_lot_is_the_plain_gable(write):
    """The reference: the index works on convex shapes only; on the L it is ignored."""
    indexed = run(write, "Lot --> roofGable(30, 0, 0, false, 1) Roof.\n", [LOT_ZOO["concave_L"]])
    plain = run(write, "Lot --> roofGable(30) Roof.\n", [LOT_ZOO["concave_L"]])
    np.testing.assert_array_equal(indexed["mesh"].vertices, plain["mesh"].vertices)
