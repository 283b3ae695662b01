"""geometry/queries.py: the faces of boxes, polygons, prisms and meshes in space, and the measures of
faces and shared edges the geometry queries are made of, against values computed by hand."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.geometry.meshes import MESH_BASE, MeshStore
from grammarc.geometry.polygons import PolygonStore
from grammarc.geometry.queries import (
    Faces,
    face_shapes,
    planar_faces,
    rectangular_faces,
    shape_any,
    shape_faces,
    shared_edges,
)

#: Rings in a polygon's (u, v), counter-clockwise around +y for a footprint (v runs along z, to the south).
L_RING = np.array([[0, 20], [30, 20], [30, 10], [10, 10], [10, 0], [0, 0]], float)
COURT = [np.array([[0, 40], [40, 40], [40, 0], [0, 0]], float), np.array([[10, 30], [10, 10], [30, 10], [30, 30]], float)]


def store_of(*polygons, extents):
    """A store of footprints (plane y), each a list of rings in metres normalized by its extent (u, v)."""
    store = PolygonStore()
    ids = []
    for rings, (eu, ev) in zip(polygons, extents):
        coords = np.concatenate(rings) / [eu, ev]
        ring_offsets = np.r_[0, np.cumsum([len(r) for r in rings])]
        ids.append(store.add(coords, ring_offsets, np.array([0, len(rings)]), np.array([1]))[0])
    return store, ids


def measure(faces: Faces, n: int):
    vector, holes, concave = face_shapes(faces.verts, faces.ring_offsets, faces.face_offsets)
    owner = faces.face_shape()
    return {
        "faces": np.diff(faces.shape_offsets),
        "area": np.bincount(owner, np.linalg.norm(vector, axis=1), minlength=n),
        "holes": np.bincount(owner, holes, minlength=n),
        "concave": shape_any(concave, faces),
        "edges": shared_edges(faces, n),
        "vector": vector,
    }


def test_boxes_rectangles_polygons_and_prisms():
    store, (l_id, court_id) = store_of([L_RING], COURT, extents=[(30, 20), (40, 40)])
    size = np.array([[2, 3, 4], [2, 0, 4], [2, 0, 0], [30, 0, 20], [30, 5, 20], [40, 3, 40]], float)
    geom = np.array([-1, -1, -1, l_id, l_id, court_id], np.int32)
    got = measure(shape_faces(size, geom, store, MeshStore()), len(geom))
    assert got["faces"].tolist() == [6, 1, 0, 1, 8, 10]  # a line has no face; a prism bottom, sides, top
    assert got["area"] == pytest.approx([52, 8, 0, 400, 2 * 400 + 100 * 5, 2 * 1200 + 240 * 3])
    assert got["holes"].tolist() == [0, 0, 0, 0, 0, 2]
    assert got["concave"].tolist() == [False, False, False, True, True, True]
    count, boundary, closed = got["edges"]
    assert count.tolist() == [12, 4, 0, 6, 18, 24]
    assert boundary == pytest.approx([0, 12, 0, 100, 0, 0])
    assert closed.tolist() == [True, False, False, False, True, True]


def test_faces_face_out_of_the_solid():
    """A box's faces and a prism's bottom, sides and top: each face's vector area points away from
    the solid's centre, so that the vector areas of a closed surface sum to nothing."""
    store, (l_id,) = store_of([L_RING], extents=[(30, 20)])
    size = np.array([[2, 3, 4], [30, 5, 20]], float)
    faces = shape_faces(size, np.array([-1, l_id], np.int32), store, MeshStore())
    vector = measure(faces, 2)["vector"]
    centre = np.array([[1, 1.5, 2], [15, 2.5, 10]])
    for f, shape in enumerate(faces.face_shape()):
        ring = faces.verts[faces.ring_offsets[faces.face_offsets[f]]:faces.ring_offsets[faces.face_offsets[f] + 1]]
        if shape == 0:  # a box is convex: its faces face away from its centre
            assert vector[f] @ (ring.mean(axis=0) - centre[shape]) > 0
    for shape in range(2):
        assert vector[faces.face_shape() == shape].sum(axis=0) == pytest.approx(np.zeros(3), abs=1e-9)
    assert vector[np.flatnonzero(faces.face_shape() == 1)[[0, -1]], 1] == pytest.approx([-400, 400])


