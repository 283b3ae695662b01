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

from grammarc.constants import Limits


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


def test_r_adds_its_angles_to_a_scope_aligned_with_its_pivot(write):
    """CityEngine's ``r`` adds its angles to ``scope.r`` (about x, then y, then z of the pivot): on a lot,
    whose scope is its pivot, r(10, 20, 30) reads back as (10, 20, 30) and is rotate(rel, pivot, ...);
    turning about the scope's own turning axes instead would read (10.6, 19.7, 3.6) for r(10, 20, 0)."""
    lot = [rotated_rectangle()]
    t = totals(run(write, 'Lot --> r(10, 20, 30) report("rx", scope.rx) report("ry", scope.ry) '
                          'report("rz", scope.rz) X\n', lot))
    assert (t["rx_sum"], t["ry_sum"], t["rz_sum"]) == pytest.approx((10, 20, 30))

    def xform(ops):
        return run(write, f"Lot --> extrude(4) {ops} X\n", lot)["xform"][0].astype(float)

    np.testing.assert_allclose(xform("r(10, 20, 0)"), xform("rotate(rel, pivot, 10, 20, 0)"), atol=1e-9)
    # in xyz order about the axes as they were: the z turn comes last, about the old z
    np.testing.assert_allclose(xform("r(10, 20, 30)"), xform("r(0, 0, 30) r(0, 20, 0) r(10, 0, 0)"), atol=1e-9)



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


def test_a_rotation_by_an_angle_that_is_not_finite_fails_its_lot(write):
    """``h / w`` of two zero attributes is NaN: the lot that gives it fails by name, the other turns."""
    r = run(write, "attr h = 0\nattr w = 0\nLot --> extrude(3) r(0, h / w, 0) X\n", [rect(12, 8), rect(12, 8)],
            lot_attrs={"w": [np.nan, 2.0]})
    (bad,) = r["bad"]
    assert bad.index == 0 and bad.reason.startswith("a rotation by an angle that is not finite in rule `Lot`")
    assert len(r["asset"]) == 1 and np.isfinite(r["xform"]).all()


def test_mirror_scope_reverses_two_axes_around_the_same_geometry(write):
    """mirrorScope(true, false, true): the 12 x 3 x 8 box keeps its place and sizes, its scope starts at the
    far corner with x and z reversed (a half turn about y); one axis alone would be left-handed and fails
    its lot by name."""
    r = run(write, "Lot --> extrude(3) mirrorScope(true, false, true) X\n", [rect(12, 8)])
    np.testing.assert_allclose(r["xform"][0], [[-12, 0, 0, 12], [0, 3, 0, 0], [0, 0, -8, 0]], atol=1e-6)
    r = run(write, "Lot --> extrude(3) mirrorScope(false, true, false) X\n", [rect(12, 8)])
    (bad,) = r["bad"]
    assert "`mirrorScope` of one or three axes is not supported yet" in bad.reason


@pytest.mark.parametrize("ops, xform", [
    # corner 2, the far end of x and z at the bottom: x and z reversed, as a half turn about y
    ("setPivot(xyz, 2)", [[-12, 0, 0, 12], [0, 3, 0, 0], [0, 0, -8, 0]]),
    # corner 0 of yzx: x along the old y, y along the old z, z along the old x
    ("setPivot(yzx, 0)", [[0, 0, 12, 0], [3, 0, 0, 0], [0, 8, 0, -8]]),
    ("setPivot(zxy, 0)", [[0, 12, 0, 0], [0, 0, 3, 0], [8, 0, 0, -8]]),
    # corner 6, the far top corner: y down, x along the old -z, z along the old -x
    ("setPivot(xyz, 6)", [[0, 0, -12, 12], [0, -3, 0, 3], [-8, 0, 0, 0]]),
    # a split then runs from the pivot's corner: the first 2 m at the far end of x
    ("setPivot(xyz, 2) split(x){ 2 : X | ~1 : NIL }", [[-2, 0, 0, 12], [0, 3, 0, 0], [0, 0, -8, 0]]),
])
def test_set_pivot_gives_the_scope_the_pivots_corner_and_axes(write, ops, xform):
    """The reference: the pivot at the chosen corner of the 12 x 3 x 8 box, its axes the scope's renamed by
    the axis map and pointing inside; the scope the same box in those axes, the geometry where it was."""
    r = run(write, f"Lot --> extrude(3) {ops} X\n", [rect(12, 8)])
    np.testing.assert_allclose(r["xform"][0], xform, atol=1e-6)


