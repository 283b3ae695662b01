"""geometry/area_cuts.py: the area before a position, and the position before which faces have an area."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.geometry.area_cuts import area_positions, total_areas


def _faces(*rings):
    """Faces of one ring each, one shape per face: verts, ring_offsets, face_offsets, shape_offsets."""
    verts = np.concatenate([np.asarray(r, float) for r in rings])
    offsets = np.cumsum([0] + [len(r) for r in rings])
    counts = np.arange(len(rings) + 1)
    return verts, offsets, counts, counts


def test_areas_and_positions_of_a_rectangle_a_triangle_and_a_tilted_face():
    """A 4 x 2 rectangle halves at 2; a right triangle of legs 10 has a quarter of its area before
    10 (1 - sqrt(3/4)) along its leg; a face tilted 60 degrees out of the x-z plane measures its own
    area, not its shadow's."""
    tilt = np.array([[0, 0, 0], [4, 0, 0], [4, 1, np.sqrt(3)], [0, 1, np.sqrt(3)]])
    faces = _faces([[0, 0, 0], [4, 0, 0], [4, 0, -2], [0, 0, -2]], [[0, 0, 0], [10, 0, 0], [0, 0, -10]], tilt)
    total = total_areas(*faces)
    assert total == pytest.approx([8.0, 50.0, 8.0])
    shape = np.array([0, 1, 2, 1, 1])
    area = np.array([4.0, 12.5, 2.0, 0.0, 60.0])
    extent = np.array([4.0, 10.0, 4.0, 10.0, 10.0])
    found = area_positions(*faces, 0, shape, area, extent, total[shape])
    assert found == pytest.approx([2.0, 10 * (1 - np.sqrt(0.75)), 1.0, 0.0, 10.0])
