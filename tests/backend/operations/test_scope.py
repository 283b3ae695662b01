"""backend/operations/scope.py in derivations: ``T S R`` and ``t s r``, ``r(scopeCenter, ...)``, ``translate``
and ``rotate`` in coordinate systems, ``center``, ``extrude``, ``alignScopeToAxes`` and ``rotateScope``, and
sizes that fail their lot."""

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


def test_translate_and_scale_with_relative_values(write):
    """s('0.5, '1, 2): half the width; t('0.25, 0, 1): a quarter of the current (scaled) width."""
    r = run(write, "Lot --> extrude(6) s('0.5, '1, 2) t('0.25, 0, 1) X\n", [rect(12, 8)])
    np.testing.assert_allclose(r["xform"][0], [[6, 0, 0, 1.5], [0, 6, 0, 0], [0, 0, 2, -7]])



def _centres(r):
    """The centre of each instance's scope box, (n, 3)."""
    x = r["xform"].astype(float)
    return x[:, :, 3] + x[:, :, :3].sum(axis=2) / 2


def test_r_around_the_scope_centre_keeps_each_slice_centre(write):
    """The reference's example: slices of a mass turned about their own centres, each by its own angle."""
    r = run(write, "Lot --> extrude(6) split(y){ 2 : r(scopeCenter, 0, scope.ty * 15, 0) X }*\n", [rect(12, 8)])
    np.testing.assert_allclose(_centres(r), [[6, 1, -4], [6, 3, -4], [6, 5, -4]], atol=1e-9)
    turns = np.radians([0, 30, 60])
    x_axes = r["xform"][:, :, 0].astype(float) / 12
    np.testing.assert_allclose(x_axes, np.c_[np.cos(turns), np.zeros(3), -np.sin(turns)], atol=1e-9)
    np.testing.assert_allclose(r["xform"][:, :, 1], [[0, 2, 0]] * 3, atol=1e-9)


def test_r_around_the_scope_origin_is_r(write):
    text = "Lot --> extrude(6) split(y){{ 2 : r({}0, scope.ty * 15, 10) X }}*\n"
    same_records(run(write, text.format(""), [rotated_rectangle()]),
                 run(write, text.format("scopeOrigin, "), [rotated_rectangle()]))


def test_translate_in_each_coordinate_system(write):
    """rel adds the vector along the system's axes; abs puts the scope origin at the position."""
    lot = [rotated_rectangle()]
    base = run(write, "Lot --> extrude(3) X\n", lot)["xform"][0].astype(float)

    def moved(op):
        x = run(write, f"Lot --> extrude(3) {op} X\n", lot)["xform"][0].astype(float)
        np.testing.assert_allclose(x[:, :3], base[:, :3], atol=1e-9)  # the axes and sizes stay
        return x[:, 3]

    np.testing.assert_allclose(moved("translate(rel, world, 2, 0, 0)"), base[:, 3] + [2, 0, 0], atol=1e-9)
    # the object system is the lot's scope: x along its first edge, turned 30 degrees on the map
    along = [np.cos(np.radians(30)), 0, -np.sin(np.radians(30))]
    np.testing.assert_allclose(moved("translate(rel, object, 2, 0, 0)"), base[:, 3] + np.multiply(2, along),
                               atol=1e-9)
    np.testing.assert_allclose(moved("translate(abs, world, 1, 2, 3)"), [1, 2, 3], atol=1e-9)
    np.testing.assert_allclose(moved("translate(rel, scope, 1, 2, 3)"), moved("t(1, 2, 3)"), atol=1e-9)
    np.testing.assert_allclose(moved("translate(abs, scope, 1, 2, 3)"), moved("t(1, 2, 3)"), atol=1e-9)
    r = run(write, 'Lot --> t(4, 1, 2) translate(abs, pivot, 1, 2, 3) report("tx", scope.tx) '
                   'report("ty", scope.ty) report("tz", scope.tz) X\n', lot)
    t = totals(r)
    assert (t["tx_sum"], t["ty_sum"], t["tz_sum"]) == pytest.approx((1, 2, 3))