def pyramid(closed: bool, lift: float = 0.0) -> MeshStore:
    """A square pyramid 4 x 4, 2 high, in its unit box; with its base, or open, and the base's first
    corner lifted by ``lift`` (a warped base)."""
    corners = np.array([[0, 0, 1], [1, 0, 1], [1, 0, 0], [0, 0, 0]], float)
    apex = np.array([0.5, 1.0, 0.5])
    rings = [np.array([corners[i], corners[(i + 1) % 4], apex]) for i in range(4)]
    if closed:
        base = corners[::-1].copy()
        base[-1, 1] = lift
        rings.insert(0, base)
    meshes = MeshStore()
    coords = np.concatenate(rings)
    ring_offsets = np.r_[0, np.cumsum([len(r) for r in rings])]
    meshes.add(coords, ring_offsets, np.arange(len(rings) + 1), np.array([0, len(rings)]))
    return meshes


def test_a_mesh_closed_or_open():
    size = np.array([[4, 2, 4]], float)
    geom = np.array([MESH_BASE], np.int32)
    closed = measure(shape_faces(size, geom, PolygonStore(), pyramid(True)), 1)
    count, boundary, is_closed = closed["edges"]
    assert (count[0], boundary[0], is_closed[0]) == (8, 0, True)
    assert closed["area"][0] == pytest.approx(16 + 4 * 2 * np.sqrt(8))
    count, boundary, is_closed = measure(shape_faces(size, geom, PolygonStore(), pyramid(False)), 1)["edges"]
    assert (count[0], boundary[0], is_closed[0]) == (8, pytest.approx(16), False)


def test_planar_within_a_tolerance():
    """The pyramid's base with a corner lifted 1 cm over 4 m is warped by a few tenths of a degree: planar
    within a degree, not within a tenth; its triangles are planar within any tolerance."""
    size = np.array([[4, 2, 4]], float)
    faces = shape_faces(size, np.array([MESH_BASE], np.int32), PolygonStore(), pyramid(True, lift=0.005))
    vector = measure(faces, 1)["vector"]
    args = (faces.verts, faces.ring_offsets, faces.face_offsets, vector)
    assert planar_faces(*args, 1.0).all()
    assert planar_faces(*args, 0.1).tolist() == [False, True, True, True, True]
    assert planar_faces(*args, 0.0)[1:].all()


def test_a_reflex_corner_makes_a_face_concave_and_a_straight_one_does_not():
    store, ids = store_of([L_RING], [np.array([[0, 0], [5, 0], [10, 0], [10, 10], [0, 10]], float)[::-1]],
                          extents=[(30, 20), (10, 10)])
    faces = shape_faces(np.array([[30, 0, 20], [10, 0, 10]], float), np.array(ids, np.int32), store, MeshStore())
    got = measure(faces, 2)
    assert got["concave"].tolist() == [True, False]
    assert planar_faces(faces.verts, faces.ring_offsets, faces.face_offsets, got["vector"], 0.0).all()


def test_a_batch_is_each_shape_alone():
    """Faces of a mixed batch (boxes, faces, prisms with holes, meshes, assets, lines), shuffled, measure
    as each shape alone."""
    store, ids = store_of([L_RING], COURT, extents=[(30, 20), (40, 40)])
    rng = np.random.default_rng(3)
    n = 200
    geom = rng.choice(np.array([-1, -2, ids[0], ids[1], MESH_BASE], np.int32), n)
    size = rng.uniform(0.5, 20, (n, 3))
    size[rng.random(n) < 0.3, rng.integers(0, 3)] = 0.0
    meshes = pyramid(True)
    batch = measure(shape_faces(size, geom, store, meshes), n)
    for i in range(0, n, 7):
        alone = measure(shape_faces(size[i:i + 1], geom[i:i + 1], store, meshes), 1)
        for key in ("faces", "area", "holes", "concave"):
            assert batch[key][i] == pytest.approx(alone[key][0]), (i, key)
        for got, want in zip(batch["edges"], alone["edges"]):
            assert got[i] == pytest.approx(want[0]), i


def test_rectangles_within_a_tolerance():
    """A rectangle, a parallelogram leaning 5 degrees, the courtyard (a square with a hole) and the L:
    only the rectangle is one at 1 degree; the parallelogram is at 6."""
    lean = np.tan(np.radians(5)) * 10
    store, ids = store_of([np.array([[0, 10], [10, 10], [10, 0], [0, 0]], float)],
                          [np.array([[lean, 10], [10 + lean, 10], [10, 0], [0, 0]], float)], COURT, [L_RING],
                          extents=[(10, 10), (10 + lean, 10), (40, 40), (30, 20)])
    size = np.array([[10, 0, 10], [10 + lean, 0, 10], [40, 0, 40], [30, 0, 20]], float)
    faces = shape_faces(size, np.array(ids, np.int32), store, MeshStore())
    args = (faces.verts, faces.ring_offsets, faces.face_offsets)
    assert rectangular_faces(*args, 1.0).tolist() == [True, False, False, False]
    assert rectangular_faces(*args, 6.0).tolist() == [True, True, False, False]
