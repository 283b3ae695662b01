"""geometry/reduce.py: rings lose the vertices whose triangles are the smallest first."""

from __future__ import annotations

import numpy as np

from grammarc.geometry.reduce import reduce_rings


def test_the_flattest_vertices_go_first_and_a_ring_keeps_three():
    """A square with a vertex near the middle of each side: reducing by half removes those four; a
    triangle and a quadrilateral stay whole whatever the tolerance; no tolerance removes nothing."""
    square = np.array([[0, 0], [5, 0.01], [10, 0], [10.01, 5], [10, 10], [5, 10], [0, 10], [0, 5.2]], float)
    triangle = np.array([[0, 0], [4, 0], [0, 3]], float)
    quad = square[::2]
    coords = np.concatenate([square, triangle, square, quad])
    offsets = np.array([0, 8, 11, 19, 23])
    keep = reduce_rings(coords, offsets, np.array([0.5, 1.0, 0.0, 1.0]))
    assert keep[:8].tolist() == [True, False, True, False, True, False, True, False]
    assert keep[8:].all()
    keep = reduce_rings(coords, offsets, np.array([1.0, 0.5, 0.2, 0.5]))
    assert keep[:8].sum() == 3 and keep[11:19].sum() == 7 and keep[19:].all()
