"""backend/operations/scope.py in derivations: ``T S R`` and ``t s r``, ``center``, ``extrude``,
``alignScopeToAxes`` and ``rotateScope``, and sizes that fail their lot."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import LOT_ZOO
from derivations import (
    assets,
    face_area,
    mesh_faces,
    names,
    paper,
    quad_normals,
    rect,
    rotated_rectangle,
    rows,
    run,
    same_records,
    totals,
)


def test_extrude_leaves_one_cube_of_the_height(write):
    """CityEngine: a rule that makes no successor leaves its shape; the mass is the lot's box."""
    r = run(write, "Lot --> extrude(10)\n", [rect(12, 8)])
    assert assets(r) == ["builtin:cube"] and names(r) == ["Lot"]
    np.testing.assert_allclose(r["xform"][0], [[12, 0, 0, 0], [0, 10, 0, 0], [0, 0, 8, -8]])


@pytest.mark.parametrize("lot, faces, area", [
    # L: bottom, six sides, top; 2 * 400 + perimeter 100 * 10
    ("concave_L", 8, 2 * 400 + 100 * 10),
    # courtyard: bottom and top with a hole, four outer and four inner sides; 2 * 1200 + 240 * 10
    ("courtyard", 10, 2 * 1200 + 240 * 10),
])
def test_extrude_of_a_concave_or_holed_lot_is_a_prism_of_mesh_faces(write, lot, faces, area):
    r = run(write, "Lot --> extrude(10)\n", [LOT_ZOO[lot]])
    assert len(r["asset"]) == 0
    got = mesh_faces(r)
    assert len(got) == faces
    assert sum(face_area(f) for f in got) == pytest.approx(area, rel=1e-5)
    vertices = r["mesh"].vertices
    np.testing.assert_allclose(sorted(set(np.round(vertices[:, 1], 4))), [0, 10])
    outline = LOT_ZOO[lot][0]
    # world x = map x, world z = -map y
    assert vertices[:, 0].min() == pytest.approx(outline[:, 0].min())
    assert vertices[:, 2].min() == pytest.approx(-outline[:, 1].max())
    if lot == "courtyard":
        assert [len(f) for f in got].count(2) == 2  # bottom and top keep their hole


def test_negative_extrude_of_a_facade_goes_behind_the_face(write):
    r = run(write, "Lot --> extrude(5) comp(f){ front : Facade }\nFacade --> extrude(-0.5)\n", [rect(12, 8)])
    assert assets(r) == ["builtin:cube"] and names(r) == ["Facade"]
    x = r["xform"][0]
    # the front face is world z = 0 facing +z; the solid spans z in [-0.5, 0]
    np.testing.assert_allclose(np.abs(x[:, :3]).sum(axis=1), [12, 5, 0.5])
    corner = x[:, 3] + np.minimum(x[:, :3], 0).sum(axis=1)
    np.testing.assert_allclose(corner, [0, 0, -0.5], atol=1e-6)


def test_extrude_of_a_side_face_goes_outward(write):
    r = run(write, "Lot --> extrude(5) comp(f){ right : Side }\nSide --> extrude(2)\n", [rect(12, 8)])
    x = r["xform"][0]
    low = x[:, 3] + np.minimum(x[:, :3], 0).sum(axis=1)
    high = x[:, 3] + np.maximum(x[:, :3], 0).sum(axis=1)
    np.testing.assert_allclose([low, high], [[12, 0, -8], [14, 5, 0]], atol=1e-6)


def _signed_volume(faces):
    """Volume enclosed by mesh faces (positive when they wind outwards), each ring fanned from its first
    vertex."""
    total = 0.0
    for rings in faces:
        for ring in rings:
            total += sum(np.dot(ring[0], np.cross(ring[k], ring[k + 1])) for k in range(1, len(ring) - 1))
    return total / 6


@pytest.mark.parametrize("direction", ["world.y", "world.up", "world.up.flatTop", "face.normal",
                                       "vertex.normal"])
def test_extrude_of_a_footprint_along_any_direction_is_the_plain_extrude(write, direction):
    """The reference: on a horizontal footprint world.up and face.normal agree (and a flat face's vertex
    normals are its normal); so does flatTop, whose lowest and highest vertex are the same level."""
    lots = [rect(12, 8), LOT_ZOO["concave_L"]]
    r = run(write, f"Lot --> extrude({direction}, 10)\n", lots)
    assert r["bad"] == () and len(r["asset"]) == 1 and len(r["mesh"].lot) == 8
    same_records(r, run(write, "Lot --> extrude(10)\n", lots))


def test_extrude_along_the_normal_of_a_roof_plane_is_a_slanted_box(write):
    """face.normal and vertex.normal extrude a roof plane across itself: its scope's y is the plane's
    normal, the box as thick as the height."""
    grammar = "Lot --> roofGable(30) comp(f){{ aslant : Plane }}\nPlane --> extrude({}, 1)\n"
    r = run(write, grammar.format("vertex.normal"), [rect(12, 8)])
    same_records(r, run(write, grammar.format("face.normal"), [rect(12, 8)]))
    x = r["xform"].astype(float)
    np.testing.assert_allclose(np.linalg.norm(x[:, :, 1], axis=1), [1, 1])
    np.testing.assert_allclose(np.abs(x[:, 1, 1]), np.cos(np.radians(30)))