@pytest.mark.parametrize("lot", ["concave_L", "courtyard"])
def test_set_pivot_keeps_a_polygon_or_a_mesh_where_it_was(write, lot):
    """A concave prism (mesh faces) and a lot's polygon keep their faces; only the scope turns."""
    for body in ("extrude(2)", ""):
        plain = run(write, f"Lot --> {body} X\n", [LOT_ZOO[lot]])
        pivoted = run(write, f"Lot --> {body} setPivot(zxy, 5) X\n", [LOT_ZOO[lot]])
        assert len(pivoted["bad"]) == 0
        before = sorted(round(face_area(f), 6) for f in mesh_faces(plain))
        assert sorted(round(face_area(f), 6) for f in mesh_faces(pivoted)) == before
        np.testing.assert_allclose(np.sort(pivoted["mesh"].vertices, axis=0), np.sort(plain["mesh"].vertices, axis=0),
                                   atol=1e-5)


def test_mirror_of_a_roof_flips_its_mesh_and_keeps_its_faces_outward(write):
    """A shed roof rising along scope z, mirrored along z, rises the other way: the same volume, its
    highest vertices at the other edge, and every face still facing out (its signed volume positive)."""
    text = 'Lot --> roofShed(20) {}report("v", geometry.volume) X\n'
    plain, mirrored = (run(write, text.format(m), [rect(12, 8)]) for m in ("", "mirror(false, false, true) "))
    assert totals(plain)["v_sum"] == pytest.approx(totals(mirrored)["v_sum"])

    def high_edge(r):
        verts = np.concatenate([ring for face in mesh_faces(r) for ring in face])
        return np.unique(np.round(verts[verts[:, 1] > verts[:, 1].max() - 1e-6][:, 2], 6))

    def signed_volume(r):
        total = 0.0
        for face in mesh_faces(r):
            ring = face[0]
            for k in range(1, len(ring) - 1):
                total += np.dot(ring[0], np.cross(ring[k], ring[k + 1])) / 6
        return total

    assert not np.array_equal(high_edge(plain), high_edge(mirrored))
    assert signed_volume(mirrored) == pytest.approx(signed_volume(plain)) and signed_volume(plain) > 0


@pytest.mark.parametrize(("given", "op"), [("", "rotateScope(0, 90, 0)"), ("", "mirror(true, false, true)"),
                                           ("s('0.5, '1, '0.5) ", "center(xz)"), ("", "mirrorScope(true, true, false)"),
                                           ("", "s(-scope.sx, scope.sy, -scope.sz)")])
def test_scope_operations_take_every_shape_kind(write, given, op):
    """rotateScope, mirror, center, mirrorScope and negative sizes on a rectangle, a concave polygon, a box,
    a prism, a roof, an inserted asset, a face, an edge and a roof face: no lot fails, and the area
    stays."""
    kinds = ["", "extrude(3) ", "roofHip(30) ", 'i("builtin:cube") ', "extrude(3) comp(f){ front : F }\nF --> ",
             "extrude(3) comp(e){ all : F }\nF --> ", "roofHip(30) comp(f){ all : F }\nF --> "]
    for lot in (rect(12, 8), LOT_ZOO["concave_L"]):
        for kind in kinds:
            text = "Lot --> " + kind + given + '@ report("a", geometry.area) X.\n'
            before, after = (run(write, text.replace("@", o), [lot]) for o in ("", op))
            assert not after["bad"], (kind, after["bad"])
            assert totals(after).get("a_sum", 0.0) == pytest.approx(totals(before).get("a_sum", 0.0)), kind


