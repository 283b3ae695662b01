"""Convex parts: rectilinear footprints into rectangles, holes cut open, random polygons tiled by convex
pieces, and split lines limited in length."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from grammarc.geometry.convexify import convex_parts

L_SHAPE = shapely.Polygon([(0, 0), (30, 0), (30, 10), (10, 10), (10, 20), (0, 20)])
U_SHAPE = shapely.Polygon([(0, 0), (40, 0), (40, 30), (30, 30), (30, 10), (10, 10), (10, 30), (0, 30)])
COURTYARD = shapely.Polygon([(0, 0), (40, 0), (40, 40), (0, 40)], [[(10, 10), (10, 30), (30, 30), (30, 10)]])


def is_convex(pieces):
    """Whether each piece's outline turns left at every corner, or right by less than a degree (a corner
    that convexify leaves as it is)."""
    out = []
    for piece in pieces:
        xy = np.asarray(shapely.orient_polygons(piece).exterior.coords)[:-1]
        d_in, d_out = xy - np.roll(xy, 1, axis=0), np.roll(xy, -1, axis=0) - xy
        turn = np.arctan2(d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0], (d_in * d_out).sum(axis=1))
        out.append(bool((turn > -np.radians(1.0)).all()) and not piece.interiors)
    return np.array(out)


@pytest.mark.parametrize("polygon, areas", [
    (L_SHAPE, [200, 200]), (U_SHAPE, [300, 300, 200]), (COURTYARD, [300, 300, 300, 300]),
    (shapely.box(0, 0, 5, 3), [15]),
])
def test_rectilinear_footprints_become_rectangles(polygon, areas):
    """In a roof's x-z plane (left-handed, as candler's roofs are cut), where the kit's L comes out as its
    two 10 m arms: a tie between a corner's two edges goes to the one coming in, the boundary running
    forward about the face's normal."""
    pieces, source = convex_parts(np.array([polygon]), None, np.array([True]))
    assert sorted(shapely.area(pieces).round(9), reverse=True) == sorted(areas, reverse=True)
    assert (source == 0).all() and is_convex(pieces).all()
    assert np.allclose(shapely.area(shapely.oriented_envelope(pieces)), shapely.area(pieces))


def corners(piece):
    return len(piece.exterior.coords) - 1


def test_a_corner_is_cut_along_the_edge_whose_run_into_the_piece_is_shorter():
    """PRT's candler roofs (one ventilation, on the rectangles of 4 corners only): an H whose bar is
    narrower than its arms is cut across the bar's ends, along the arms' inner edges, into the bar and
    two arms that keep the cuts' ends as corners; a Z's middle likewise; a U deeper than its arms are
    wide is cut below its arms (the kit's U: two ventilations, on the arms)."""
    h = shapely.Polygon([(0, 0), (4, 0), (4, 3.5), (8, 3.5), (8, 0), (12, 0), (12, 10), (8, 10), (8, 6.5),
                         (4, 6.5), (4, 10), (0, 10)])
    pieces, _ = convex_parts(np.array([h]))
    assert sorted(shapely.area(pieces).round(9)) == [12, 40, 40]
    assert sorted(corners(p) for p in pieces) == [4, 6, 6]
    z = shapely.Polygon([(0, 0), (10, 0), (10, 10), (28, 10), (28, 25), (18, 25), (18, 15), (0, 15)])
    pieces, _ = convex_parts(np.array([z]))
    assert sorted(zip(shapely.area(pieces).round(9), (corners(p) for p in pieces))) == [(40, 4), (150, 5),
                                                                                         (150, 5)]
    pieces, _ = convex_parts(np.array([shapely.Polygon([(0, 0), (40, 0), (40, 30), (30, 30), (30, 15), (10, 15),
                                                       (10, 30), (0, 30)])]))
    assert sorted(zip(shapely.area(pieces).round(9), (corners(p) for p in pieces))) == [(150, 4), (150, 4),
                                                                                         (600, 6)]


