"""Sections of concave meshes: the faces' segments on a cut plane, the caps built from them, and closed
slabs."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
import trimesh

from grammarc.geometry.meshes import clip_slabs
from grammarc.geometry.sections import append_caps, plane_segments, section_caps

L_SHAPE = shapely.Polygon([(0, 0), (30, 0), (30, 10), (10, 10), (10, 20), (0, 20)])
COURTYARD = shapely.Polygon([(0, 0), (40, 0), (40, 40), (0, 40)], [[(10, 10), (10, 30), (30, 30), (30, 10)]])


def prism(polygon, height):
    """A closed prism (polygon extruded along z) as one ragged mesh of triangles facing out."""
    mesh = trimesh.creation.extrude_polygon(polygon, height)
    verts = mesh.vertices[mesh.faces].reshape(-1, 3)
    n = len(mesh.faces)
    return verts, np.arange(0, 3 * n + 1, 3), np.arange(n + 1), np.array([0, n])


def cut(mesh, axis, lo, hi):
    verts, rings, faces, meshes = mesh
    lo, hi = np.array([float(lo)]), np.array([float(hi)])
    child = np.zeros(1, dtype=np.int64)
    clipped = clip_slabs(verts, rings, faces, meshes, child, axis, lo, hi, np.zeros(1, dtype=np.bool_), 1e-9)
    ends, cap = plane_segments(verts, rings, faces, meshes, child, np.zeros(1, dtype=np.int64), axis, lo, hi)
    parts, which = section_caps(ends, cap, axis)
    return append_caps(*clipped, parts, which, axis, lo, hi), parts, which


def volume(verts, rings, faces):
    """Signed volume by the divergence theorem (fans of every ring; holes wind the other way)."""
    total = 0.0
    for r in range(len(rings) - 1):
        ring = verts[rings[r]:rings[r + 1]]
        for i in range(1, len(ring) - 1):
            total += np.dot(ring[0], np.cross(ring[i], ring[i + 1])) / 6
    return total


def test_a_cut_across_both_arms_of_an_l_is_closed_by_its_two_sections():
    (verts, rings, faces, _), parts, _ = cut(prism(L_SHAPE, 3.0), 0, 5, 15)
    assert sorted(shapely.area(parts)) == pytest.approx([30, 60])  # 10 x 3 at x = 15, 20 x 3 at x = 5
    assert volume(verts, rings, faces) == pytest.approx(3 * (5 * 20 + 5 * 10))
    assert verts[:, 0].min() == pytest.approx(5) and verts[:, 0].max() == pytest.approx(15)


def test_a_cut_through_a_courtyard_has_caps_with_holes_facing_out():
    (verts, rings, faces, _), parts, which = cut(prism(COURTYARD, 3.0), 2, 1, 2)
    assert list(which) == [0, 1] and shapely.area(parts) == pytest.approx([1200, 1200])
    assert all(len(p.interiors) == 1 for p in parts)
    assert volume(verts, rings, faces) == pytest.approx(1200)
    # the lo cap faces -z (clockwise in (x, y)), the hi cap +z
    assert not parts[0].exterior.is_ccw and parts[1].exterior.is_ccw


def test_a_plane_touching_the_top_from_inside_makes_no_cap():
    _, parts, _ = cut(prism(L_SHAPE, 3.0), 2, 0, 3)
    assert len(parts) == 0