# a gable over 12 x 8 at 30 degrees: the ridge at 4 tan 30 above the eaves, each plane 12 x 4 in plan
RIDGE = 4 * np.tan(np.radians(30))


@pytest.mark.parametrize("direction, top, volume", [
    # every vertex 1 up: the prism over each plane's plan, 12 * 4 * 1
    ("world.up", RIDGE + 1, 2 * 48.0),
    # a flat top at the lowest vertex + 1, at least up to the ridge: the wedge between plane and ridge
    ("world.up.flatTop", RIDGE, 2 * 48.0 * RIDGE / 2),
])
def test_extrude_of_a_roof_plane_along_the_world_up_axis_is_a_mesh(write, direction, top, volume):
    """The reference's "extrusion along world axes": a slanted face extruded vertically, each vertex
    straight up (or to one flat top), closed by the face, its copy and a side per edge, all outward."""
    r = run(write, "Lot --> roofGable(30) comp(f){ aslant : Plane }\n"
                   f'Plane --> extrude({direction}, 1) report("sy", scope.sy) report("sx", scope.sx)\n',
            [rect(12, 8)])
    assert len(r["asset"]) == 0
    faces = mesh_faces(r)
    assert len(faces) == 2 * 6  # each plane: bottom, top, four sides
    vertices = r["mesh"].vertices
    assert vertices[:, 1].min() == pytest.approx(0, abs=1e-5)
    assert vertices[:, 1].max() == pytest.approx(top, abs=1e-5)
    assert _signed_volume(faces) == pytest.approx(volume, rel=1e-5)
    t = totals(r)
    # the scope is upright (y the world's up), fitted to the solid; x along the eaves
    assert (t["sy_sum"], t["sx_sum"]) == pytest.approx((2 * top, 24), abs=1e-5)


def test_extrude_world_up_flat_top_negative_and_a_face_looking_down(write):
    """A negative flatTop distance is measured from the highest vertex down (at least to the lowest);
    a face looking down extruded world.up rises above it, outward."""
    r = run(write, "Lot --> roofGable(30) comp(f){ aslant : Plane }\nPlane --> extrude(world.up.flatTop, -1)\n",
            [rect(12, 8)])
    vertices = r["mesh"].vertices
    assert (vertices[:, 1].min(), vertices[:, 1].max()) == pytest.approx((0, RIDGE), abs=1e-5)
    assert abs(_signed_volume(mesh_faces(r))) == pytest.approx(48 * RIDGE, rel=1e-5)
    r = run(write, "Lot --> extrude(5) comp(f){ bottom : Under }\nUnder --> extrude(world.up, 2)\n",
            [rect(12, 8)])
    faces = mesh_faces(r)
    vertices = r["mesh"].vertices
    assert (vertices[:, 1].min(), vertices[:, 1].max()) == pytest.approx((0, 2), abs=1e-5)
    assert _signed_volume(faces) == pytest.approx(12 * 8 * 2, rel=1e-5)


def test_extrude_along_world_up_in_a_batch_equals_each_lot_alone(write):
    grammar = ("Lot --> extrude(4) comp(f){ bottom : Under | top : Roof }\n"
               "Roof --> roofHip(25) comp(f){ aslant : Plane }\nPlane --> extrude(world.up.flatTop, 0.5)\n"
               "Under --> extrude(world.up, 1)\n")
    lots = [rect(12, 8), LOT_ZOO["concave_L"]]
    together = run(write, grammar, lots)
    alone = [run(write, grammar, [lot]) for lot in lots]
    assert together["bad"] == () and len(alone[0]["mesh"].lot) == 2 * 6  # the solid under, one plane
    assert len(together["mesh"].lot) == sum(len(a["mesh"].lot) for a in alone)
    offset = len(alone[0]["mesh"].vertices)
    np.testing.assert_array_equal(together["mesh"].vertices[:offset], alone[0]["mesh"].vertices)
    np.testing.assert_array_equal(together["mesh"].vertices[offset:], alone[1]["mesh"].vertices)


def test_translate_and_scale_with_relative_values(write):
    """s('0.5, '1, 2): half the width; t('0.25, 0, 1): a quarter of the current (scaled) width."""
    r = run(write, "Lot --> extrude(6) s('0.5, '1, 2) t('0.25, 0, 1) X\n", [rect(12, 8)])
    np.testing.assert_allclose(r["xform"][0], [[6, 0, 0, 1.5], [0, 6, 0, 0], [0, 0, 2, -7]])


