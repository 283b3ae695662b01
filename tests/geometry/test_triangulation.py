"""Triangulation of planar polygons with holes: fans for convex faces, earcut for the rest, along the normal."""

import importlib.util

import numpy as np
import pytest

from grammarc.geometry.triangulation import triangulate_polygons

needs_earcut = pytest.mark.skipif(importlib.util.find_spec("mapbox_earcut") is None,
                                  reason="mapbox-earcut not installed")


def polygons(faces: list[list[np.ndarray]]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertices, ring and face offsets of faces given as lists of rings (outline first), each (n, 3)."""
    rings = [np.asarray(ring, float) for face in faces for ring in face]
    ring_offsets = np.concatenate([[0], np.cumsum([len(r) for r in rings])]).astype(np.int64)
    face_offsets = np.concatenate([[0], np.cumsum([len(f) for f in faces])]).astype(np.int64)
    return np.concatenate(rings), ring_offsets, face_offsets


def tilt(points) -> np.ndarray:
    """Points of the x-z plane (y = 0) turned 40 degrees about x and moved: a polygon in a tilted plane."""
    a = np.radians(40)
    turn = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    return np.asarray(points, float) @ turn.T + [100, 20, -50]


def test_convex_faces_are_fans_and_degenerate_faces_vanish():
    square = np.array([[0, 0, 0], [0, 5, 0], [0, 5, 5], [0, 0, 5.0]])  # normal -x
    line = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]])
    triangles = triangulate_polygons(*polygons([[square], [line]]))
    assert triangles.tolist() == [[0, 1, 2], [0, 2, 3]]
    no_offsets = np.zeros(1, np.int64)
    assert triangulate_polygons(np.zeros((0, 3)), no_offsets, no_offsets).shape == (0, 3)


@needs_earcut
def test_holes_and_concave_outlines_in_a_tilted_plane_face_along_the_normal():
    # (x, z) rings with normal +y before tilting: counter-clockwise seen from +y goes +x -> -z.
    outline = [[0, 0, 0], [10, 0, 0], [10, 0, -10], [0, 0, -10]]
    hole = [[3, 0, -3], [3, 0, -7], [7, 0, -7], [7, 0, -3]]  # opposite order, 4 x 4
    ell = [[0, 0, 0], [6, 0, 0], [6, 0, -2], [2, 0, -2], [2, 0, -6], [0, 0, -6]]  # 20 m2, concave
    vertices, ring_offsets, face_offsets = polygons([[tilt(outline), tilt(hole)], [tilt(ell)]])
    triangles = triangulate_polygons(vertices, ring_offsets, face_offsets)
    assert len(triangles) == (8 + 2 - 2) + (6 - 2)  # V + 2H - 2 per face
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    cross = np.cross(b - a, c - a)
    normal = tilt([[0, 1, 0]])[0] - tilt([[0, 0, 0]])[0]
    np.testing.assert_allclose(cross / np.linalg.norm(cross, axis=1, keepdims=True),
                               np.tile(normal, (len(triangles), 1)), atol=1e-9)
    assert 0.5 * np.linalg.norm(cross, axis=1).sum() == pytest.approx(100 - 16 + 20, rel=1e-9)
    assert (triangles[:8] < 8).all() and (triangles[8:] >= 8).all()  # each face's triangles use its rings


def test_a_convex_face_faces_the_way_its_outline_winds():
    # The same square both ways round: its Newell normal, and so its fan, turns with the winding.
    square = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
    vertices, ring_offsets, face_offsets = polygons([[square], [square[::-1]]])
    triangles = triangulate_polygons(vertices, ring_offsets, face_offsets)
    a, b, c = (vertices[triangles[:, k]] for k in range(3))
    assert np.cross(b - a, c - a)[:, 2].tolist() == [1, 1, -1, -1]
