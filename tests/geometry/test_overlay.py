"""Overlays cleaned of what rounding leaves: nanometre steps and slivers, seams beside lines."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from grammarc.geometry.overlay import without_seams, without_spikes


def test_snapping_leaves_no_nanometre_step_nor_sliver():
    """Two strips' lines that should be one but for rounding (a lot far from the origin) snap to neighbouring
    grid lines: the step of a nanometre between them goes (massing's holes.62285 90 km away: 130 faces for
    126), and so does a sliver a nanometre wide where two folded strips should meet on one line, a hole in
    the strips and a piece of the remainder (holes.62033 56 km away: 192 faces for 191)."""
    stepped = shapely.Polygon([(0, 0), (52, 0), (52, 3.691705197), (45, 3.691705197), (45, 3.691705196),
                               (2.7, 3.691705196), (2.7, 0.5), (0, 0.5)])
    holed = shapely.Polygon([(0, 0), (27, 0), (27, 9), (0, 9)],
                            [[(5.4, 8.1253), (0.6, 8.1253), (0.6, 8.125300001)], [(10, 1), (12, 1), (12, 3), (10, 3)]])
    sliver = shapely.MultiPolygon([shapely.box(21, 0, 27, 5.7), shapely.Polygon([(0.6, 8.1253), (5.4, 8.1253),
                                                                                 (0.6, 8.125300001)])])
    out = without_spikes(np.array([stepped, holed, sliver]))
    assert len(np.asarray(shapely.get_exterior_ring(shapely.get_geometry(out[0], 0)).coords)) == 8
    assert shapely.get_num_interior_rings(shapely.get_geometry(out[1], 0)) == 1
    assert shapely.area(out[1]) == pytest.approx(27 * 9 - 4)
    assert shapely.get_num_geometries(out[2]) == 1 and shapely.area(out[2]) == pytest.approx(6 * 5.7)


def test_seams_go_from_regions_that_also_hold_lines():
    """A region that snapping left with a line beside its polygon (a strip's zero-wide spike) loses its
    seams as well."""
    polygon = shapely.box(0, 0, 10, 4)
    seamed = shapely.Polygon([(0, 0), (5, 0), (10, 0), (10, 4), (0, 4)])
    region = shapely.GeometryCollection([seamed, shapely.LineString([(10, 4), (12, 6)])])
    out = without_seams(np.array([region]), np.array([polygon]))
    assert len(shapely.get_coordinates(out[0])) == 5