def test_negative_size_lot_is_reported_and_skipped(write):
    r = paper(write, 'lot ~> S(Scope.sx - 11, 1, 1r) I("cube")\n', [rect(12, 5), rect(10, 5), rect(20, 5)])
    assert list(np.unique(r["lot"])) == [0, 2]
    on_threads = paper(write, 'lot ~> S(Scope.sx - 11, 1, 1r) I("cube")\n', [rect(12, 5), rect(10, 5), rect(20, 5)],
                     chunk_size=1, workers=2)
    same_records(r, on_threads)
    assert on_threads["bad"] == r["bad"]
    assert len(r["bad"]) == 1 and r["bad"][0].index == 1
    assert "negative or NaN size" in r["bad"][0].reason and "g.cga:1" in r["bad"][0].reason



def test_a_nan_size_beside_a_negative_one_fails_the_lot(write):
    """CityEngine's ``s`` mirrors along an axis given a negative size; a NaN size on another axis (``h / w``
    of two zero attributes) fails the lot by name, as the paper's ``S`` does, and is not mirrored (GEOS
    refused the mirrored face's NaN ring and the build stopped: the build fuzz, seed 94)."""
    text = "attr h = 0\nattr w = 0\nLot --> s(1, -1, h / w) X.\n"
    r = run(write, text, [rect(10, 5), rect(10, 5)], lot_attrs={"w": np.array([0.0, 1.0])})
    assert [(b.index, b.reason.split(" in rule")[0]) for b in r["bad"]] == [(0, "`s` gives a NaN size (1, -1, nan)")]


def test_negative_size_mirrors_the_shape_and_inverts_its_normals(write):
    """CityEngine's ``s`` mirrors along an axis given a negative size (the reference: "the normals are
    inverted"). complexpatterns' ``Balcony`` on a tiny lot, a parallelogram: its box narrower than its two
    border walls, ``s(scope.sx - 1.312, ..)`` is negative. PRT centres it and puts the front railing at the
    lot's far edge, 3.344 m from its first edge (the mirrored box's back face, facing in), its ends where
    PRT's railing ends (its OBJ, to the millimetre), and the side railings from 0.656 to 3.344 m."""
    lot = [np.array([[1.361, -1.068], [1.711, -0.252], [-1.361, 1.068], [-1.711, 0.252]])]
    text = ("Lot --> extrude(0.7) s(scope.sx - 1.312, '1, scope.sz - 0.656) center(x)\n"
            "    comp(f){ front : Front | left : Side | right : Side }\n")
    r = run(write, text, [lot])
    assert not r["bad"]
    # world x = map x, world z = -map y: the first edge's start, and the unit vector across the lot
    first, depth = np.array([1.361, 0, 1.068]), np.array([-0.816, 0, -0.35]) / np.hypot(0.816, 0.35)
    names_of = [str(r["symbols"][s]) for s in r["mesh"].symbol]
    assert sorted(names_of) == ["Front", "Side", "Side"]
    for name, (ring, *_) in zip(names_of, mesh_faces(r), strict=True):
        along = (ring - first) @ depth
        if name == "Front":
            ends = ring[ring[:, 1] < 0.35][:, [0, 2]]
            np.testing.assert_allclose(ends[np.argsort(ends[:, 0])], [[-1.620, -0.465], [-1.454, -0.852]],
                                       atol=2e-3)
            np.testing.assert_allclose(along, 3.344, atol=1e-3)
            normal = np.cross(ring[1] - ring[0], ring[2] - ring[1])
            assert normal @ depth < 0  # it faces into the box, towards the first edge
        else:
            assert (along.min(), along.max()) == pytest.approx((0.656, 3.344), abs=1e-3)


def _cube(r):
    """The xform (3, 4) of each cube record, as floats."""
    return r["xform"][np.array(assets(r)) == "builtin:cube"].astype(float)