def test_pieces_start_where_their_boundary_leaves_the_cut():
    """The part whose boundary runs on from the cut corner starts there, the other where the cut ends on
    the boundary, so that each part's first edge is one of the polygon's (the kit's L: PRT's ventilation
    on the arm runs along it); but a part that keeps its parent's first vertex starts there."""
    pieces, _ = convex_parts(np.array([L_SHAPE]))
    assert sorted(p.exterior.coords[0] for p in pieces) == [(0, 0), (10, 10)]
    assert all(p.exterior.is_ccw for p in pieces)



# a roof whose main block has a strip along one side and a small bump at the strip's end (candler.tartu.17's,
# squared): the corner where the strip leaves the block comes first in the ring, its cut (5.7 m, across the
# strip's foot) is longer than the one at the bump's foot (1 m)
BUMPED_ROOF = shapely.Polygon([(0, 11.5), (6.7, 11.5), (6.7, 5.7), (7.55, 5.7), (7.55, 4.7), (7.35, 4.7), (7.35, 0),
                               (0, 0)])


def test_the_shortest_cut_goes_first():
    """PRT's candler on this roof's footprint (inset by 0.8 m), from each of its eight ring starts, lays its
    one ventilation on the bump's 0.2 m outer strip: the bump's foot is cut first, across the bump (1 m),
    and the rest then along the block's side, so that the strip (with the bump's inner part) and the block
    keep a cut's end as a fifth corner. Cut at the ring's first corner, the strip came out a rectangle and
    the ventilation stood on it (2.3 to 2.9 m off PRT's bounding box)."""
    pieces, _ = convex_parts(np.array([BUMPED_ROOF]), None, np.array([True]))
    assert is_convex(pieces).all()
    assert sorted(zip(shapely.area(pieces).round(9), (corners(p) for p in pieces))) == [
        (0.2, 4), (3.705, 5), (77.05, 5)]


def test_a_cut_that_passes_a_corner_by_half_a_millimetre_ends_there():
    """A block with a bump whose sides stand 1 mm off the line of the block's side (candler.tartu.12's
    outline, squared): PRT's candler, from four ring starts of the footprint, lays its ventilation on the
    bump, a rectangle, and none on the block. The cut along the block's side at the bump's foot ends at the
    bump's other corner, half a millimetre beside its line, instead of running on along the side and leaving a
    sliver rectangle (1.3 to 1.5 m off PRT's bounding box)."""
    footprint = shapely.Polygon([(0, 0), (10, 0), (9.999, 4), (12.5, 4), (12.5, 7.5), (9.999, 7.5), (10, 12), (0, 12)])
    roof = shapely.buffer(footprint, -0.8, join_style="mitre")
    pieces, _ = convex_parts(np.array([roof]))
    assert is_convex(pieces).all() and shapely.area(pieces).sum() == pytest.approx(roof.area)
    rectangles = [p for p in pieces if corners(p) == 4]
    assert len(rectangles) == 1 and rectangles[0].area == pytest.approx(2.501 * 1.9, abs=1e-3)

# candler.H.31062's footprint: an H turned by 5 degrees, its bars 27 m by 4.5 m; its roof is inset by 0.8 m
H_LOT = shapely.Polygon([(13.13, 4.42), (12.73, 8.96), (-14.09, 6.63), (-13.7, 2.09), (-3.7, 2.96), (-3.14, -3.56),
                         (-13.13, -4.42), (-12.73, -8.96), (14.09, -6.63), (13.7, -2.09), (3.7, -2.96),
                         (3.14, 3.56)])


def test_the_arm_that_keeps_the_roofs_first_corner_starts_there():
    """PRT's ventilation on candler.H.31062's arm beside the roof's first corner lies across the arm (its
    scope runs along the short side from that corner), the other three along their arms: a part is a run
    of its parent's ring, kept in the parent's order."""
    roof = shapely.buffer(H_LOT, -0.8, join_style="mitre")
    first = roof.exterior.coords[0]
    pieces, _ = convex_parts(np.array([roof]))
    arms = [p for p in pieces if corners(p) == 4]
    assert len(arms) == 4
    starting = [p for p in arms if np.allclose(p.exterior.coords[0], first)]
    assert len(starting) == 1
    ring = np.asarray(starting[0].exterior.coords)
    assert np.hypot(*(ring[1] - ring[0])) < 3.5  # its first edge: the arm's short end
    for arm in arms:
        if arm is not starting[0]:
            ring = np.asarray(arm.exterior.coords)
            assert np.hypot(*(ring[1] - ring[0])) > 9.0


