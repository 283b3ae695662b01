"""backend/operations/primitives.py in derivations: CityEngine's primitives with and without sizes, after
the examples of the reference (on a lot 20 x 10, whose scope origin is (0, 0, -10))."""

from __future__ import annotations

import numpy as np
import pytest
from derivations import assets, mesh_faces, names, rect, run, same_records


@pytest.mark.parametrize("call, asset, size", [
    ("primitiveCube(10, 15, 20)", "builtin:cube", [10, 15, 20]),
    ("primitiveCylinder(8, 10, 15)", "builtin:cylinder8", [20, 15, 20]),
    ("primitiveCone(8, 10, 15)", "builtin:cone8", [20, 15, 20]),
    ("primitiveSphere(8, 4, 10)", "builtin:sphere8x4", [20, 20, 20]),
])  # fmt: skip
def test_a_primitive_with_sizes_stands_in_the_xz_centre_of_the_scope(write, call, asset, size):
    r = run(write, f"Lot --> extrude(4) {call} X\n", [rect(20, 10)])
    assert r["bad"] == () and assets(r) == [asset] and names(r) == ["X"]
    sx, sy, sz = size
    np.testing.assert_allclose(r["xform"][0], [[sx, 0, 0, (20 - sx) / 2], [0, sy, 0, 0],
                                               [0, 0, sz, -10 + (10 - sz) / 2]])


@pytest.mark.parametrize("call, asset", [
    ("primitiveCube()", "builtin:cube"), ("primitiveCylinder()", "builtin:cylinder16"),
    ("primitiveCone()", "builtin:cone16"), ("primitiveSphere()", "builtin:sphere16x16"),
    ("primitiveCylinder(5)", "builtin:cylinder5"), ("primitiveSphere(6.4, 3)", "builtin:sphere6x3"),
])  # fmt: skip
def test_a_primitive_without_sizes_fills_the_scope(write, call, asset):
    r = run(write, f"Lot --> extrude(4) {call} X\n", [rect(20, 10)])
    assert r["bad"] == () and assets(r) == [asset]
    np.testing.assert_allclose(r["xform"][0], [[20, 0, 0, 0], [0, 4, 0, 0], [0, 0, 10, -10]])



@pytest.mark.parametrize("call, extents", [("primitiveQuad()", [20, 10]), ("primitiveQuad(10, 20)", [10, 20])])
def test_a_quad_fills_or_centres_in_the_plane_of_its_flat_axis(write, call, extents):
    """The reference's example: the scope turned so that its x is flat, the quad fills its y and z, or with
    a width and length is centred in them (a quad record's first two columns span the face)."""
    r = run(write, f"Lot --> rotateScope(0, 0, 90) {call} X\n", [rect(20, 10)])
    assert r["bad"] == () and assets(r) == ["builtin:quad"]
    x = r["xform"][0].astype(float)
    np.testing.assert_allclose(np.linalg.norm(x[:, :3], axis=0), [*extents, 0], atol=1e-6)
    np.testing.assert_allclose(x[:, 3] + (x[:, 0] + x[:, 1]) / 2, [10, 0, -5], atol=1e-6)  # its centre


def test_a_quad_of_a_volume_lies_on_its_floor(write):
    r = run(write, "Lot --> extrude(4) primitiveQuad(6, 2) X\n", [rect(20, 10)])
    assert assets(r) == ["builtin:quad"]
    x = r["xform"][0].astype(float)
    np.testing.assert_allclose(np.abs(x[:, :3]).sum(axis=1), [6, 0, 2], atol=1e-6)  # world x, y, z extents
    np.testing.assert_allclose(x[:, 3] + (x[:, 0] + x[:, 1]) / 2, [10, 0, -5], atol=1e-6)


def test_a_disk_is_a_polygon_that_later_operations_take(write):
    """primitiveDisk(6, 1): a hexagon 2 x 2 in the middle of the lot; extruded, it has 6 sides."""
    r = run(write, "Lot --> primitiveDisk(6, 1) X\n", [rect(20, 10)])
    (ring,) = mesh_faces(r)[0]
    assert len(ring) == 6
    np.testing.assert_allclose(ring.min(axis=0), [9, 0, -6])
    np.testing.assert_allclose(ring.max(axis=0), [11, 0, -4])
    r = run(write, "Lot --> primitiveDisk(6, 1) extrude(2) comp(f){ side : S | top : T }\n", [rect(20, 10)])
    assert names(r) == ["S"] * 6
    (top,) = mesh_faces(r)
    assert len(top[0]) == 6 and np.allclose(top[0][:, 1], 2)


def test_segments_may_be_an_attribute_a_lot_overrides_to_a_count_the_grammar_declares(write):
    text = "attr n = 8\nLot --> extrude(2) primitiveCylinder(n) X\n"
    r = run(write, text, [rect(20, 10)] * 2, lot_attrs={"n": [8, 5]})
    assert assets(r) == ["builtin:cylinder8"]
    assert len(r["bad"]) == 1 and "`primitiveCylinder` with 5 segments" in r["bad"][0].reason


def test_a_batch_of_lots_derives_as_each_lot_alone(write):
    text = ("Lot --> extrude(rand(2, 6)) split(x){ ~1 : primitiveCylinder(8, rand(1, 2), 3) A | "
            "~1 : primitiveDisk(5) extrude(1) B | ~1 : primitiveQuad(rand(1, 3), 2) C }\n")
    lots = [rect(20, 10), rect(12, 8), rect(9, 30)]
    together = run(write, text, lots)
    assert together["bad"] == () and names(together) == ["A", "C"] * 3
    assert len(mesh_faces(together)) == 3 * 7  # each extruded pentagon: 5 sides, top and bottom
    same_records(together, run(write, text, lots, chunk_size=1))