def test_align_to_geometry_side_face_of_a_box(write):
    """A box's face 1 is its first side (the lot's first edge, world z = 0, facing +z): yUp puts y along
    that normal and x along its first edge, so z points down; zUp puts z along it and y up. The box stays a
    box (quarter turns), in the same place."""
    text = "Lot --> extrude(4) alignScopeToGeometry({}, 1, 0) i(\"builtin:cube\")\n"
    np.testing.assert_allclose(_cube(run(write, text.format("yUp"), [rect(12, 8)]))[0],
                               [[12, 0, 0, 0], [0, 0, -4, 4], [0, 8, 0, -8]], atol=1e-9)
    np.testing.assert_allclose(_cube(run(write, text.format("zUp"), [rect(12, 8)]))[0],
                               [[12, 0, 0, 0], [0, 4, 0, 0], [0, 0, 8, -8]], atol=1e-9)


def test_align_to_geometry_of_a_rotated_lot_by_edge_index_and_longest(write):
    """The 10 x 4 lot turned by 30 degrees: edge 1 is a short side, ``longest`` the first long one."""
    lot = rotated_rectangle()
    for edge, size in (("1", (4, 10)), ("longest", (10, 4)), ("-1", (4, 10))):
        r = run(write, f'Lot --> alignScopeToGeometry(yUp, 0, {edge}) report("sx", scope.sx) '
                       'report("sy", scope.sy) report("sz", scope.sz) X\n', [lot])
        t = totals(r)
        assert (t["sx_sum"], t["sy_sum"], t["sz_sum"]) == pytest.approx((*size[:1], 0, size[1]))
        # a rectangle filling its new scope: a quad on the lot's corners
        assert assets(r) == ["builtin:quad"]
        x = r["xform"][0].astype(float)
        corners = [x[:, 3] + a * x[:, 0] + c * x[:, 2] for a in (0, 1) for c in (0, 1)]
        world = np.c_[lot[0][:, 0], np.zeros(4), -lot[0][:, 1]]
        assert max(np.linalg.norm(world - p, axis=1).min() for p in corners) < 1e-4


def test_align_to_geometry_auto_takes_the_largest_faces_longest_edge(write):
    """Older rule files' ``alignScopeToGeometry(yUp, auto)``: a 4 x 10 lot whose first edge is a short
    side gets its scope x along a long side, as ``largest, longest`` gives it; a box its y across its
    largest face."""
    for body, lot, size in (("", rect(4, 10), (10, 0, 4)), ("extrude(2) ", rect(4, 10), (10, 2, 4))):
        r = run(write, f'Lot --> {body}alignScopeToGeometry(yUp, auto) report("sx", scope.sx) '
                       'report("sy", scope.sy) report("sz", scope.sz) X\n', [lot])
        t = totals(r)
        assert (t["sx_sum"], t["sy_sum"], t["sz_sum"]) == pytest.approx(size)


def test_align_to_geometry_of_an_l_prism_lowest_face_longest_edge(write):
    """The L's lowest face is its bottom (its sides reach as low, their middles do not); the bottom's ring
    runs backwards, so its longest edge runs along world -x; y is the bottom's normal (down). The prism,
    turned out of its plane, becomes a mesh where it was."""
    lot = LOT_ZOO["concave_L"]
    text = ('Lot --> extrude(10) {}report("sx", scope.sx) report("sy", scope.sy) report("sz", scope.sz) '
            '[ s(\'1, 0.5, \'1) i("builtin:cube") C ] X\n')
    r = run(write, text.format("alignScopeToGeometry(yUp, world.lowest, longest) "), [lot])
    t = totals(r)
    assert (t["sx_sum"], t["sy_sum"], t["sz_sum"]) == pytest.approx((30, 10, 20))
    axes = _cube(r)[0][:, :3] / [30, 0.5, 20]
    np.testing.assert_allclose(axes, [[-1, 0, 0], [0, -1, 0], [0, 0, 1]], atol=1e-9)
    before = run(write, text.format(""), [lot])
    got, want = mesh_faces(r), mesh_faces(before)
    assert sum(face_area(f) for f in got) == pytest.approx(sum(face_area(f) for f in want))
    np.testing.assert_allclose(np.concatenate([f[0] for f in got]).min(axis=0),
                               np.concatenate([f[0] for f in want]).min(axis=0), atol=1e-5)
    np.testing.assert_allclose(np.concatenate([f[0] for f in got]).max(axis=0),
                               np.concatenate([f[0] for f in want]).max(axis=0), atol=1e-5)


