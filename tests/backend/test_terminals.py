"""backend/terminals.py: leaves as quads and mesh faces, and inserts trimmed at their trim planes
with the asset meshes the plan's loader gives."""

from __future__ import annotations

import numpy as np
import pytest
from operations.derivations import VERSION, make_lots_polys, names, paper, rect, run

from grammarc.backend.derive import derive_chunk
from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.constants import LIMITS
from grammarc.errors import AssetError
from grammarc.io.lots import lots_from_polygons
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
    """The last guard before records are made: an instance whose transform is not finite as float32 (a
    height of 1e308 or inf) fails its lot, named with the rule; the others are written."""
    text = 'attr height = 9\nlot ~> S(1r, height, 1r) Repeat("X", 2){ I("cube") }\n'
    r = paper(write, text, [rect(4, 4)] * 2, lot_attrs={"height": np.array([9.0, height])})
    assert np.isfinite(r["xform"]).all() and r["lot"].tolist() == [0, 0]
    [bad] = r["bad"]
    assert bad.index == 1 and bad.reason.startswith("an instance with a coordinate of ")
    assert "(not finite as float32) in rule `lot` at " in bad.reason


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
    assert bad.index == 1 and bad.reason.startswith("a mesh vertex with a coordinate of ")
    assert "(not finite as float32) in rule `Lot` at " in bad.reason
