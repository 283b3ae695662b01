"""backend/terminals.py: leaves as quads and mesh faces, and inserted geometry (not a shape's own) trimmed
at its trim planes with the asset meshes the plan's loader gives."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import PRT_KIT, needs_kit
from operations.derivations import VERSION, assets, make_lots_polys, names, paper, rect, run
from shapely.geometry import Polygon

from grammarc.backend.derive import derive_chunk
from grammarc.backend.plan import make_plan
from grammarc.build import derive
from grammarc.compiler import compile_grammar
from grammarc.conform import measure
from grammarc.conform.cases import Case, write_lots
from grammarc.conform.fuzz import lot_record, open_packages
from grammarc.constants import LIMITS
from grammarc.errors import AssetError
from grammarc.io.bake import bake
from grammarc.io.lots import lots_from_polygons, read_lots
from grammarc.model.assets import load_asset

LEDGE = ("Lot --> extrude(10) {set}comp(f){{ side : Facade }}\n"
         "Facade --> split(y){{ 1 : Ledge | ~1 : NIL }}\n"
         "Ledge --> s('1.2, '1, 0.5) center(x) primitiveCube()\n")


def test_trim_planes_mitre_inserts_at_corners_unless_turned_off(write):
    """A ledge wider than its facade is cut at the corners' trim planes (mesh faces, not instances);
    ``set(trim.vertical, false)`` keeps it whole; the horizontal plane at the facade's foot, which the
    ledge does not reach past, leaves it as the vertical ones cut it."""
    base = LEDGE
    trimmed = run(write, base.format(set=""), [rect(12, 8)])
    assert len(trimmed["asset"]) == 0 and len(trimmed["mesh"].lot) > 0
    whole = run(write, base.format(set="set(trim.vertical, false) "), [rect(12, 8)])
    assert len(whole["asset"]) == 4 and len(whole["mesh"].lot) == 0
    also = run(write, base.format(set="set(trim.horizontal, true) "), [rect(12, 8)])
    assert np.array_equal(also["mesh"].vertices, trimmed["mesh"].vertices)


FRAME = ("Lot --> extrude(10) comp(f){{ side : Facade | top : Top }}\n"
         "Facade --> split(y){{ 1 : Frame | ~1 : NIL }}\n"
         "Frame --> s('1.2, '1, {depth}) center(x) {frame}\n"
         "Top --> i(\"builtin:cube\")\n")  # an insert (a flat one, a quad): the grammar has trim planes


@pytest.mark.parametrize("depth, frame, cut", [
    (0, "extrude(0.5)", False),  # the shape's own box
    (0.5, "primitiveCube()", True),  # inserted
    (0, "primitiveCube(14, 1, 0.5)", True),  # a primitive with its sizes
    (0.5, "primitiveCube() split(x){ ~1 : Piece | ~1 : Piece }", True),  # pieces of an inserted cube
    (0, "primitiveQuad() extrude(0.5)", False),  # a box extruded from an inserted face
    (0, "extrude(0.5) i(\"builtin:cube\")", True),  # own geometry replaced by an insert
])
def test_trim_planes_cut_inserted_geometry_not_the_shapes_own(write, depth, frame, cut):
    """CityEngine trims geometry as ``i()`` and the primitives insert it, never a box ``extrude`` made: a
    frame wider than its facade is cut at the corners' trim planes where it is inserted (mesh faces), and
    stands whole across them (instances) where it is extruded, even from an inserted face."""
    r = run(write, FRAME.format(depth=depth, frame=frame), [rect(12, 8)])
    whole = assets(r).count("builtin:cube")
    assert (len(r["mesh"].lot) > 0) == cut and (whole == 0) == cut


@needs_kit
def test_complexpatterns_window_frames_cross_a_notchs_trim_planes_whole_as_in_prt(tmp_path):
    """complexpatterns on a notched lot: its window frames are extruded, its milk glass a primitiveCube;
    PRT leaves the frames whole where they cross the trim planes of the outline's notches and cuts the
    glass. PRT's surface area of this lot is 1161.628699 m² (PyPRT 1.12, measured as the harness does);
    grammarc made 1145.81 m² (-1.4 %) when it cut every leaf box."""
    lot = Polygon([(6.284, -3.708), (10.171, -0.515), (7.319, 0.989), (7.613, 3.043), (5.488, 2.503),
                   (8.669, 5.222), (4.737, 3.365), (0.134, 10.102), (-9.45, 0.38), (-5.476, -0.129),
                   (-8.289, -5.617), (-4.104, -6.058), (-1.923, -7.337), (1.934, -7.843)])
    attrs = {"buildingH": 9.16, "floorH": 5.44, "groundfloorH": 4.08, "nSymmetries": 2.0, "borderwallW": 0.26,
             "ledgeH": 0.2, "windowW": 3.85, "milkGlassW": 3.89, "blindH": 2.4, "frameW": 0.45,
             "balconyDepth": 4.08}
    with open_packages(["complexpatterns"], PRT_KIT) as packages:
        package = packages["complexpatterns"]
        write_lots(tmp_path / "lot.geojson", [Case("complexpatterns", "concave", 0, attrs, lot)])
        record = derive(package.grammar, read_lots(tmp_path / "lot.geojson"), package.options)
        area = measure(bake(lot_record(record, 0), package.options.asset_roots))["surface_area"]
    assert area == pytest.approx(1161.628699, rel=1e-4)


def test_trims_take_their_asset_meshes_from_the_plans_loader(write):
    """The derivation opens no asset file itself: the plan's loader gives the meshes trims cut, each asked
    for once in a chunk; an asset the loader cannot give stays whole."""
    grammar = compile_grammar(write("g.cga", VERSION + LEDGE.format(set="")))
    lots = lots_from_polygons([rect(12, 8), rect(10, 10)])
    asked = []

    def counting(name, roots):
        asked.append(name)
        return load_asset(name, roots)

    def missing(name, roots):
        raise AssetError(f"no root holds {name}")

    options = {"seed": 0, "limits": LIMITS, "overrides": {}, "chunk_budget": 10**9}
    trimmed, _ = derive_chunk(make_plan(grammar, load_asset=counting), lots, **options)
    assert asked == ["builtin:cube"] and len(trimmed.asset) == 0 and len(trimmed.mesh.lot) > 0
    whole, _ = derive_chunk(make_plan(grammar, load_asset=missing), lots, **options)
    assert len(whole.asset) == 8 and len(whole.mesh.lot) == 0


def test_leaf_face_is_a_quad_facing_outwards(write):
    r = paper(write, 'lot ~> S(1r, 3, 1r) Comp("sidefaces"){ wall }\n', make_lots_polys("square"))
    assert set(r["assets"][r["asset"]]) == {"builtin:quad"}
    normals = np.cross(r["xform"][:, :, 0], r["xform"][:, :, 1])
    centres = r["xform"][:, :, 3] + (r["xform"][:, :, 0] + r["xform"][:, :, 1]) / 2
    middle = np.array([5, 1.5, -5])
    assert (np.einsum("ij,ij->i", normals, centres - middle) > 0).all()


def test_polygon_leaves_go_to_the_mesh_table(write):
    r = paper(write, 'lot ~> S(1r, 3, 1r) mass\n', make_lots_polys("concave_L", "square"))
    mesh = r["mesh"]
    # the L prism: bottom, top and 6 sides; the square is a box: one cube instance
    assert list(mesh.lot) == [0] * 8 and list(r["lot"]) == [1]
    assert len(r["asset"]) == 1 and r["assets"][r["asset"][0]] == "builtin:cube"



@pytest.mark.parametrize("leaf", ["roofHip(30) R.", "extrude(3) E."])  # a roof; a prism's faces
def test_mesh_faces_carry_the_texture_coordinates_of_their_vertices(write, leaf):
    """Projected from above in 2 m tiles: every vertex of the mesh table has u = x / 2, v = z / 2."""
    r = run(write, f"Lot --> setupProjection(0, world.xz, 2, 2) projectUV(0) {leaf}\n",
            make_lots_polys("concave_L"))
    mesh = r["mesh"]
    assert len(mesh.lot) and mesh.uv.shape == (len(mesh.vertices), 2)
    np.testing.assert_allclose(mesh.uv, mesh.vertices[:, [0, 2]] / 2, atol=1e-5)


def test_inserted_geometry_carries_no_texture_coordinates(write):
    """An inserted asset, whole or trimmed at the corners, has its own coordinates, which grammarc does not
    keep: it carries none, where the boxes and faces of the same grammar carry theirs."""
    r = run(write, "Lot --> setupProjection(0, world.xz, 2, 2) projectUV(0) extrude(10) comp(f){ side : Facade "
            "| top : T. }\nFacade --> split(y){ 1 : Ledge | 1 : W | ~1 : NIL }\nW --> i(\"builtin:cylinder\")\n"
            "Ledge --> s('1.2, '1, 0.5) center(x) i(\"builtin:cylinder\")\n", [rect(12, 8)])
    top = np.array(names(r)) == "T"
    assert np.isnan(r["uv"][~top]).all() and not np.isnan(r["uv"][top]).any()
    trimmed = r["mesh"]
    assert len(trimmed.lot) and trimmed.uv is None


@pytest.mark.parametrize("height", [1e308, np.inf, 1e39])
def test_a_record_with_a_coordinate_that_is_not_finite_fails_its_lot_with_the_rule(write, height):
    """An instance whose transform would not be finite as float32 (a height of 1e308 or inf) fails its lot,
    named with the rule, where the scale makes the scope (``Context.refuse_far``; the records' own guard
    stands behind it); the others are written."""
    text = 'attr height = 9\nlot ~> S(1r, height, 1r) Repeat("X", 2){ I("cube") }\n'
    r = paper(write, text, [rect(4, 4)] * 2, lot_attrs={"height": np.array([9.0, height])})
    assert np.isfinite(r["xform"]).all() and r["lot"].tolist() == [0, 0]
    [bad] = r["bad"]
    assert bad.index == 1 and bad.reason.startswith(f"a scope sized or placed beyond any coordinate ({height:g})")
    assert " in rule `lot` at " in bad.reason


def test_records_whose_sum_overflows_float32_are_finite_and_kept(write):
    """Finite transforms whose float32 sum is not (two heights of 3e38) are checked value by value and kept:
    the sum only spares that check where it is finite."""
    text = 'attr height = 9\nlot ~> S(1r, height, 1r) Repeat("X", 2){ I("cube") }\n'
    r = paper(write, text, [rect(4, 4)] * 2, lot_attrs={"height": np.array([3e38, 3e38])})
    assert not r["bad"] and r["lot"].tolist() == [0, 0, 1, 1]
    with np.errstate(over="ignore"):
        assert np.isinf(r["xform"].astype(np.float32).sum()) and np.isfinite(r["xform"]).all()


def test_a_mesh_vertex_that_is_not_finite_fails_its_lot_with_the_rule(write):
    r = run(write, "attr h = 3\nLot --> roofHip(byHeight, h) Roof.\n", [rect(10, 10)] * 2,
            lot_attrs={"h": np.array([3.0, 1e39])})
    assert np.isfinite(r["mesh"].vertices).all() and np.unique(r["mesh"].lot).tolist() == [0]
    [bad] = r["bad"]
    assert bad.index == 1 and bad.reason.startswith("a scope sized or placed beyond any coordinate (")
    assert " in rule `Lot` at " in bad.reason