@pytest.mark.parametrize("roof, up", [
    # a hip roof at 30 degrees: its base (96) is larger than a slope (36.9), and faces down
    ("roofHip(30)", (0, -1, 0)),
    # a gable roof at 70 degrees: a slope (12 x 4 / cos 70 = 140) is larger than the base
    ("roofGable(70)", (0, np.cos(np.radians(70)), np.sin(np.radians(70)))),
])
def test_align_to_geometry_largest_face_of_a_roof(write, roof, up):
    """On 12 x 8, x along the largest face's longest edge (12 long), y its normal; the whole roof fits the
    scope along x."""
    r = run(write, f'Lot --> {roof} alignScopeToGeometry(yUp, largest, longest) report("sx", scope.sx) '
                   "[ s('1, 1, '1) i(\"builtin:cube\") C ]\n", [rect(12, 8)])
    assert totals(r)["sx_sum"] == pytest.approx(12)
    x, y = (_cube(r)[0][:, k] for k in (0, 1))
    np.testing.assert_allclose(np.abs(x / np.linalg.norm(x)), [1, 0, 0], atol=1e-9)
    y = y / np.linalg.norm(y)
    np.testing.assert_allclose([y[0], y[1], abs(y[2])], up, atol=1e-9)


def test_align_to_geometry_any_lowest_puts_y_up_the_slope_of_each_roof_face(write):
    """The reference's use: each face of a roof, zUp along its normal and x along its lowest edge (the
    eave), has its y going up the slope."""
    r = run(write, "Lot --> roofHip(30) comp(f){ all : F }\n"
                   "F --> alignScopeToGeometry(zUp, any, world.lowest) i(\"builtin:cube\")\n", [rect(12, 8)])
    slopes = r["xform"][quad_normals(r)[:, 1] > 0].astype(float)  # not the base
    assert len(slopes) == 4
    np.testing.assert_allclose(slopes[:, 1, 0], 0, atol=1e-9)  # x horizontal
    assert (slopes[:, 1, 1] > 0).all()  # y up the slope
    np.testing.assert_allclose(sorted(np.linalg.norm(slopes[:, :, 0], axis=1)), [8, 8, 12, 12], atol=1e-9)


def test_align_to_geometry_in_a_batch_equals_each_lot_alone(write):
    """Edge indices and selectors per shape: a batch gives each lot what it gets alone."""
    lots = [rect(12, 8), rotated_rectangle(), LOT_ZOO["concave_L"], LOT_ZOO["courtyard"]]
    for align in ("largest, longest", "0, floor(scope.sx) % 5", "world.lowest, world.lowest", "any, longest",
                  "-2, 1"):
        text = f"Lot --> extrude(5) alignScopeToGeometry(zUp, {align}) [ i(\"builtin:cube\") C ] X\n"
        batch = run(write, text, lots)
        for k, lot in enumerate(lots):
            alone = run(write, text, [lot])
            np.testing.assert_array_equal(batch["xform"][batch["lot"] == k], alone["xform"])
            mesh, one = batch["mesh"], alone["mesh"]
            np.testing.assert_array_equal(mesh.vertices[np.repeat(mesh.lot, np.diff(
                mesh.ring_offsets[mesh.face_offsets]))== k], one.vertices)


