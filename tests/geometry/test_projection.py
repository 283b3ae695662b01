"""geometry/projection.py: faces seen along an axis, united per shape; faces seen edge-on drop out."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from grammarc.geometry.projection import projected_outlines


def test_faces_project_and_unite_per_shape():
    """Shape 0: a unit square's top, bottom and an edge-on wall (x, z kept); shape 1: two squares apart;
    shape 2: no face."""
    square = [[0, 0], [1, 0], [1, 1], [0, 1]]
    wall = [[0, 0], [1, 0], [1, 0], [0, 0]]
    far = [[3, 0], [4, 0], [4, 1], [3, 1]]
    points = np.array(square + square + wall + square + far, dtype=float)
    rings = np.arange(0, 21, 4)
    faces = np.arange(6)
    outlines = projected_outlines(points, rings, faces, np.array([0, 0, 0, 1, 1]), 3)
    assert shapely.area(outlines).tolist() == pytest.approx([1, 2, 0])
    assert shapely.get_num_geometries(outlines[:2]).tolist() == [1, 2] and shapely.is_empty(outlines[2])