# candler.Z.11103's roof (inset by 0.8 m), a Z turned by 10.7 degrees whose arms are 3.3 m by 13.5 m
Z_ROOF = shapely.Polygon([(8.1, 14.81), (5.61, 1.56), (-7.87, 4.1), (-11.32, -14.2), (-8.1, -14.81),
                          (-5.61, -1.56), (7.87, -4.1), (11.32, 14.2)])


@pytest.mark.parametrize("mirrored", [False, True])
def test_the_arms_of_a_z_start_along_their_long_side(mirrored):
    """PRT lays the ventilations of candler.Z.11103 along the Z's arms: each arm, cut off along the line of
    the middle's long edge, starts where that cut ends and runs along its long side first. The same in a
    left-handed frame (a roof's x-z plane), where the boundary runs forward clockwise."""
    polygon = shapely.transform(Z_ROOF, lambda xy: xy * [-1, 1]) if mirrored else Z_ROOF
    pieces, _ = convex_parts(np.array([polygon]), None, np.array([True])) if mirrored else convex_parts(
        np.array([polygon]))
    arms = [p for p in pieces if corners(p) == 4]
    assert len(arms) == 2
    for arm in arms:
        xy = np.asarray(arm.exterior.coords)
        assert arm.exterior.is_ccw != mirrored
        assert np.hypot(*(xy[1] - xy[0])) == pytest.approx(13.48, abs=0.02)


# a 12 m by 8 m block with a strip 0.4 m wide along its side (its foot 4 m from the block's corner) and one 0.5 m
# wide across its end, the two meeting at the corner (candler.seoul.35's roof, squared); the strip across the
# end runs 3 m along the block (its cut, 3.4 m, goes before the side strip's, 4.5 m), or 6 m (6.4 m: after it)
def strips(end_strip):
    return shapely.Polygon([(0, 0), (12, 0), (12, 8), (end_strip, 8), (end_strip, 8.5), (-0.4, 8.5), (-0.4, 4), (0, 4)])


@pytest.mark.parametrize("end_strip, rectangle", [(3, shapely.box(-0.4, 4, 0, 8)), (6, shapely.box(0, 8, 6, 8.5))])
def test_a_cut_that_ends_on_an_earlier_cut_gives_the_piece_beyond_it_a_corner_there(end_strip, rectangle):
    """PRT's candler on these roofs' footprints (inset by 0.8 m) lays one ventilation, on the strip whose cut
    goes last (on the side strip, x -0.4..0, when the end strip's is shorter; on the end strip, y 8..8.5,
    when it is longer): the cut that goes last ends on the first one, and the strip beyond that, whose
    edge it splits, keeps the cut's end as a fifth corner."""
    pieces, _ = convex_parts(np.array([strips(end_strip)]), None, np.array([True]))
    assert sorted(corners(p) for p in pieces) == [4, 5, 6]
    (four,) = [p for p in pieces if corners(p) == 4]
    assert four.equals(rectangle)


@pytest.mark.parametrize("degrees", [0.003, 1.5])
def test_a_side_that_bends_back_just_before_its_end_leaves_no_rectangle(degrees):
    """A 10 m by 6 m roof whose side bends back by a few thousandths of a degree or by 1.5 degrees 15.8 cm
    before its end (candler.seoul.12's roof, squared): PRT's candler lays no ventilation on it, from 0.0003
    to 5 degrees. The corner is not cut (under a degree), or its cut, 1.5 degrees, runs 4 mm beside the
    side's end, its own neighbour, on to the boundary; cut across the boundary, or ended at that neighbour
    and then cut across, it made two rectangles."""
    bend = 0.158 * np.tan(np.radians(degrees))
    roof = shapely.Polygon([(0, 0), (9.842, 0), (10, -bend), (10, 6), (0, 6)])
    pieces, _ = convex_parts(np.array([roof]), None, np.array([True]))
    assert 4 not in [corners(p) for p in pieces]
    assert shapely.area(pieces).sum() == pytest.approx(roof.area)