@pytest.mark.parametrize("axes, sizes", [("xz", (10, 0, 4)), ("zx", (4, 0, 10)), ("xy", (4, 0, 10))])
def test_align_scope_to_geometry_bbox_puts_the_first_axis_along_the_longer_side(write, axes, sizes):
    """The reference's example: a lot whose scope runs along its first, short edge; ``xz`` turns x (and z)
    about y onto the smallest rectangle around it, x along its longer side; ``zx`` puts z there, as it was.
    ``xy`` turns about z, across which the lot is flat: it keeps its scope."""
    lot = [rotated_rectangle(30, 4, 10)[0]]
    text = (f'Lot --> alignScopeToGeometryBBox({axes}) report("x", scope.sx) report("y", scope.sy) '
            'report("z", scope.sz) report("a", geometry.area) X.\n')
    t = totals(run(write, text, [lot]))
    assert (t["x_sum"], t["y_sum"], t["z_sum"], t["a_sum"]) == pytest.approx((*sizes, 40))


def test_align_scope_to_geometry_bbox_of_a_solid_and_a_batch(write):
    """A box turned by a quarter turn stays a box; an L's rectangle is its own scope; each lot of a batch
    gets what it gets alone."""
    text = "Lot --> extrude(5) alignScopeToGeometryBBox(xz) X.\n"
    r = run(write, text, [rect(10, 30)])
    assert len(r["xform"]) == 1 and not len(r["mesh"].face_offsets) - 1
    np.testing.assert_allclose(sorted(np.linalg.norm(r["xform"][0, :, :3], axis=0)), [5, 10, 30])
    lots = [rect(10, 30), rotated_rectangle(30, 4, 10), LOT_ZOO["concave_L"], LOT_ZOO["courtyard"]]
    text = "Lot --> alignScopeToGeometryBBox(xz) extrude(2) comp(f){ front : F. }\n"
    batch = run(write, text, lots)
    for k, lot in enumerate(lots):
        alone = run(write, text, [lot])
        np.testing.assert_array_equal(batch["xform"][batch["lot"] == k], alone["xform"])


@pytest.mark.parametrize("axis, k", [("x", 0), ("world.z", 2), ("y", 1)])
def test_align_scope_to_one_world_axis(write, axis, k):
    """alignScopeToAxes(x|y|z) of a turned box: that scope axis is the world's, the next one the old one
    projected across it (z for x, x for y and z), and the box's corners stay inside the new scope."""
    text = "Lot --> extrude(8) t(5, 0, 4) s(8, 24, 8) r(10, 20, 30) {}i(\"builtin:cube\")\n"
    before = _cube(run(write, text.format(""), [rect(12, 8)]))[0]
    after = _cube(run(write, text.format(f"alignScopeToAxes({axis}) "), [rect(12, 8)]))[0]
    axes = after[:, :3] / np.linalg.norm(after[:, :3], axis=0)
    np.testing.assert_allclose(axes[:, k], np.eye(3)[k], atol=1e-12)
    second = {0: 2, 1: 0, 2: 0}[k]
    old = before[:, second] / np.linalg.norm(before[:, second])
    projected = old - old[k] * np.eye(3)[k]
    np.testing.assert_allclose(axes[:, second], projected / np.linalg.norm(projected), atol=1e-9)
    corners = before[:, 3] + np.array([[i, j, m] for i in (0, 1) for j in (0, 1) for m in (0, 1)]) @ before[:, :3].T
    local = np.linalg.solve(after[:, :3], (corners - after[:, 3]).T).T
    assert local.min() == pytest.approx(0, abs=1e-6) and local.max() == pytest.approx(1, abs=1e-6)


def test_align_to_geometry_without_an_edge_keeps_the_scope(write):
    """A shape with no face to align to (a scope box shrunk to a line) keeps its scope, next to one that
    turns."""
    text = ("Lot --> extrude(4) comp(f){ front : F }\n"
            "F --> [ s(0, '1, 0) E ] G\n"
            "E --> alignScopeToGeometry(zUp, largest, longest) report(\"sy\", scope.sy) report(\"ty\", scope.ty)\n"
            "G --> alignScopeToGeometry(yUp, 0, 0) i(\"builtin:cube\")\n")
    r = run(write, text, [rect(12, 8)])
    assert (totals(r)["sy_sum"], totals(r)["ty_sum"]) == pytest.approx((4, 0))
    assert names(r) == ["G"]  # the face beside it turned and made its quad


