"""geometry/extrusion.py: faces and their moved copies closed into meshes that wind outwards."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.geometry.extrusion import extruded_meshes

# a 2 x 2 square at y = 0 wound around +y, and a 1 x 1 hole in it wound the other way
SQUARE = np.array([[0, 0, 0], [2, 0, 0], [2, 0, -2], [0, 0, -2]], float)
HOLE = np.array([[0.5, 0, -0.5], [0.5, 0, -1.5], [1.5, 0, -1.5], [1.5, 0, -0.5]], float)


def volumes(verts, ring_offsets, face_offsets, mesh_offsets):
    """Signed volume of each mesh (positive when its faces wind outwards)."""
    out = []
    for m in range(len(mesh_offsets) - 1):
        total = 0.0
        for f in range(mesh_offsets[m], mesh_offsets[m + 1]):
            for r in range(face_offsets[f], face_offsets[f + 1]):
                ring = verts[ring_offsets[r]:ring_offsets[r + 1]]
                total += sum(np.dot(ring[0], np.cross(ring[k], ring[k + 1])) for k in range(1, len(ring) - 1))
        out.append(total / 6)
    return out


def test_a_face_and_a_holed_face_extruded_along_their_normals():
    bottom = np.concatenate([SQUARE, SQUARE, HOLE])
    top = bottom + [0, 3, 0]
    verts, rings, faces, meshes = extruded_meshes(bottom, top, np.array([0, 4, 8, 12]), np.array([0, 1, 3]),
                                                  np.array([True, True]))
    # per face: bottom, top, a side per edge (the hole's edges give inner walls)
    np.testing.assert_array_equal(np.diff(meshes), [6, 10])
    np.testing.assert_array_equal(np.diff(faces), [1, 1, 1, 1, 1, 1, 2, 2, *[1] * 8])
    assert volumes(verts, rings, faces, meshes) == pytest.approx([12, 9])


@pytest.mark.parametrize("lift", [3.0, -3.0])
def test_a_face_extruded_against_its_normal_still_winds_outwards(lift):
    """A face looking down extruded up (or one looking up extruded down): the face keeps its winding as
    the solid's outer side, its copy turns over."""
    face = SQUARE[::-1] if lift > 0 else SQUARE
    verts, rings, faces, meshes = extruded_meshes(face, face + [0, lift, 0], np.array([0, 4]), np.array([0, 1]),
                                                  np.array([False]))
    assert volumes(verts, rings, faces, meshes) == pytest.approx([12])


def test_each_vertex_moves_its_own_way():
    """flatTop: a slanted quad's vertices lifted to one level make a wedge."""
    slanted = SQUARE + np.array([[0, 0, 0], [0, 0, 0], [0, 1, 0], [0, 1, 0]])
    top = slanted.copy()
    top[:, 1] = 1
    verts, rings, faces, meshes = extruded_meshes(slanted, top, np.array([0, 4]), np.array([0, 1]),
                                                  np.array([True]))
    assert volumes(verts, rings, faces, meshes) == pytest.approx([2])
