"""geometry/meshes.py: the border of meshes, as comp's ``border`` and ``inside`` read it."""

from __future__ import annotations

import numpy as np

from grammarc.geometry.meshes import border_ring_edges, mesh_corners, mesh_edges

#: Two unit squares side by side (an open mesh: they share the edge x = 1), then a closed tetrahedron.
VERTS = np.array([
    [0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
    [1, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0],
    [0, 0, 0], [0, 1, 0], [1, 0, 0],
    [0, 0, 0], [1, 0, 0], [0, 0, 1],
    [1, 0, 0], [0, 1, 0], [0, 0, 1],
    [0, 1, 0], [0, 0, 0], [0, 0, 1],
], float)
RINGS = np.array([0, 4, 8, 11, 14, 17, 20])
FACES = np.arange(7)
MESHES = np.array([0, 2, 6])


def test_border_edges_meet_one_face_and_a_closed_mesh_has_none():
    border = border_ring_edges(VERTS, RINGS, FACES, MESHES, 1e-9)
    # the squares' ring edges: all but the shared one (1, 0)-(1, 1), the second of the first square and
    # the last of the second; the tetrahedron: none
    assert border.tolist() == [True, False, True, True, True, True, True, False] + [False] * 12
    _, _, _, _, _, _, edge_border = mesh_edges(VERTS, RINGS, FACES, MESHES, 1e-9)
    assert edge_border.tolist() == [True, False, True, True, True, True, True] + [False] * 6
    *_, corner_border = mesh_corners(VERTS, RINGS, FACES, MESHES, 1e-9)
    assert corner_border.tolist() == [True] * 6 + [False] * 4