def test_rotate_sets_or_adds_the_scopes_angles_in_a_system(write):
    """The reference's example: rotate(abs, world, 0, 90, 0) turns the scope to world angles (x to world
    -z, z to world +x) around its origin, whatever the lot's own turn."""
    lot = [rotated_rectangle()]
    head = "Lot --> extrude(10) t('0.2, 0, '0.3) s('0.5, '1, '0.5) "
    base = run(write, head + "X\n", lot)["xform"][0].astype(float)
    x = run(write, head + "rotate(abs, world, 0, 90, 0) X\n", lot)["xform"][0].astype(float)
    np.testing.assert_allclose(x[:, 3], base[:, 3], atol=1e-9)
    np.testing.assert_allclose(x[:, :3], [[0, 0, 2], [0, 10, 0], [-5, 0, 0]], atol=1e-9)
    r = run(write, 'Lot --> rotate(abs, object, 10, 20, 30) report("rx", scope.rx) report("ry", scope.ry) '
                   'report("rz", scope.rz) X\n', lot)
    t = totals(r)
    assert (t["rx_sum"], t["ry_sum"], t["rz_sum"]) == pytest.approx((10, 20, 30))

    def xform(ops):
        return run(write, f"Lot --> extrude(4) {ops} X\n", lot)["xform"][0].astype(float)

    # rel adds the angles: twice 30 about the pivot's y is 60
    np.testing.assert_allclose(xform("rotate(rel, pivot, 0, 30, 0) rotate(rel, pivot, 0, 30, 0)"),
                               xform("rotate(abs, pivot, 0, 60, 0)"), atol=1e-9)
    np.testing.assert_allclose(xform("rotate(rel, world, 0, 90, 0)"), xform("r(0, 90, 0)"), atol=1e-9)
    np.testing.assert_allclose(xform("rotate(rel, scope, 0, 0, 45)"), xform("r(0, 0, 45)"), atol=1e-9)



def test_set_of_a_scope_field_keeps_the_other_two(write):
    report = "".join(f'report("{f}", scope.{f}) ' for f in ("tx", "ty", "tz", "sx", "sy", "sz", "rx", "ry", "rz"))
    head = "Lot --> extrude(4) t(1, 2, 3) r(0, 30, 0) "
    t = totals(run(write, head + report + "X\n", [rotated_rectangle()]))
    for field, value in (("tx", 7), ("ty", -1), ("tz", 0.5), ("sx", 3), ("sy", 9), ("sz", 2),
                         ("rx", 20), ("ry", -45), ("rz", 10)):
        got = totals(run(write, f"{head}set(scope.{field}, {value}) {report}X\n", [rotated_rectangle()]))
        want = {key: (value if key == f"{field}_sum" else t[key]) for key in t if key.endswith("_sum")}
        assert {key: got[key] for key in want} == pytest.approx(want, abs=1e-9), field

def test_transforms_move_every_kind_of_shape(write):
    """A roof, a concave prism (meshes), a lot polygon and an inserted asset move and turn with their
    scope: r(scopeCenter, 0, 90, 0) swaps the footprint's sides around its centre."""
    for body in ("roofHip(30)", "extrude(3)", "", 'i("builtin:cube")'):
        lot = LOT_ZOO["concave_L"] if body == "extrude(3)" else rect(10, 6)
        text = f"Lot --> {body} translate(rel, world, 0, 5, 0) r(scopeCenter, 0, 90, 0) X\n"
        r = run(write, text, [lot])
        if len(r["asset"]):
            x = r["xform"].astype(float)
            corners = x[:, :, 3][:, None] + np.array(np.meshgrid([0, 1], [0, 1], [0, 1])).reshape(3, -1).T @ \
                np.swapaxes(x[:, :, :3], 1, 2)
            points = corners.reshape(-1, 3)
        else:
            points = r["mesh"].vertices.astype(float)
        outline = lot[0]
        width, depth = np.ptp(outline[:, 0]), np.ptp(outline[:, 1])
        centre = (outline[:, 0].min() + width / 2, -(outline[:, 1].min() + depth / 2))
        np.testing.assert_allclose(points[:, 1].min(), 5, atol=1e-6)
        np.testing.assert_allclose([np.ptp(points[:, 0]), np.ptp(points[:, 2])], [depth, width], atol=1e-6)
        np.testing.assert_allclose([points[:, 0].min() + depth / 2, points[:, 2].min() + width / 2], centre,
                                   atol=1e-6)


def test_transforms_of_a_batch_equal_each_shape_alone(write):
    """Angles and vectors that differ per shape: a chunk of lots derives each lot as it would alone."""
    text = ("Lot --> extrude(scope.sx / 4) r(scopeCenter, scope.sx, 10, scope.sz) translate(rel, object, scope.sz, 1, 0)"
            " rotate(rel, pivot, 0, scope.sx * 3, 5) translate(abs, world, scope.sx, 0, 2)"
            " rotate(abs, world, 0, scope.sz, 0) X\n")
    lots = [rect(12, 8), rotated_rectangle(), LOT_ZOO["concave_L"], rotated_rectangle(70, 6, 9)]
    batch = run(write, text, lots)
    faces = mesh_faces(batch)
    for k, lot in enumerate(lots):
        alone = run(write, text, [lot])
        np.testing.assert_allclose(batch["xform"][batch["lot"] == k], alone["xform"], atol=1e-9)
        mine = [f for f, owner in zip(faces, batch["mesh"].lot) if owner == k]
        assert len(mine) == len(mesh_faces(alone))
        for got, want in zip(mine, mesh_faces(alone)):
            np.testing.assert_allclose(np.concatenate(got), np.concatenate(want), atol=1e-9)

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

