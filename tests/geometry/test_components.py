"""Component splits (grammarc.geometry.components): frames of faces, edges and vertices of boxes, prisms
and flat faces, checked geometrically and against a plain-Python reference of the ring-edge frames."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from conftest import make_lots
from hypothesis import given, settings
from hypothesis import strategies as st

from grammarc.geometry.components import (
    BOTTOM_POLY,
    KIND_CODES,
    RECT,
    RECT_RINGS,
    SAME_POLY,
    TOP_POLY,
    components,
    rect_corners,
    rect_plane,
    rect_rings,
    reverse_rings,
)
from grammarc.geometry.footprint import footprint_polygons, lot_scopes

TOL = 1e-9
KINDS = ("faces", "sidefaces", "top", "bottom", "edges", "sideedges", "topedges", "bottomedges", "vertices")
UNIT_AXES = {0: (1, 2, 0), 1: (0, 2, 1), 2: (0, 1, 2)}  # plane -> (a, b, normal)



def run(kind, shapes):
    """components() of shapes given as [(rings, plane, size)], rings a list of (k, 2) arrays."""
    rings = [r for s in shapes for r in s[0]]
    coords = np.concatenate(rings) if rings else np.zeros((0, 2))
    ring_offsets = np.concatenate([[0], np.cumsum([len(r) for r in rings])]).astype(np.int64)
    shape_offsets = np.concatenate([[0], np.cumsum([len(s[0]) for s in shapes])]).astype(np.int64)
    plane = np.array([s[1] for s in shapes], np.int8)
    size = np.array([s[2] for s in shapes], float).reshape(-1, 3)
    return components(KIND_CODES[kind], coords, ring_offsets, shape_offsets, plane, size, TOL,
                      np.zeros(len(coords), np.int8))


def box(size, plane=1):
    return ([RECT_RINGS[plane]], plane, size)


def courtyard(h):
    """The zoo's courtyard lot (40 x 40, hole 10..30) as footprint_polygons stores it, extruded by h."""
    lots = make_lots("courtyard")
    _, _, size, local = lot_scopes(lots)
    _, coords, ring_offsets, _ = footprint_polygons(lots, size, local)
    rings = [coords[s:e] for s, e in itertools.pairwise(ring_offsets)]
    return (rings, 1, (size[0, 0], h, size[0, 2]))


def corners(origin, axes, csize):
    """The corners of a component's rectangle (2-D) or segment, in the parent frame."""
    out = []
    for fx, fy in itertools.product((0, 1), (0, 1)):
        out.append(origin + fx * csize[0] * axes[0] + fy * csize[1] * axes[1])
    return np.unique(np.round(out, 9), axis=0)


