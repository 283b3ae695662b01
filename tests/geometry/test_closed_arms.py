"""geometry/closed_arms.py: an offset that closes an arm leaves one vertex on the run its neighbours make,
on the bisector of the arm's side lines, as PRT's insets have it (measured through PyPRT on massing)."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from grammarc.geometry.closed_arms import closed_arm_insets

#: A T: a 30 x 20 m bar, a 6 m wide stem on it from x = 10 to 16.
T_LOT = shapely.Polygon([[0, 0], [30, 0], [30, 20], [16, 20], [16, 30], [10, 30], [10, 20], [0, 20]])


def _inset(polygon, distance):
    inset = shapely.buffer(np.array([polygon]), -distance, join_style="mitre", mitre_limit=1e6)
    return closed_arm_insets(inset, np.array([polygon]), np.array([distance]))[0]


def test_a_closed_stem_leaves_one_vertex_on_its_centre_line():
    """Offset by 4 m the 6 m stem closes: PRT's inset is the 22 x 12 m bar with one more vertex, at the
    stem's centre line (13, 16); GEOS leaves two, where each moved side crosses the run (12 and 14)."""
    ring = shapely.get_coordinates(shapely.orient_polygons(_inset(T_LOT, 4.0)).exterior)[:-1]
    assert sorted(map(tuple, ring.tolist())) == [(4, 4), (4, 16), (13, 16), (26, 4), (26, 16)]


def test_a_closed_slanted_stem_leaves_its_vertex_on_the_bisector_of_its_sides():
    """A stem narrowing from 6 m to 4 m: its sides' bisector is the line x = 13 still, by symmetry."""
    narrowing = shapely.Polygon([[0, 0], [30, 0], [30, 20], [16, 20], [15, 30], [11, 30], [10, 20], [0, 20]])
    ring = shapely.get_coordinates(_inset(narrowing, 4.0).exterior)[:-1]
    on_run = ring[(np.abs(ring[:, 1] - 16) < 1e-9) & (ring[:, 0] > 4) & (ring[:, 0] < 26)]
    assert on_run[:, 0].tolist() == pytest.approx([13.0])


def test_an_inset_without_a_closed_arm_is_left_alone():
    """A rectangle's inset, and an inset whose arm stays open, keep GEOS's vertices."""
    for polygon, distance in ((shapely.box(0, 0, 30, 20), 4.0), (T_LOT, 2.0)):
        inset = shapely.buffer(np.array([polygon]), -distance, join_style="mitre", mitre_limit=1e6)
        assert shapely.equals_exact(closed_arm_insets(inset, np.array([polygon]), np.array([distance]))[0],
                                    inset[0])


def test_channels_between_grown_holes_leave_one_vertex_each_on_their_centre_lines():
    """Three bars whose ends lie on one line, 3 m apart, grown by a 4 m offset: the channels between them
    close, and the inset's side along the grown ends keeps one vertex per channel, on its centre line
    (y = 9.5 and 16.5), as PRT's wavefront does (massing's holes.33739), where GEOS leaves each grown
    bar's corners (y = 7, 12, 14 and 19)."""
    lot = shapely.Polygon([(0, 0), (40, 0), (40, 30), (0, 30)],
                          [[(5, 4), (5, 8), (30, 8), (30, 4)], [(5, 11), (5, 15), (30, 15), (30, 11)],
                           [(5, 18), (5, 21), (30, 21), (30, 18)]])
    ring = shapely.get_coordinates(_inset(lot, 4.0).exterior)[:-1]
    assert sorted(ring[ring[:, 0] == 34][:, 1].tolist()) == [4, 9.5, 16.5, 25]
    assert len(ring) == 8


