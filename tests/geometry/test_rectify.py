"""geometry/rectify.py: edges near an axis snapped to it, runs of them one line, holes and falls apart."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from grammarc.geometry.rectify import rectified


def test_a_bent_edge_becomes_one_line_and_a_hole_is_rectified_too():
    """The bottom edge bends at (5, 0.1): one line at the weighted mean height, its middle vertex gone; the
    hole's leaning edge is snapped; an L is left as it is; a triangle's slanted edges are not snapped."""
    polygons = np.array([
        shapely.Polygon([(0, 0), (5, 0.1), (10, 0), (10, 10), (0, 10)], [[(2, 2), (2, 4), (4.1, 4), (4, 2)]]),
        shapely.Polygon([(0, 0), (30, 0), (30, 10), (10, 10), (10, 20), (0, 20)]),
        shapely.Polygon([(0, 0), (10, 5), (0, 10)]),
    ], dtype=object)
    out = rectified(polygons, np.full(3, 5.0))
    assert shapely.equals_exact(out[0], shapely.Polygon([(0, 0.05), (10, 0.05), (10, 10), (0, 10)], [
        [(2, 2), (2, 4), (4.05, 4), (4.05, 2)]]), tolerance=1e-9)
    assert shapely.equals_exact(out[1:], polygons[1:], tolerance=1e-9).all()
    assert shapely.area(rectified(polygons[:1], np.zeros(1))) == pytest.approx(shapely.area(polygons[:1]))