def assert_frames(axes):
    for a in axes:
        np.testing.assert_allclose(a @ a.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(a) == pytest.approx(1.0)


def box_corners(size, y):
    return np.array([[x, y, z] for x in (0, size[0]) for z in (0, size[2])])


def same_points(a, b):
    a = np.unique(np.round(a, 9), axis=0)
    b = np.unique(np.round(b, 9), axis=0)
    return a.shape == b.shape and np.allclose(a, b)


# ----------------------------------------------------------------------------------------------------- box

SIZE = np.array([4.0, 3.0, 2.0])


def test_box_sidefaces():
    parent, index, origin, axes, csize, poly = run("sidefaces", [box(SIZE)])
    assert len(parent) == 4 and parent.tolist() == [0] * 4 and index.tolist() == [0, 1, 2, 3]
    assert np.all(poly == RECT)
    assert_frames(axes)
    center = SIZE / 2
    for o, a, s in zip(origin, axes, csize):
        assert o[1] == 0.0  # on the base
        np.testing.assert_allclose(a[1], [0, 1, 0])  # y up the extrusion
        np.testing.assert_allclose(s[1:], [SIZE[1], 0])
        # x along a base edge of the box: both ends are base corners
        assert any(np.allclose(o + a[0] * s[0], c) for c in box_corners(SIZE, 0))
        assert any(np.allclose(o, c) for c in box_corners(SIZE, 0))
        # z out of the box: from the box centre to the face centre
        face_center = o + a[0] * s[0] / 2 + a[1] * s[1] / 2
        assert np.dot(face_center - center, a[2]) > 0
        # the face lies on the box's boundary plane it faces
        k = int(np.argmax(np.abs(a[2])))
        assert np.allclose(corners(o, a, s)[:, k], 0 if a[2, k] < 0 else SIZE[k])
    np.testing.assert_allclose(axes[0, 2], [0, 0, 1])  # the first side face faces +z
    assert sorted(csize[:, 0].tolist()) == [2, 2, 4, 4]


def test_box_faces():
    parent, index, origin, axes, csize, poly = run("faces", [box(SIZE)])
    assert len(parent) == 6 and index.tolist() == list(range(6))
    assert poly.tolist() == [BOTTOM_POLY, RECT, RECT, RECT, RECT, TOP_POLY]
    assert_frames(axes)
    np.testing.assert_allclose(axes[0, 2], [0, -1, 0])
    np.testing.assert_allclose(axes[-1, 2], [0, 1, 0])
    # bottom and top rectangles are exactly the box's base and lid
    assert same_points(corners(origin[0], axes[0], csize[0]), box_corners(SIZE, 0))
    assert same_points(corners(origin[-1], axes[-1], csize[-1]), box_corners(SIZE, SIZE[1]))
    np.testing.assert_allclose(axes[0, 0], [1, 0, 0])
    np.testing.assert_allclose(axes[-1, 0], [1, 0, 0])
    # the middle four are the side faces, in order
    side = run("sidefaces", [box(SIZE)])
    for got, want in zip((origin, axes, csize), side[2:5]):
        np.testing.assert_array_equal(got[1:5], want)
    # all six face outward and together cover the box's surface
    area = (csize[:, 0] * csize[:, 1]).sum()
    assert area == pytest.approx(2 * (4 * 3 + 3 * 2 + 4 * 2))
    for o, a, s in zip(origin, axes, csize):
        assert np.dot(o + a[0] * s[0] / 2 + a[1] * s[1] / 2 - SIZE / 2, a[2]) > 0


@pytest.mark.parametrize("kind", ["top", "bottom"])
def test_box_top_and_bottom_alone(kind):
    faces = run("faces", [box(SIZE)])
    got = run(kind, [box(SIZE)])
    pick = 0 if kind == "bottom" else -1
    assert len(got[0]) == 1 and got[1].tolist() == [0]
    for g, f in zip(got[2:], faces[2:]):
        np.testing.assert_array_equal(g[0], f[pick])


def test_box_edges_and_vertices():
    parent, index, origin, axes, csize, _ = run("edges", [box(SIZE)])
    assert len(parent) == 12 and index.tolist() == list(range(12))
    assert_frames(axes)
    assert np.all(csize[:, 1:] == 0)
    segments = {tuple(sorted([tuple(np.round(o, 9)), tuple(np.round(o + a[0] * s[0], 9))]))
                for o, a, s in zip(origin, axes, csize)}
    cube = np.array(list(itertools.product((0, SIZE[0]), (0, SIZE[1]), (0, SIZE[2]))))
    want = {tuple(sorted([tuple(p), tuple(q)])) for p, q in itertools.combinations(cube, 2)
            if np.count_nonzero(p != q) == 1}
    assert segments == want
    # bottom ring, top ring, then side edges along +y
    assert np.all(origin[:4, 1] == 0) and np.allclose(origin[4:8, 1], SIZE[1])
    np.testing.assert_allclose(axes[8:, 0], np.tile([0, 1, 0], (4, 1)))
    np.testing.assert_allclose(csize[8:, 0], SIZE[1])
    # a side edge's z is the mean of the outward normals of the side faces meeting there (the one ending
    # there and the one starting there), as CityEngine's edges look along their faces' mean normal
    side = run("sidefaces", [box(SIZE)])
    mean = side[3][:, 2] + np.roll(side[3][:, 2], 1, axis=0)
    np.testing.assert_allclose(axes[8:, 2], mean / np.sqrt(2), atol=1e-12)
    np.testing.assert_allclose(origin[8:], side[2])

    parent, index, origin, axes, csize, _ = run("vertices", [box(SIZE)])
    assert len(parent) == 8 and np.all(csize == 0)
    assert_frames(axes)
    assert same_points(origin, cube)


@pytest.mark.parametrize("kind, count", [("sideedges", 4), ("topedges", 4), ("bottomedges", 4)])
def test_box_edge_subsets(kind, count):
    edges = run("edges", [box(SIZE)])
    got = run(kind, [box(SIZE)])
    start = {"bottomedges": 0, "topedges": 4, "sideedges": 8}[kind]
    assert len(got[0]) == count
    for g, e in zip(got[2:5], edges[2:5]):
        np.testing.assert_allclose(g, e[start:start + count])


# ----------------------------------------------------------------------------------------------- courtyard


def test_courtyard_sidefaces_point_into_the_hole():
    parent, _, origin, axes, csize, _ = run("sidefaces", [courtyard(6.0)])
    assert len(parent) == 8
    assert_frames(axes)
    center = np.array([20.0, 3.0, 20.0])
    for f, (o, a, s) in enumerate(zip(origin, axes, csize)):
        face_center = o + a[0] * s[0] / 2 + a[1] * s[1] / 2
        outward = np.dot(face_center - center, a[2])
        # the exterior's faces point away from the centre, the hole's towards it
        assert outward > 0 if f < 4 else outward < 0
        probe = face_center + a[2] * 1.0
        in_hole = 10 < probe[0] < 30 and 10 < probe[2] < 30
        assert in_hole == (f >= 4)
    assert sorted(csize[:, 0].tolist()) == [20] * 4 + [40] * 4


def test_courtyard_counts():
    assert len(run("faces", [courtyard(6.0)])[0]) == 10
    assert len(run("edges", [courtyard(6.0)])[0]) == 24
    assert len(run("vertices", [courtyard(6.0)])[0]) == 16
    poly = run("faces", [courtyard(6.0)])[5]
    assert poly[0] == BOTTOM_POLY and poly[-1] == TOP_POLY


# ------------------------------------------------------------------------------------------------ flat face


def test_flat_face():
    face = box((5.0, 2.0, 0.0), plane=2)
    parent, _, origin, axes, csize, poly = run("faces", [face])
    assert len(parent) == 1 and poly.tolist() == [SAME_POLY]
    np.testing.assert_array_equal(axes[0], np.eye(3))
    np.testing.assert_array_equal(origin[0], 0)
    np.testing.assert_array_equal(csize[0], [5, 2, 0])
    for kind in ("sidefaces", "top", "bottom", "sideedges", "topedges", "bottomedges"):
        assert len(run(kind, [face])[0]) == 0

    parent, _, origin, axes, csize, _ = run("edges", [face])
    assert len(parent) == 4
    assert_frames(axes)
    np.testing.assert_allclose(axes[:, 1], np.tile([0, 0, 1], (4, 1)))  # y = the face's normal
    center = np.array([2.5, 1.0, 0.0])
    for o, a, s in zip(origin, axes, csize):
        assert a[2, 2] == 0  # z in the plane
        assert np.dot(o + a[0] * s[0] / 2 - center, a[2]) > 0  # pointing out of the face
    assert sorted(csize[:, 0].tolist()) == [2, 2, 5, 5]
    assert len(run("vertices", [face])[0]) == 4


def test_flat_face_plane_0():
    face = box((0.0, 2.0, 3.0), plane=0)
    _, _, origin, axes, csize, _ = run("edges", [face])
    assert len(origin) == 4
    assert_frames(axes)
    np.testing.assert_allclose(axes[:, 1], np.tile([1, 0, 0], (4, 1)))
    center = np.array([0.0, 1.0, 1.5])
    for o, a, s in zip(origin, axes, csize):
        assert np.dot(o + a[0] * s[0] / 2 - center, a[2]) > 0


# -------------------------------------------------------------------------------------------- degenerate


def test_zero_length_edges_are_skipped():
    ring = np.array([[0, 1], [1, 1], [1, 1], [1, 0], [0, 0], [0, 0]], float)
    shape = ([ring], 1, SIZE)
    assert len(run("sidefaces", [shape])[0]) == 4
    assert len(run("edges", [shape])[0]) == 12
    assert len(run("vertices", [shape])[0]) == 8
    np.testing.assert_allclose(run("sidefaces", [shape])[4], run("sidefaces", [box(SIZE)])[4])


@pytest.mark.parametrize("kind", KINDS)
def test_no_shapes(kind):
    parent, _, origin, axes, csize, poly = run(kind, [])
    assert parent.shape == (0,) and origin.shape == (0, 3) and axes.shape == (0, 3, 3)
    assert csize.shape == (0, 3) and poly.shape == (0,)


# -------------------------------------------------------------------------- batches against a reference


def random_polygon(rng):
    """A star-shaped CCW ring in [0, 1]^2 of 3 to 8 vertices, touching the box on both axes."""
    k = rng.integers(3, 9)
    t = np.sort(rng.uniform(0, 2 * np.pi, k))
    r = rng.uniform(0.3, 1.0, k)
    ring = np.stack([np.cos(t) * r, np.sin(t) * r], axis=1)
    ring -= ring.min(axis=0)
    return ring / ring.max(axis=0)


def random_shapes(rng, n):
    shapes = []
    for _ in range(n):
        plane = int(rng.integers(0, 3))
        size = rng.uniform(0.5, 10, 3)
        if rng.random() < 0.3:
            size[plane] = 0.0  # a flat face
        rings = [random_polygon(rng)] if rng.random() < 0.5 else [RECT_RINGS[plane]]
        shapes.append((rings, plane, size))
    return shapes


def ring_edge_reference(rings, plane, size):
    """Plain-Python side-face frames: x along p -> q, y the normal, z = x cross y; origin p."""
    a, b, nrm = UNIT_AXES[plane]
    out = []
    for ring in rings:
        for j in range(len(ring)):
            p, q = np.zeros(3), np.zeros(3)
            p[[a, b]] = ring[j] * size[[a, b]]
            q[[a, b]] = ring[(j + 1) % len(ring)] * size[[a, b]]
            length = np.linalg.norm(q - p)
            if length <= TOL:
                continue
            x = (q - p) / length
            y = np.eye(3)[nrm]
            out.append((p, np.array([x, y, np.cross(x, y)]), length))
    return out


@pytest.mark.parametrize("n", [1, 2, 40])
def test_sidefaces_and_edges_match_reference(n):
    shapes = random_shapes(np.random.default_rng(n), n)
    for kind in ("sidefaces", "bottomedges"):
        parent, _, origin, axes, csize, _ = run(kind, shapes)
        want = [(i, *e) for i, s in enumerate(shapes) if s[2][s[1]] > TOL for e in ring_edge_reference(*s)]
        assert parent.tolist() == [w[0] for w in want]
        np.testing.assert_allclose(origin, np.reshape([w[1] for w in want], (-1, 3)), atol=1e-12)
        np.testing.assert_allclose(axes, np.reshape([w[2] for w in want], (-1, 3, 3)), atol=1e-12)
        np.testing.assert_allclose(csize[:, 0], [w[3] for w in want], rtol=1e-12)
        if kind == "sidefaces":
            np.testing.assert_allclose(csize[:, 1], [shapes[i][2][shapes[i][1]] for i in parent])


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("n", [1, 2, 30])
def test_batch_is_the_concatenation_of_single_shapes(kind, n):
    shapes = random_shapes(np.random.default_rng(100 + n), n)
    whole = run(kind, shapes)
    singles = [run(kind, [s]) for s in shapes]
    parent = np.concatenate([np.full(len(s[0]), i) for i, s in enumerate(singles)])
    assert np.array_equal(whole[0], parent)
    for k in range(1, 6):
        np.testing.assert_array_equal(whole[k], np.concatenate([s[k] for s in singles]))
    assert_frames(whole[3])
    # index numbers each shape's components from 0
    for i in range(n):
        assert whole[1][whole[0] == i].tolist() == list(range(np.count_nonzero(whole[0] == i)))


# ---------------------------------------------------------------------------------------------- property

lengths = st.floats(0.01, 100.0, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(sx=lengths, sy=lengths, sz=lengths, plane=st.sampled_from([0, 1, 2]))
def test_box_areas(sx, sy, sz, plane):
    size = np.array([sx, sy, sz])
    a, b, nrm = UNIT_AXES[plane]
    _, _, _, axes, csize, _ = run("sidefaces", [box(size, plane)])
    perimeter = 2 * (size[a] + size[b])
    assert (csize[:, 0] * csize[:, 1]).sum() == pytest.approx(perimeter * size[nrm], rel=1e-9)
    _, _, origin, axes, csize, _ = run("faces", [box(size, plane)])
    assert len(csize) == 6
    surface = 2 * (sx * sy + sy * sz + sx * sz)
    assert (csize[:, 0] * csize[:, 1]).sum() == pytest.approx(surface, rel=1e-9)
    assert_frames(axes)
    # every face rectangle lies on the box's surface
    for o, ax, s in zip(origin, axes, csize):
        k = int(np.argmax(np.abs(ax[2])))
        pts = corners(o, ax, s)
        assert np.allclose(pts[:, k], 0 if ax[2, k] < 0 else size[k], atol=1e-9)
        assert np.all(pts >= -1e-9) and np.all(pts <= size + 1e-9)


# ----------------------------------------------------------------------------------------- small helpers


def test_rect_plane():
    size = np.array([[1, 2, 3], [1, 2, 0], [0, 2, 3], [1, 0, 3], [0, 2, 0], [1e-12, 1, 1]], float)
    assert rect_plane(size, TOL).tolist() == [1, 2, 0, 1, 2, 0]


@pytest.mark.parametrize("plane", [0, 1, 2])
def test_rect_rings_are_ccw_about_the_normal(plane):
    ring = RECT_RINGS[plane]
    area = 0.5 * np.sum(ring[:, 0] * np.roll(ring[:, 1], -1) - np.roll(ring[:, 0], -1) * ring[:, 1])
    # (u, v) = (a, b); a x b = +normal for planes 0 and 2, -normal for plane 1 (x cross z = -y)
    assert area == (-1.0 if plane == 1 else 1.0)


@pytest.mark.parametrize("n", [0, 1, 2, 10])
def test_reverse_rings(n):
    rng = np.random.default_rng(n)
    counts = rng.integers(1, 6, n)
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    coords = rng.normal(size=(offsets[-1], 2))
    out = reverse_rings(coords, offsets)
    want = [np.roll(coords[s:e][::-1], 1, axis=0) for s, e in itertools.pairwise(offsets)]
    np.testing.assert_array_equal(out, np.concatenate(want) if n else coords)
    np.testing.assert_array_equal(reverse_rings(out, offsets), coords)


def test_a_rectangle_ring_starts_at_its_corner():
    """A box's ring turned to start at a corner, and the corner read back off its first vertex."""
    for plane in range(3):
        for corner in range(4):
            ring = rect_rings(np.array([plane]), np.array([corner]))
            assert rect_corners(ring[:1], np.array([plane])).tolist() == [corner]
            np.testing.assert_array_equal(ring, np.roll(RECT_RINGS[plane], -corner, axis=0))


def test_rect_corners_are_the_nearest_as_argmin_takes_them():
    rng = np.random.default_rng(4)
    plane = rng.integers(0, 3, 5000)
    first = rng.choice([0.0, 1.0, 0.5, -0.0, 1 - 1e-16, np.nan, np.inf], (5000, 2))  # ties, NaN, inf
    first[:2500] = rng.random((2500, 2))
    nearest = np.argmin(((RECT_RINGS[plane] - first[:, None, :]) ** 2).sum(axis=2), axis=1)
    np.testing.assert_array_equal(rect_corners(first, plane), nearest)


def test_rect_rings_start_at_their_corners_taken_mod_4():
    rng = np.random.default_rng(6)
    plane, corner = rng.integers(0, 3, 500), rng.integers(-9, 9, 500).astype(float)  # as the float columns hold it
    rings = rect_rings(plane, corner).reshape(-1, 4, 2)
    for ring, p, c in zip(rings, plane, corner.astype(int)):
        np.testing.assert_array_equal(ring, np.roll(RECT_RINGS[p], -(c % 4), axis=0))