def stepped_block(side):
    """An 11 m wide block whose left side steps sideways by ``side`` at a bump 0.85 m deep, 3.39 m high (its
    top 1.02 m below a step of 1.4 m out on the right side): candler.tartu.3's roof, squared."""
    return shapely.Polygon([(0, 0), (11, 0), (11, 18.14), (12.4, 18.14), (12.4, 30), (side, 30), (side, 17.12),
                            (-0.85, 17.12), (-0.85, 13.73), (0, 13.73)])


def rectangles(pieces):
    return sorted(tuple(np.round(shapely.bounds(p), 4)) for p in pieces if corners(p) == 4)


BUMP = (-0.85, 13.73, 0.0, 17.12)


@pytest.mark.parametrize("side, expected", [
    (0.0007, [(-0.85, 13.73, 0.0007, 17.12)]),  # cut along one slanting line
    (0.0015, [BUMP, (0.0015, 17.12, 11.0, 18.14)]),
    (0.0035, [BUMP, (0.0035, 17.12, 11.0, 18.14)]),
])
def test_a_cut_passing_a_corner_by_a_millimetre_runs_on(side, expected):
    """PRT's candler on these roofs' footprints: a side that steps 0.7 mm sideways at the bump (0.3 to 0.7
    mm measured) gets one ventilation, on the bump; one that steps 0.9 mm or more, a second on the strip
    between the bump's top and the step on the right side. The cut along the side's line at the bump's
    top passes its other foot and runs on to the block's bottom; the cut along the bump's top, shorter,
    goes instead (it ended at the other foot, 1.5 and 3.5 mm beside its line, and took the bump off)."""
    pieces, _ = convex_parts(np.array([stepped_block(side)]), None, np.array([True]))
    assert [r for r in rectangles(pieces) if r[0] < 0 or r[1] > 17] == expected


@pytest.mark.parametrize("start", range(10))
def test_of_two_cuts_across_a_block_the_shorter_by_millimetres_goes_first(start):
    """The side steps 3.5 mm out at the bump: PRT's candler, from each of the footprint's ten ring starts,
    lays a ventilation on the block below the bump (11 m by 13.73 m). The cut across it at the bump's foot
    (11 m) goes before the one across at the step on the right (11.0035 m), whose end at the side would
    have sent the foot's cut up along the side; cuts within 1 % of each other went in ring order."""
    ring = np.asarray(stepped_block(-0.0035).exterior.coords)[:-1]
    pieces, _ = convex_parts(np.array([shapely.Polygon(np.roll(ring, -start, axis=0))]), None, np.array([True]))
    assert (0.0, 0.0, 11.0, 13.73) in rectangles(pieces)


@pytest.mark.parametrize("bend, rectangles", [(0.002, 1), (0.3, 1), (0.31, 0), (1.0, 0)])
def test_a_corner_of_under_a_degree_is_not_cut(bend, rectangles):
    """A block 17.3 m wide with a strip 8.6 m by 2.65 m across its end (candler.hiroshima.72's roof, squared),
    whose other side bends in by ``bend`` 30 m up (0.007, 0.99, 1.02 and 3.3 degrees): PRT's candler lays a
    ventilation on the strip below 1 degree and none from 1.02 degrees on. The bend's cut, down along its
    side's line, ends on the strip's edge and gives it a fifth corner; under a degree it is not cut (it was,
    after the others, and the strip lost its ventilation)."""
    roof = shapely.Polygon([(0, 0), (8.6, 0), (8.6, 2.65), (17.3, 2.65), (17.3, 71.5), (0, 71.5), (bend, 30)])
    pieces, _ = convex_parts(np.array([roof]), None, np.array([True]))
    assert [corners(p) for p in pieces].count(4) == rectangles


def test_split_lines_longer_than_max_length_are_not_cut():
    # the split lines at the L's and the U's inner corners cross their 10 m deep foot
    _, source = convex_parts(np.array([L_SHAPE, U_SHAPE, L_SHAPE, U_SHAPE]), np.array([5.0, 8.0, 12.0, 12.0]))
    assert np.bincount(source).tolist() == [1, 1, 2, 3]