def test_center_centres_on_the_rules_starting_scope(write):
    """center(x) in A centres on A's own scope (the split part from 0 to 4), not on the lot."""
    r = run(write, "Lot --> extrude(6) split(x){ 4 : A | ~1 : B }\nA --> s(1, 1, 1) center(x) X\n",
            [rect(12, 8)])
    np.testing.assert_allclose(r["xform"][rows(r, "X")][0, :, 3], [1.5, 0, -8])


def test_center_on_several_axes_and_inside_a_push(write):
    r = run(write, "Lot --> extrude(6) s(4, '1, 2) center(xz) X\n", [rect(12, 8)])
    np.testing.assert_allclose(r["xform"][0, :, 3], [4, 0, -5])
    # inside [ ], the scope pushed is the reference
    r = run(write, "Lot --> extrude(6) t(3, 0, 0) [ s(2, 2, 2) center(xyz) X ]\n", [rect(12, 8)])
    np.testing.assert_allclose(r["xform"][0, :, 3], [3 + 6 - 1, 2, -5])


def test_align_scope_to_axes_gives_a_world_aligned_scope_around_the_lot(write):
    lot = rotated_rectangle()
    r = run(write, 'Lot --> alignScopeToAxes() report("sx", scope.sx) report("sz", scope.sz)\n'
                   '    report("area", geometry.area) extrude(3) primitiveCube()\n', [lot])
    x = r["xform"][0].astype(float)
    # columns along the world axes: the scope is axis-aligned
    np.testing.assert_allclose(x[:, :3], np.diag(np.diag(x[:, :3])), atol=1e-5)
    ring = lot[0]
    world = np.c_[ring[:, 0], np.zeros(4), -ring[:, 1]]
    low, high = x[:, 3], x[:, 3] + np.diag(x[:, :3])
    assert (world >= low - 1e-4).all() and (world <= high + 1e-4).all()
    # the tightest such box
    np.testing.assert_allclose(low[[0, 2]], world.min(axis=0)[[0, 2]], atol=1e-4)
    np.testing.assert_allclose(high[[0, 2]], world.max(axis=0)[[0, 2]], atol=1e-4)
    t = totals(r)
    assert t["sx_sum"] == pytest.approx(np.ptp(ring[:, 0]))
    assert t["sz_sum"] == pytest.approx(np.ptp(ring[:, 1]))
    assert t["area_sum"] == pytest.approx(40)


def test_align_scope_to_axes_leaf_is_the_lot_polygon(write):
    lot = rotated_rectangle()
    r = run(write, "Lot --> alignScopeToAxes() X\n", [lot])
    assert len(r["asset"]) == 0
    (face,) = mesh_faces(r)
    assert face_area(face) == pytest.approx(40, rel=1e-5)
    np.testing.assert_allclose(face[0][:, 1], 0, atol=1e-6)
    np.testing.assert_allclose(face[0][:, [0, 2]], np.c_[lot[0][:, 0], -lot[0][:, 1]], atol=1e-4)


def test_rotate_scope_turns_the_axes_around_the_same_geometry(write):
    """rotateScope(0, 90, 0): x turns to world -z and z to world +x; the lot stays where it is."""
    r = run(write, 'Lot --> rotateScope(0, 90, 0) report("sx", scope.sx) report("sz", scope.sz) X\n',
            [rect(12, 8)])
    t = totals(r)
    assert (t["sx_sum"], t["sz_sum"]) == pytest.approx((8, 12))
    assert assets(r) == ["builtin:quad"]
    np.testing.assert_allclose(quad_normals(r), [[0, 1, 0]], atol=1e-6)
    x = r["xform"][0].astype(float)
    corners = x[:, 3] + np.array([[0, 0], [1, 0], [0, 1], [1, 1]]) @ x[:, :2].T
    np.testing.assert_allclose(sorted(map(tuple, np.round(corners, 5))),
                               [(0, 0, -8), (0, 0, 0), (12, 0, -8), (12, 0, 0)], atol=1e-5)
    r = run(write, "Lot --> rotateScope(0, 90, 0) extrude(2) X\n", [rect(12, 8)])
    np.testing.assert_allclose(r["xform"][0], [[0, 0, 12, 0], [0, 2, 0, 0], [-8, 0, 0, 0]], atol=1e-6)


def test_negative_size_lot_is_reported_and_skipped(write):
    r = paper(write, 'lot ~> S(Scope.sx - 11, 1, 1r) I("cube")\n', [rect(12, 5), rect(10, 5), rect(20, 5)])
    assert list(np.unique(r["lot"])) == [0, 2]
    on_threads = paper(write, 'lot ~> S(Scope.sx - 11, 1, 1r) I("cube")\n', [rect(12, 5), rect(10, 5), rect(20, 5)],
                     chunk_size=1, workers=2)
    same_records(r, on_threads)
    assert on_threads["bad"] == r["bad"]
    assert len(r["bad"]) == 1 and r["bad"][0].index == 1
    assert "negative or NaN size" in r["bad"][0].reason and "g.cga:1" in r["bad"][0].reason