#: Two 10 x 10 squares joined by a bridge 2 wide: an inset of 1.5 leaves two disjoint squares of 7 x 7.
DUMBBELL = [np.array([[0, 0], [10, 0], [10, 4], [14, 4], [14, 0], [24, 0], [24, 10], [14, 10], [14, 6],
                      [10, 6], [10, 10], [0, 10]], float)]


@pytest.mark.parametrize("height", [2.0, -2.0])
def test_extrude_of_an_offsets_pieces_is_a_box_per_piece(write, height):
    """Each face of the geometry extruded along its normal: two 7 x 7 x 2 boxes in one shape, whose
    scope is fitted to both."""
    r = run(write, f'Lot --> offset(-1.5, inside) extrude({height}) '
            'report("sx", scope.sx) report("sy", scope.sy) X.\n', [DUMBBELL])
    got = mesh_faces(r)
    level = [f for f in got if np.ptp(f[0][:, 1]) < 1e-9]
    assert len(level) == 4  # a bottom and a top per box; the walls keep the inset's vertices along edges
    assert sum(face_area(f) for f in level) == pytest.approx(4 * 49)
    assert sum(face_area(f) for f in got) == pytest.approx(2 * (2 * 49 + 4 * 7 * 2))
    y = r["mesh"].vertices[:, 1]
    assert (y.min(), y.max()) == (pytest.approx(min(height, 0)), pytest.approx(max(height, 0)))
    t = totals(r)
    assert (t["sx_sum"], t["sy_sum"]) == (pytest.approx(21), pytest.approx(2))


def test_extrude_of_convex_parts_has_no_lamina_faces(write):
    """CityEngine's extrude makes no inner faces: convexify's parts of the L extruded are the L's prism,
    its bottom and top in parts, the walls around the L."""
    r = run(write, 'Lot --> convexify extrude(3) comp(f){ side : report("w", geometry.area) W. | all : X. }\n',
            [LOT_ZOO["concave_L"]])
    got = mesh_faces(r)
    assert sum(face_area(f) for f in got) == pytest.approx(2 * 400 + 100 * 3)
    t = totals(r)
    assert (t["w_n"], t["w_sum"]) == (6, pytest.approx(100 * 3))


def test_extruding_a_face_beyond_any_geometry_fails_its_lot(write):
    """The build fuzz's `s(0, 1, -1e308) extrude(-1e308)`: GEOS, joining the face's outline, never
    returned (nor let a signal stop the build); the lot fails with the operation named (the scale, past any
    coordinate; the extrude, past 1e8 m), the other builds."""
    text = "attr h = 5\nLot --> s(0, 1, h) extrude(h) X.\n"
    out = run(write, text, [rect(10, 8), rect(6, 4), rect(6, 4)], lot_attrs={"h": np.array([-1e308, 3.0, -1e9])})
    assert [b.index for b in out["bad"]] == [0, 2]
    assert out["bad"][0].reason.startswith("a scope sized or placed beyond any coordinate (1e+308)")
    assert "`extrude` of a face whose size or height is beyond any geometry" in out["bad"][1].reason


def test_a_geometry_extruded_again_and_again_fails_its_lot_before_it_fills_the_memory(write):
    """As the build fuzz test found it: a mirrored box (a mesh) extruded, mirrored and extruded again grows
    sixfold a round (15 million vertices in eight; the test process ran out of its 2 GB). The vertices of
    a mesh's solids count toward --max-shapes before they are made: the lot fails, named, and the others
    derive."""
    text = "attr n = 0\nLot --> case n > 0 : s(-1, 2, 1) extrude(1) Lot\n    else : X.\n"
    r = run(write, text, [rect(5, 5)] * 2, lot_attrs={"n": np.array([1.0, 0.0])},
            limits=Limits(max_shapes=50_000))
    [bad] = r["bad"]
    assert bad.index == 0 and bad.reason.startswith("more than 50,000 shapes (")
    assert np.unique(r["lot"]).tolist() == [1]