def star(seed, hole):
    rng = np.random.default_rng(seed)
    k = int(rng.integers(5, 30))
    angles = np.sort(rng.uniform(0, 2 * np.pi, k))
    angles += (np.arange(k) * 2 * np.pi / k - angles) * 0.5
    polygon = shapely.Polygon(np.stack([np.cos(angles), np.sin(angles)], 1) * rng.uniform(6, 12, k)[:, None])
    if hole:
        polygon = polygon.difference(shapely.Point(rng.uniform(-1, 1, 2)).buffer(2.0, 2))
    return polygon if isinstance(polygon, shapely.Polygon) else max(polygon.geoms, key=lambda g: g.area)


# derandomized: a piece whose corners' cuts all shave off slivers stays concave (see convexify.py); a
# fixed set of examples keeps the test a regression test
@settings(max_examples=80, deadline=None, derandomize=True)
@given(st.integers(0, 2**32 - 1), st.booleans())
def test_random_polygons_are_tiled_by_convex_pieces(seed, hole):
    polygon = star(seed, hole)
    pieces, _ = convex_parts(np.array([polygon]))
    assert sum(shapely.area(pieces)) == pytest.approx(polygon.area, rel=1e-9)
    assert shapely.area(shapely.union_all(pieces, grid_size=1e-9)) == pytest.approx(polygon.area, rel=1e-6)
    assert is_convex(pieces).all()


def test_the_cut_corner_stays_a_vertex_whatever_the_last_bits():
    """candler.L.31352's roof as it comes out 8 km from the origin, where the corner at (12.47, 3.68) and
    the edge above it are off the cut's line by 1e-13 m: GEOS's overlay took the cut's line for the edge
    and dropped the corner, which the same lot at the origin kept (its roof part rectangular there, and
    not here); the corner stays."""
    roof = shapely.Polygon([(12.473032481078317, 18.491418641666332), (17.313648359239465, 18.491418641666332),
                            (17.313648359239508, 2.9132252166164103e-13), (0.0, 0.0),
                            (5.2937169036571445e-14, 3.680220508187176), (12.473032481078445, 3.680220508187494)])
    pieces, _ = convex_parts(np.array([roof]), None, np.array([True]))
    assert sorted(corners(p) for p in pieces) == [4, 5]


def test_a_nearly_straight_corner_is_not_cut():
    """candler.near_degenerate.31488's roof: an L whose bar has a bump of 1 cm at (18.79, 16.3), before the
    L's corner in the boundary's order. Cut there first, the bar came off whole (202 m^2, a roof access);
    PRT cuts the L's corner across the bar, and neither part is large enough for one."""
    roof = shapely.Polygon([(0.0, 21.07), (42.3, 21.07), (42.3, 16.29), (18.79, 16.3), (7.57, 16.29), (7.57, 0.0),
                            (2.32, 0.0), (0.0, 0.0)])
    pieces, _ = convex_parts(np.array([roof]), None, np.array([True]))
    assert shapely.area(pieces).max() < 170
    assert np.isclose(shapely.area(pieces).sum(), roof.area)


def test_a_hole_is_opened_by_cuts_that_stop_at_the_boundary():
    """candler.courtyard.32354's roof (a rectangle with a turned square hole that nearly touches two of its
    sides): from each of the hole's corners a cut runs on along one of its edges to the outer ring and
    stops there. PRT builds roof accesses on two faces over 200 m^2, which a cut along the whole line
    (through the hole and out the other side) split into four under it."""
    roof = shapely.Polygon([(0.0, 41.67), (22.77, 41.67), (22.77, 0.0), (0.0, 0.0)],
                           [[(21.91, 27.27), (11.64, 33.17), (0.86, 14.4), (11.13, 8.5)]])
    pieces, _ = convex_parts(np.array([roof]), None, np.array([True]))
    assert sorted(shapely.area(pieces).round(0)) == [109, 109, 237, 237]
    assert is_convex(pieces).all()