def test_channels_closed_along_a_run_leave_their_vertices_whatever_the_rounding():
    """massing's holes.43669: four holes whose ends lie on one line, offset 7.232 m: the narrow piece between
    them and the outline keeps one vertex per closed channel, on its centre line (y = 9.301, 18.3655 and
    27.9025), as PRT's wavefront does (its building 5346.85 m², grammarc's now 5346.85). GEOS's vertices on
    that run change with a rounding of the coordinates (the lot moved 2 km away: 6564.5 m² at home,
    5334.8 away); the run's vertices do not."""
    holes = [(2.359, 6.806, 30.174), (11.796, 15.498, 40.401), (21.233, 25.135, 38.131), (30.670, 34.404, 38.706)]
    rng = np.random.default_rng(0)
    for noise in (0.0, 1e-13, 1e-13, 1e-13):
        def jiggled(points, noise=noise):
            return [(x + noise * rng.standard_normal(), y + noise * rng.standard_normal()) for x, y in points]
        lot = shapely.Polygon(jiggled([(0, 0), (60.058, 0), (60.058, 37.748), (0, 37.748)]),
                              [jiggled([(15.0145, low), (15.0145, high), (right, high), (right, low)])
                               for low, high, right in holes])
        (piece,) = [p for p in shapely.get_parts(_inset(lot, 7.232)) if p.bounds[2] < 10]
        ring = shapely.get_coordinates(piece.exterior)[:-1]
        run = np.sort(ring[np.abs(ring[:, 0] - 7.7825) < 1e-6][:, 1])
        assert run == pytest.approx([7.232, 9.301, 18.3655, 27.9025, 30.516], abs=1e-9)


def test_a_closed_bar_leaves_its_vertex_on_a_run_where_geos_leaves_none():
    """massing's H.57370: an H's 4.7 m bar closes under a 7.721 m offset, and each leg's inner side keeps
    one vertex on the bar's centre line (y = 12.95), as PRT's wavefront does (its building 2247.03 m²,
    grammarc's 2247.02). Moved 59 km away, GEOS leaves no vertex on that run at all (grammarc's building
    was 1561.99 m² there); the run's vertex is placed all the same."""
    outline = [(0, 0), (17.5, 0), (17.5, 10.6), (27.15, 10.6), (27.15, 0), (44.65, 0), (44.65, 25.9),
               (27.15, 25.9), (27.15, 15.3), (17.5, 15.3), (17.5, 25.9), (0, 25.9)]
    rng = np.random.default_rng(1)
    for noise in (0.0, 1e-12, 1e-12, 1e-12, 1e-12):
        lot = shapely.Polygon([(x + noise * rng.standard_normal(), y + noise * rng.standard_normal())
                               for x, y in outline])
        ring = np.concatenate([shapely.get_coordinates(p.exterior)[:-1]
                               for p in shapely.get_parts(_inset(lot, 7.721))])
        inner = ring[np.isclose(ring[:, 0], 17.5 - 7.721) | np.isclose(ring[:, 0], 27.15 + 7.721)]
        assert np.sort(inner[:, 1]) == pytest.approx([7.721] * 2 + [12.95] * 2 + [25.9 - 7.721] * 2, abs=1e-9)


def test_a_face_offset_as_its_valid_parts_takes_the_rings_of_all_its_parts():
    """A face whose ring runs back over its own edge (a facade face of candler on a real lot of Sibiu's old
    town) is offset as its valid parts, a multipolygon (``offsets._inset_and_border``); beside a polygon in
    one batch, the closed arm of the polygon is still placed, and the parts' inset kept (the batch's
    rings were read as one polygon's each, and the build stopped with a traceback)."""
    face = shapely.Polygon([(14.9, 0.43), (15.12, 6.49), (17.98, 6.49), (17.6, 0.96), (31.89, 0), (37.81, 0),
                            (38.26, 6.49), (57.62, 6.49), (56.33, 0), (18.79, 0), (11.84, 0.53), (14.9, 0.43)])
    parts = shapely.make_valid(face, method="structure", keep_collapsed=False)
    assert shapely.get_type_id(parts) == shapely.GeometryType.MULTIPOLYGON
    polygons, distance = np.array([T_LOT, parts]), np.array([4.0, 1.85])
    inset = shapely.buffer(polygons, -distance, join_style="mitre", mitre_limit=1e6)
    out = closed_arm_insets(inset, polygons, distance)
    ring = shapely.get_coordinates(shapely.orient_polygons(out[0]).exterior)[:-1]
    assert sorted(map(tuple, ring.tolist())) == [(4, 4), (4, 16), (13, 16), (26, 4), (26, 16)]
    assert shapely.equals(out[1], inset[1])
    assert shapely.get_num_coordinates(out[1]) == shapely.get_num_coordinates(inset[1])
