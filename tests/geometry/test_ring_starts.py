"""Where the rings of clipped, offset and set back pieces start (``geometry.ring_starts``, through
``clip.fit_pieces``): each rule as PRT was measured to start them."""

from __future__ import annotations

import numpy as np
import pytest
import shapely


def test_pieces_start_where_cityengine_starts_them():
    """Offsets keep vertex i at the mitre of vertex i, so edge numbers follow the parent's; a cut piece
    on the side without vertex 0 and 1 starts with its cut edge. The U lot of the PRT kit in its
    footprint plane (x, z), clockwise there: counter-clockwise seen from +y."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    u_lot = shapely.Polygon([(0, 0), (0, 30), (10, 30), (10, 15), (30, 15), (30, 30), (40, 30), (40, 0)])
    plane, size = np.array([1]), np.array([[40.0, 0.0, 30.0]])

    def first_vertex(pieces):
        return pieces.coords[0] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]]

    inset = shapely.buffer(u_lot, -3, join_style="mitre")  # GEOS starts it anywhere
    np.testing.assert_allclose(first_vertex(fit_pieces(np.array([inset]), plane, size, np.array([u_lot]))),
                               [3, 3])  # vertex 0's mitre
    ordered = shapely.Polygon([(3, 3), (3, 27), (7, 27), (7, 12), (33, 12), (33, 27), (37, 27), (37, 3)])
    cut = shapely.intersection(ordered, shapely.box(20, -1, 50, 40))
    # the side of the cut without vertex 0 and 1: where the boundary leaves the piece, on the edge into vertex 0
    np.testing.assert_allclose(first_vertex(fit_pieces(np.array([cut]), plane, size, np.array([ordered]),
                                                       cut_sides=np.array([False]))), [20, 3])


def test_an_inset_without_the_last_edge_starts_where_edge_0_ends():
    """An offset that makes the parent's last edge vanish takes vertex 0 with it: PRT's inset starts at
    the end of the first edge left (vertex 1's mitre, edge 0 left), not at its start (measured through
    PyPRT on massing's H and L footprints whose arms the offset closed)."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    # an L whose arm (edges 4 and 5, the last) is narrower than twice the offset; clockwise in (x, z)
    arm = shapely.Polygon([(-30, 0), (0, 0), (0, -12), (-7, -12), (-7, -4), (-30, -4)])
    inset = shapely.buffer(arm, -2.5, join_style="mitre")
    pieces = fit_pieces(np.array([inset]), np.array([1]), np.array([[30.0, 0.0, 12.0]]), np.array([arm]),
                        insets=np.array([True]))
    np.testing.assert_allclose(pieces.coords[:2] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]],
                               [[-2.5, -2.5], [-2.5, -9.5]])


def test_an_inset_whose_hole_cuts_the_last_edge_off_starts_at_its_end():
    """A hole grown by the offset into the outline's corner between the last edge and edge 0: the inset
    starts where the last edge ends, at the hole's edge, not where edge 0 starts (PRT on massing's
    holes.7039, whose footprint split ran along that hole's edge)."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    square = shapely.Polygon([(0, 0), (30, 0), (30, -30), (0, -30)], [[(1, -1), (1, -10), (10, -10), (10, -1)]])
    inset = shapely.buffer(square, -3, join_style="mitre")
    pieces = fit_pieces(np.array([inset]), np.array([1]), np.array([[30.0, 0.0, 30.0]]), np.array([square]),
                        insets=np.array([True]))
    np.testing.assert_allclose(pieces.coords[:2] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]],
                               [[3, -13], [13, -13]])


def test_an_inset_without_the_last_edge_starts_at_the_end_of_edge_0s_last_run():
    """A hole grown by the offset takes the last edge (and vertex 0), another parts edge 0 in two runs: the
    inset starts where edge 0 itself ends, at its last run's mitre with edge 1, not where its first run
    ends at the hole (measured through PyPRT on massing: a 60 x 40 m lot, holes 10 x 34 m beside its last
    edge and 10 x 7 m beside edge 0, offset 5 m, its first tier setting back edge 0 by 8 m: PRT's moved
    the inset of edge 1; massing's holes.43599, whose split footprint's edges follow that start)."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    # clockwise in (x, z), as the lots' footprints are; edge 0 along z = 0, the last edge along x = 0
    lot = shapely.Polygon([(0, 0), (60, 0), (60, -40), (0, -40)],
                          [[(2, -3), (2, -37), (12, -37), (12, -3)], [(30, -2), (30, -9), (40, -9), (40, -2)]])
    inset = shapely.buffer(lot, -5, join_style="mitre")  # edge 0's runs: x 17 to 25 and 45 to 55
    pieces = fit_pieces(np.array([inset]), np.array([1]), np.array([[60.0, 0.0, 40.0]]), np.array([lot]),
                        insets=np.array([True]))
    np.testing.assert_allclose(pieces.coords[:2] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]],
                               [[55, -5], [55, -35]])


def test_inset_pieces_of_a_hole_across_the_lot_start_at_their_first_edges_end():
    """A hole grown across the inset parts it in two; a run along the last edge ends at the hole in both,
    but only the one nearest vertex 0 (its mitre, in the lower piece) counts from the last: the upper
    piece starts at vertex 2's mitre, where its first outer edge left (edge 1) ends (PRT on massing's
    courtyards and holes.11067). A thin hole's far side nearer the inset's left side than edge 3 does not
    take it over: it lies beyond the side, on the hole's side (the inset of the second lot starts at
    vertex 0's mitre, not vertex 1's)."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    def first_vertices(parent):
        inset = shapely.buffer(parent, -3, join_style="mitre", mitre_limit=1e6)
        pieces = fit_pieces(np.array([inset]), np.array([1]), np.array([[30.0, 0.0, 40.0]]), np.array([parent]),
                            insets=np.array([True]))
        starts = pieces.ring_offsets[pieces.poly_offsets[:-1]]
        return sorted(tuple(np.round(pieces.coords[k] * pieces.extent[i, [0, 2]] + pieces.low[i, [0, 2]], 6))
                      for i, k in enumerate(starts))

    # clockwise in (x, z) as the lots' footprints are
    across = shapely.Polygon([(0, 0), (30, 0), (30, -30), (0, -40)], [[(2, -12), (2, -18), (28, -18), (28, -12)]])
    assert first_vertices(across) == [(3, -3), (27, -27.837722)]
    thin = shapely.Polygon([(0, 0), (30, 0), (30, -30), (0, -30)], [[(4, -10), (4, -20), (5.5, -20), (5.5, -10)]])
    assert first_vertices(thin) == [(3, -3)]


def test_an_inset_edge_comes_from_the_collinear_edge_it_runs_beside():
    """An H's inner sides lie on one line (edges 4 and 11, in one direction): the inset's side beside the
    last edge is moved in from that edge, not from edge 4, so the inset starts at vertex 0's mitre (PRT on
    massing's H.7048), and the near-collinear left sides of a lot (edges 6 and 7, 0.001 m off one line),
    whose mitre GEOS places a little off, are told apart (near_degenerate.7110)."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    h = shapely.Polygon([(15, 41), (20, 41), (20, 0), (15, 0), (15, 18), (5, 18), (5, 0), (0, 0), (0, 41), (5, 41),
                         (5, 23), (15, 23)])
    bent = shapely.Polygon([(0, 30), (10, 30), (10, 0), (0, 0.001), (0.001, 18.107)])

    def start(parent, d):
        inset = shapely.buffer(parent, d, join_style="mitre", mitre_limit=1e6)
        bounds = np.array([[*np.ptp(np.asarray(parent.exterior.coords), axis=0)]])
        pieces = fit_pieces(np.array([inset]), np.array([1]), np.insert(bounds, 1, 0.0, axis=1), np.array([parent]),
                            insets=np.array([True]))
        return np.round(pieces.coords[:2] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]], 6)

    np.testing.assert_allclose(start(h, -2), [[17, 39], [18, 39]])
    np.testing.assert_allclose(start(bent, -3.915)[0], [3.915, 26.085], atol=1e-3)


def test_a_cut_piece_starts_with_its_cut_edge():
    """PRT's half of massing's octagon starts with the cut edge, at the point where the octagon's
    boundary leaves the half, though Sutherland-Hodgman from vertex 0 (in the other half) would
    start at the point where it enters."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    a, b = 11.08655439, 4.592201188
    octagon = shapely.Polygon([(-a, -b), (-a, b), (-b, a), (b, a), (a, b), (a, -b), (b, -a), (-b, -a)])
    half = shapely.intersection(octagon, shapely.box(0, -20, 20, 20))
    pieces = fit_pieces(np.array([half]), np.array([1]), np.array([[2 * a, 0.0, 2 * a]]), np.array([octagon]),
                        cut_sides=np.array([False]))
    ring = pieces.coords[:6] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]]
    np.testing.assert_allclose(ring[:3], [[0, -a], [0, a], [b, a]], atol=1e-9)


def _first_vertices(parent, pieces, cut_sides):
    """The first vertex of each piece of ``parent`` (shapely polygons) as ``fit_pieces`` turns them."""
    from grammarc.geometry.clip import fit_pieces

    fitted = fit_pieces(np.array(pieces), np.ones(len(pieces), np.int8), np.array([[40.0, 0.0, 40.0]] * len(pieces)),
                        np.array([parent] * len(pieces)), cut_sides=np.array(cut_sides))
    starts = fitted.ring_offsets[fitted.poly_offsets[:-1]]
    return [tuple(np.round(fitted.coords[k] * fitted.extent[i, [0, 2]] + fitted.low[i, [0, 2]], 9))
            for i, k in enumerate(starts)]


def test_cut_pieces_start_as_prt_starts_them():
    """PRT's pieces of a split (massing's footprint split, measured through PyPRT on a square and on
    convex and concave lots): the piece with vertex 0 starts there; a piece on the side of vertex 1
    starts where the boundary enters it (edge 0's crossing); a piece on neither side starts with its cut
    edge, where the boundary leaves it."""
    import shapely

    square = shapely.Polygon([(10, 10), (-10, 10), (-10, -10), (10, -10)])
    # a cut across edges 1 and 3: vertices 0 and 1 on one side
    low, high = shapely.box(-20, -20, 20, 0), shapely.box(-20, 0, 20, 20)
    assert _first_vertices(square, [square.intersection(high), square.intersection(low)], [True, False]) == [
        (10, 10), (10, 0)]
    # a cut across edges 0 and 2: vertex 0 on one side, vertex 1 on the other
    left, right = shapely.box(-20, -20, 0, 20), shapely.box(0, -20, 20, 20)
    assert _first_vertices(square, [square.intersection(right), square.intersection(left)], [True, True]) == [
        (10, 10), (0, 10)]


def test_a_cut_through_a_hole_starts_the_side_of_vertex_0_at_the_cut_into_the_hole():
    """A cut that runs through a hole: PRT starts the piece that holds vertices 0 and 1 with the cut edge
    that runs into the hole, where the outline leaves the piece, not at vertex 0 (measured through PyPRT
    on a 40 x 20 m lot whose hole the footprint split of massing crosses, at each orientation); the
    other piece starts with its cut edge as without a hole."""
    import shapely

    lot = shapely.Polygon([(0, 0), (30, 0), (30, -30), (0, -30)],  # clockwise in (x, z)
                          [[(10, -12), (16, -12), (16, -18), (10, -18)]])
    upper, lower = shapely.box(-1, -15, 31, 1), shapely.box(-1, -31, 31, -15)
    assert _first_vertices(lot, [lot.intersection(upper), lot.intersection(lower)], [True, False]) == [
        (30, -15), (0, -15)]
    whole = shapely.Polygon(lot.exterior)  # without the hole vertex 0 starts its piece
    assert _first_vertices(whole, [whole.intersection(upper)], [True]) == [(0, 0)]


def test_an_inset_side_comes_from_the_edge_moved_by_the_offset():
    """A hole's side parallel to the outline's left edge, nearer the inset's left side than that edge:
    the side was moved in from the left edge (by the offset's 3 m), not from the hole's side (1 m off),
    so the inset starts at vertex 0's mitre, where its last edge's run ends (PRT on massing's holes.33921,
    whose footprint split ran along the inset's first edge)."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    lot = shapely.Polygon([(0, 0), (30, 0), (30, -40), (0, -40)],  # clockwise in (x, z)
                          [[(1, -10), (1, -30), (2, -30), (2, -10)]])
    inset = shapely.buffer(lot, -3, join_style="mitre", mitre_limit=1e6)
    vertices = len(shapely.get_coordinates(lot)) - 2
    pieces = fit_pieces(np.array([inset]), np.array([1]), np.array([[30.0, 0.0, 40.0]]), np.array([lot]),
                        insets=np.array([True]), moves=np.full(vertices, 3.0))
    np.testing.assert_allclose(pieces.coords[:2] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]],
                               [[3, -3], [27, -3]])


def test_a_remainder_that_a_hole_notches_starts_at_the_first_run_of_its_edge():
    """A hole that the setback's strip reaches parts the edge moved in from the parent's edge 0 in two
    runs: the remainder starts at the run nearer edge 0's start, as PRT's second tiers on massing's holed
    footprints (courtyard.33584, holes.33347), whichever of the runs GEOS lists first."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    lot = shapely.Polygon([(0, 0), (0, 20), (20, 20), (20, 0)],  # clockwise in (x, z): edge 0 the left side
                          [[(2, 8), (6, 8), (6, 12), (2, 12)]])
    remainder = shapely.box(4, 4, 20, 16).difference(shapely.box(2, 8, 6, 12))
    for turned in range(8):  # GEOS's start anywhere on the ring
        ring = np.asarray(remainder.exterior.coords)[:-1]
        piece = shapely.Polygon(np.roll(ring, turned, axis=0))
        pieces = fit_pieces(np.array([piece]), np.array([1]), np.array([[20.0, 0.0, 20.0]]), np.array([lot]))
        np.testing.assert_allclose(pieces.coords[:2] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]],
                                   [[4, 4], [4, 8]])


def test_a_remainder_starts_at_the_vertex_its_first_moved_edge_steps_back_to():
    """Edge 0 set back 4 m, edge 1 beside it kept and turned by under 15 degrees: the strip steps back to
    vertex 1, which the remainder keeps, and PRT starts the remainder there, not at edge 0's moved copy
    (measured through PyPRT on this lot under massing's tiers; its concave.33911, T.33381 at a reflex
    vertex 1); where edge 0's strip runs out to edge 1 (a turn of 27 degrees), at edge 0's moved copy."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    def first_vertex(lot, remainder):
        pieces = fit_pieces(np.array([remainder]), np.array([1]), np.array([[40.0, 0.0, 20.0]]), np.array([lot]))
        return tuple(np.round(pieces.coords[0] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]], 3))

    stepped = shapely.Polygon([(0, 0), (20, 0), (40, -3.5), (40, -20), (0, -20)])  # clockwise in (x, z)
    assert first_vertex(stepped, shapely.Polygon([(0, -4), (19.653, -4), (20, 0), (36, -2.8), (36, -16),
                                                  (0, -16)])) == (20, 0)
    met = shapely.Polygon([(0, 0), (20, 0), (40, -10), (40, -20), (0, -20)])
    assert first_vertex(met, shapely.Polygon([(28, -4), (36, -8), (36, -16), (0, -16), (0, -4)])) == (0, -4)


def test_strips_start_at_the_first_edge_they_set_back():
    """PRT's shapeL and shapeU: the strips' region starts at the first parent edge it sets back, though it
    holds vertex 0 (an L along the left and top edges, 2 and 3, of the square)."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    square = shapely.Polygon([(10, 10), (10, -10), (-10, -10), (-10, 10)])  # clockwise in (x, z)
    strips = shapely.union(shapely.box(-10, -10, -5, 10), shapely.box(-10, 5, 10, 10))

    def first_vertex(start_edges):
        fitted = fit_pieces(np.array([strips]), np.ones(1, np.int8), np.array([[20.0, 0.0, 20.0]]),
                            np.array([square]), start_edges=start_edges)
        return tuple(np.round(fitted.coords[0] * fitted.extent[0, [0, 2]] + fitted.low[0, [0, 2]], 9))

    assert first_vertex(None) == (10, 10)
    assert first_vertex(np.array([False, False, True, True])) == (-10, -10)


def test_a_remainder_whose_first_edge_steps_starts_after_the_step():
    """massing.convex.33000's first tier (4;0;4;4;0): moved edge 0 steps to the kept edge 1 it turns 11
    degrees from; PRT's remainder starts at vertex 1, the kept edge's, not at moved edge 0 (its second tier's
    setback 3;3;4;4;0 then leaves the 18.3 m^2 that PRT extrudes to the third tier; one vertex sooner,
    nothing)."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    # the tier's top in its plane (x, z), where it winds clockwise: the traced (u, v) with v = -z
    tier = shapely.Polygon([(25.156, -6.763), (13.55, -6.763), (2.785, -4.689), (0.0, 0.0), (12.216, 0.0),
                            (27.76, -1.874)])
    remainder = shapely.from_wkt("POLYGON ((27.2866 -2.7633, 27.7603 -1.8742, 12.2159 0, 11.9756 -4, 7.0281 -4, "
                                 "8.0387 -5.7015, 13.5501 -6.7633, 13.9319 -2.7633, 27.2866 -2.7633))")
    fitted = fit_pieces(np.array([remainder]), np.ones(1, np.int8), np.array([[27.76, 0.0, 6.763]]),
                        np.array([tier]))
    first = fitted.coords[0] * fitted.extent[0, [0, 2]] + fitted.low[0, [0, 2]]
    np.testing.assert_allclose(first, (13.5501, -6.7633), atol=1e-9)


def _setback_remainder(ring, distances):
    """The lot ``ring`` (k, 2) set back by ``distances`` per edge (``geometry.setback``): the ring as an array,
    its remainder (shapely), the ring's lowest corner and its extent."""
    from grammarc.geometry.polygon_edges import polygon_edges
    from grammarc.geometry.setback import setback_regions

    ring = np.asarray(ring, float)
    lot = shapely.Polygon(ring)
    edges = polygon_edges(np.array([lot]))
    _, remainder = setback_regions(np.array([lot]), edges, np.asarray(distances, float),
                                   np.zeros(len(edges.poly), dtype=np.int64), 1)
    return ring, remainder[0], ring.min(axis=0), np.ptp(ring, axis=0)


def _remainder_starts(ring, distances):
    """The first vertex, in (x, y), of the remainder of the lot ``ring`` (counter-clockwise in (x, y)) set back
    by ``distances`` per edge (``geometry.setback``), as ``fit_pieces`` starts it in the lot's plane (x, z)
    with z = -y, where the lot winds clockwise as a face's top does: one per start GEOS may give the ring."""
    from grammarc.geometry.clip import fit_pieces

    ring, remainder, low, size = _setback_remainder(ring, distances)
    kept = np.asarray(remainder.exterior.coords)[:-1]
    firsts = []
    for turned in range(len(kept)):  # GEOS's start anywhere on the ring
        piece = shapely.Polygon((np.roll(kept, turned, axis=0) - low) * (1, -1))
        fitted = fit_pieces(np.array([piece]), np.ones(1, np.int8), np.array([[size[0], 0.0, size[1]]]),
                            np.array([shapely.Polygon((ring - low) * (1, -1))]))
        firsts.append(tuple(np.round((fitted.coords[0] * fitted.extent[0, [0, 2]] + fitted.low[0, [0, 2]])
                                     * (1, -1) + low, 9)))
    return firsts


def test_a_remainder_whose_last_edge_steps_to_edge_0_starts_at_edge_0():
    """The last edge set back 4 m, turning by 12 degrees into the kept edge 0: its strip steps back to
    vertex 0, and PRT starts the remainder at vertex 0, along edge 0 (measured through PyPRT under massing's
    tiers), not at the step from the last edge's moved copy (which comes first in the ring)."""
    ring = [(4.279, -5.065), (9.389, 3.478), (10.586, 5.661), (6.247, 18.281), (-13.91, -11.706), (-3.311, -13.327)]
    assert set(_remainder_starts(ring, [0, 0, 0, 0, 0, 4])) == {ring[0]}


@pytest.mark.parametrize("turn", [-10, -14, 10, 20, 30, 44])
def test_a_remainder_whose_edge_0_steps_from_a_last_edge_kept_whole_starts_at_the_last_edge(turn):
    """Edge 0 set back 3 m steps back to vertex 0 from the kept last edge, 5 m long, from a kept corner,
    turned ``turn`` degrees from edge 0 (a convex vertex 0 below 0, a reflex one above): PRT starts the
    remainder at the last edge's start (measured through PyPRT: massing's second tier's edge 0, set back
    alone, is the last edge's run at each of these turns; concave.43155's 20.7 degrees, reflex), not at
    vertex 0."""
    corner = (-5 * np.cos(np.radians(turn)), -5 * np.sin(np.radians(turn)))
    ring = [(0, 0), (20, 0), (20, 15), (-10, 15), corner]
    assert set(_remainder_starts(ring, [3, 0, 0, 0, 0])) == {tuple(np.round(corner, 9))}


@pytest.mark.parametrize("ring, distances, first", [
    # a 10 x 10 m block with a 1 m arm whose side, edge 1, is set back 3 m: the strip takes the arm and ends
    # on the kept edge 2's line, and PRT starts the remainder where that line leaves the boundary, 1 m before
    # vertex 2, the first vertex it keeps (measured through PyPRT: massing's second tier's edge 0, set back
    # alone, is that 1 m run; so with edge 2 turned 12.5 degrees, and with the arm's side edge 2 after a
    # tip of two edges; holes.43991, 50445)
    ([(-20, 10), (-20, 9), (0, 9), (0, 0), (10, 0), (10, 10)], [0, 3, 0, 0, 0, 0], (0, 10)),
    ([(-20, 10), (-20, 9), (0, 9), (2, 0), (10, 0), (10, 10)], [0, 3, 0, 0, 0, 0], (round(-2 / 9, 9), 10)),
    ([(-20, 11), (-20, 10), (-20, 9), (0, 9), (0, 0), (10, 0), (10, 10)], [0, 0, 3, 0, 0, 0, 0], (0, round(31 / 3, 9))),
    # the arm's side edge 0 or the last edge: PRT starts the remainder at vertex 1 or 0 (measured; U.43550)
    ([(-20, 9), (0, 9), (0, 0), (10, 0), (10, 10), (-20, 10)], [3, 0, 0, 0, 0, 0], (0, 9)),
    ([(0, 9), (0, 0), (10, 0), (10, 10), (-20, 10), (-20, 9)], [0, 0, 0, 0, 0, 3], (0, 9)),
])
def test_a_remainder_that_reaches_its_first_kept_vertex_along_its_edge_starts_at_that_run(ring, distances, first):
    """The strip of a moved edge that covers an arm ends on the next, kept, edge's line; the remainder
    reaches that edge's vertex along the line, from the boundary: PRT counts the run before the vertex,
    but for the vertex after edge 0 or the last edge."""
    assert set(_remainder_starts(ring, distances)) == {first}


@pytest.mark.parametrize("lot, remainder, first", [
    # the last edge (kept) and edge 0 (set back 4 m) on one line: edge 0's strip steps back to vertex 0 and
    # PRT starts the remainder at the run along the last edge that ends there (was: at the step)
    ([(10, 0), (20, 0), (20, -20), (0, -20), (0, 0)],
     [(4, 0), (10, 0), (10, -4), (20, -4), (20, -16), (4, -16)], (4, 0)),
    # a reflex vertex 0: the kept last edge runs on past it beside edge 0's strip, and PRT starts the
    # remainder at vertex 0 (was: at edge 0's moved copy)
    ([(10, -5), (20, -5), (20, -30), (0, -30), (0, 0), (10, 0)],
     [(4, 0), (10, 0), (10, -5), (10, -9), (20, -9), (20, -26), (4, -26)], (10, -5)),
    # the first lot's edge 0 stepping back from a last edge kept whole, from a kept corner: PRT starts the
    # remainder at the run along the last edge too (this lot's second tier setting back its edge 0 by 2 m:
    # PRT's moved the run from (6, 0), 204 m^2 left, where the step's would leave 206.667; and with the last
    # edge turned from edge 0 by 10 degrees: massing.convex.50756's second tier;
    # massing.near_degenerate.43838's second tier, a 6.3 m last edge on edge 0's line)
    ([(10, 0), (20, 0), (20, -20), (0, -20), (0, -4), (6, 0)],
     [(6, 0), (10, 0), (10, -4), (20, -4), (20, -20), (0, -20), (0, -4)], (6, 0)),
    ([(10, 0), (20, 0), (20, -20), (0, -20), (0, -4), (6, 0.7053)],
     [(6, 0.7053), (10, 0), (9.65, -4), (20, -4), (20, -20), (0, -20), (0, -4)], (6, 0.7053)),
])
def test_a_remainder_that_keeps_vertex_0_starts_where_prt_starts_it(lot, remainder, first):
    """massing's tiers (4;0;4;4;0) on these lots, PRT's second tier's edge 0 measured through PyPRT (a
    setback of edge 0 alone); the same on 19 of 19 real lots of Seoul, Bergen, Tartu and Yaroslavl."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    lot = shapely.Polygon(lot)  # clockwise in (x, z)
    ring = np.array(remainder, float)
    for turned in range(len(ring)):  # GEOS's start anywhere on the ring
        pieces = fit_pieces(np.array([shapely.Polygon(np.roll(ring, turned, axis=0))]), np.array([1]),
                            np.array([[20.0, 0.0, 30.0]]), np.array([lot]))
        start = pieces.coords[0] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]]
        np.testing.assert_allclose(start, first, atol=1e-9)


def _flip(points):
    """(x, y) of a map (counter-clockwise) as (x, z) of PRT's ground plane (clockwise)."""
    return [(x, -y) for x, y in points]


ARM_L = [(10, 0), (10, 3), (-10, 3), (-10, -10), (-5, -10), (-5, 0)]  # vertex 0 at the 3 m arm's end


@pytest.mark.parametrize("lot, remainder, first", [
    # the arm's long side set back 4 m covers the 3 m arm: its end (edge 0) and inner side (the last edge)
    # are lost, and PRT starts at the run of the edge before them (was: at the long side's moved line)
    (ARM_L, [(-5, -1), (-10, -1), (-10, -10), (-5, -10)], (-5, -10)),
    # the same L numbered from the arm's inner corner: its inner side is edge 0, the run before it the last
    (ARM_L[5:] + ARM_L[:5], [(-5, -1), (-10, -1), (-10, -10), (-5, -10)], (-5, -10)),
    # the body's side beside the arm set back 3 m too: PRT starts at its moved line
    (ARM_L, [(-8, -1), (-10, -1), (-10, -10), (-8, -10)], (-8, -10)),
    # the arm's short side set back 4 m under the kept long side (both lost with the arm's end, edge 0): PRT
    # starts where the last edge's run ends, with the side of the strip along the body's kept side
    ([(-7, 3), (-7, 0), (2, 0), (2, -6), (12, -6), (12, 3)], [(2, 3), (2, 0), (2, -6), (12, -6), (12, 3)], (2, 3)),
    # a kept chamfer (edge 0) that the moved line of edge 1 passes: no sweep, PRT starts at that moved line
    ([(0, 1), (1, 0), (20, 0), (20, 10), (0, 10)], [(0, 4), (20, 4), (20, 10), (0, 10)], (0, 4)),
    # a 0.6 m jog (edge 1) set back 4 m, with edge 0: the kept 0.6 m edge facing it that edge 0's strip takes
    # lies 4 m beyond the jog's end, beside none of it, so it is no sweep: PRT starts at the jog's moved line
    # (its second tier's edge 0 set back 1 m alone: PRT's terrace the 4.1 m^2 strip along x = 10, measured
    # through PyPRT; was the 4.0 m^2 one along the kept y = 4.1; massing.seoul.47's second tier)
    ([(0, 0.6), (6, 0.6), (6, 0), (14, 0), (14, 4.1), (9, 4.1), (9, 4.7), (4, 4.7), (4, 12), (0, 12)],
     [(10, 0), (14, 0), (14, 4.1), (10, 4.1)], (10, 4.1)),
])
def test_a_remainder_that_lost_edge_0_starts_where_prt_starts_it(lot, remainder, first):
    """massing's first tier set back as the comments say on these lots (map coordinates), PRT's second tier's
    edge 0 measured through PyPRT (a setback of it alone), on every turn of the first two lots' rings (an
    edge 0 left starts the remainder: twelve of twelve); massing.L.50366's and holes.50515's second tiers."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    lot = shapely.Polygon(_flip(lot))
    ring = np.array(_flip(remainder), float)
    for turned in range(len(ring)):  # GEOS's start anywhere on the ring
        pieces = fit_pieces(np.array([shapely.Polygon(np.roll(ring, turned, axis=0))]), np.array([1]),
                            np.array([[30.0, 0.0, 30.0]]), np.array([lot]))
        start = pieces.coords[0] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]]
        np.testing.assert_allclose(start, _flip([first])[0], atol=1e-9)


JOG_BLOCK = [(20, 5.4), (10, 5.4), (10, 6), (6, 6), (6, 6.6), (4, 6.6), (4, 6), (0, 6), (0, 0), (20, 0)]


@pytest.mark.parametrize("moves, remainder, first", [
    # edges 0 and 2 set back 4 m past the kept 0.6 m jog (edge 1), carried along its line: PRT starts at edge
    # 2's moved line (was: at edge 0's, which edge 2's moved line was taken for, the nearer parallel)
    ([4, 0, 4, 4], [(20, 1.4), (10, 1.4), (10, 2), (2, 2), (2, 6), (0, 6), (0, 0), (20, 0)], (10, 2)),
    # edge 3 kept: the remainder runs on through its kept vertex, which is no start
    ([4, 0, 4, 0], [(20, 1.4), (10, 1.4), (10, 2), (6, 2), (6, 6), (6, 6.6), (4, 6.6), (4, 6), (0, 6), (0, 0),
                    (20, 0)], (10, 2)),
    # edge 0 set back 3 m: the jog vanishes and the step left runs against its line: at edge 0's moved line
    ([3, 0, 4, 4], [(20, 2.4), (10, 2.4), (10, 2), (2, 2), (2, 6), (0, 6), (0, 0), (20, 0)], (20, 2.4)),
])
def test_a_remainder_past_a_carried_jog_starts_where_prt_starts_it(moves, remainder, first):
    """massing's first tier set back as ``moves`` says on a 20 x 6 m block with a kept jog after edge 0, PRT's
    second tier's edge 0 measured through PyPRT (a setback of it alone by 1 m; the jog 0.5 to 0.8 m high:
    five of five; massing.tartu.8's second tier), on every turn of the remainder's ring."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    lot = shapely.Polygon(_flip(JOG_BLOCK))
    distances = np.array(moves + [0] * (len(JOG_BLOCK) - len(moves)), float)
    ring = np.array(_flip(remainder), float)
    for turned in range(len(ring)):  # GEOS's start anywhere on the ring
        pieces = fit_pieces(np.array([shapely.Polygon(np.roll(ring, turned, axis=0))]), np.array([1]),
                            np.array([[30.0, 0.0, 30.0]]), np.array([lot]), moves=distances)
        start = pieces.coords[0] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]]
        np.testing.assert_allclose(start, _flip([first])[0], atol=1e-9)


def _arm(turn):
    """A 12 x 11 m block with a 1.4 m wide arm whose end is edge 0 and whose top, the last edge, turns
    ``turn`` degrees off square (its inner end raised)."""
    top = 8.2 + 3.5 * np.tan(np.radians(turn))
    return [(0, 8.2), (0, 6.8), (1.7, 6.8), (1.7, 3), (12, 3), (12, 14), (5, 14), (5, 13), (3.5, 13), (3.5, top)]


@pytest.mark.parametrize("turn, remainder, first", [
    # the arm's end set back 4 m past the top's far end: PRT starts at the run along the edge before the last
    (0, [(4, 8.2), (4, 7), (12, 7), (12, 14), (5, 14), (5, 13), (3.5, 13), (3.5, 8.2)], (3.5, 13)),
    # the top turned 30 degrees: at edge 0's moved line
    (30, [(3.5, 13), (5, 13), (5, 14), (12, 14), (12, 7), (4, 7), (4, 10.5094), (3.5, 10.2207)], (4, 10.5094)),
])
def test_a_remainder_past_a_swept_last_edge_starts_where_prt_starts_it(turn, remainder, first):
    """massing's first tier ("4;0;4;4;0") on ``_arm``, PRT's second tier's edge 0 measured through PyPRT (a
    setback of it alone by 1 m: the run before the last edge at 0, 10 and 20 degrees, edge 0's moved line
    at 30 and 45; massing.seoul.37's second tier), on every turn of the remainder's ring."""
    import shapely

    from grammarc.geometry.clip import fit_pieces

    lot = _arm(turn)
    distances = np.array([4, 0, 4, 4] + [0] * (len(lot) - 4), float)
    ring = np.array(_flip(remainder), float)
    for turned in range(len(ring)):  # GEOS's start anywhere on the ring
        pieces = fit_pieces(np.array([shapely.Polygon(np.roll(ring, turned, axis=0))]), np.array([1]),
                            np.array([[30.0, 0.0, 30.0]]), np.array([shapely.Polygon(_flip(lot))]),
                            moves=distances)
        start = pieces.coords[0] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]]
        np.testing.assert_allclose(start, _flip([first])[0], atol=1e-4)


@pytest.mark.parametrize("ring, distances, first", [
    # edge 0 set back 4 m past the 3 m kept step (edge 1) after it, to the reflex vertex 2: PRT starts there
    ([(0, 0), (8, 0), (8, 3), (14, 3), (14, 20), (0, 20)], [4, 0, 0, 0, 0, 0], (8, 3)),
    ([(0, 0), (8, 0), (7, 3), (14, 3), (14, 20), (0, 20)], [4, 0, 0, 0, 0, 0], (7, 3)),
    ([(0, 0), (8, 0), (9, 3), (14, 3), (14, 20), (0, 20)], [4, 0, 0, 0, 0, 0], (9, 3)),
    # edge 1 set back as far: its strip folds, and it stays (``geometry.setback``); the same start
    ([(0, 0), (8, 0), (8, 3), (14, 3), (14, 20), (0, 20)], [4, 4, 0, 0, 0, 0], (8, 3)),
    # set back 2 m, short of the step: at edge 0's moved line
    ([(0, 0), (8, 0), (8, 3), (14, 3), (14, 20), (0, 20)], [2, 0, 0, 0, 0, 0], (0, 2)),
])
def test_a_remainder_whose_first_edge_ends_past_a_kept_step_starts_at_the_step_s_reflex_end(ring, distances,
                                                                                          first):
    """massing's first tier set back as ``distances`` say on a 14 x 20 m block with a kept step after edge 0,
    PRT's second tier's edges read off its roof (measured through PyPRT, distinct distances per edge), on
    every turn of the remainder's ring (its edges told from the parent edges moved by their distances, as
    ``backend.operations.setbacks`` tells them: edge 0's moved line lies nearer the step's top)."""
    from grammarc.geometry.clip import fit_pieces

    _, remainder, _, _ = _setback_remainder(ring, distances)
    kept = np.array(_flip(np.asarray(remainder.exterior.coords)[:-1]), float)
    lot = shapely.Polygon(_flip(ring))
    for turned in range(len(kept)):  # GEOS's start anywhere on the ring
        pieces = fit_pieces(np.array([shapely.Polygon(np.roll(kept, turned, axis=0))]), np.array([1]),
                            np.array([[30.0, 0.0, 30.0]]), np.array([lot]), moves=np.asarray(distances, float))
        start = pieces.coords[0] * pieces.extent[0, [0, 2]] + pieces.low[0, [0, 2]]
        np.testing.assert_allclose(start, _flip([first])[0], atol=1e-9)


def test_a_piece_that_edge_1_s_step_parts_off_starts_on_the_step():
    """Massing's first tier on massing.hannam.48's face (edges 0 and 1 set back 4 m): edge 1's strip ends
    in a step back to the kept vertex 2 (a 39 degree reflex vertex) that runs across the face to edge 6 and
    parts the remainder. The piece beyond it, without edge 0's or edge 1's moved copy, starts where the step
    enters it, not at vertex 2, as PRT's (measured through PyPRT: its second tier, whose terrace is off by
    4.5 m^2 when numbered from vertex 2)."""
    from grammarc.geometry.clip import fit_pieces

    ring = np.array([(6.725, 0), (7.125, 0), (6.877, 8.812), (10.428, 13.475), (15.356, 13.763),
                     (17.549, 16.933), (12.023, 21.12), (0, 5.061)])
    distances = [4, 4, 0, 0, 0, 0, np.nan, np.nan]
    _, remainder, low, size = _setback_remainder(ring, distances)
    piece = max(remainder.geoms, key=lambda part: part.area)
    kept = np.asarray(piece.exterior.coords)[:-1]
    step = kept[np.argmin(np.abs(kept[:, 0] - 3.599) + np.abs(kept[:, 1] - 9.867))]
    moves = np.nan_to_num(np.asarray(distances, float))
    for turned in range(len(kept)):  # GEOS's start anywhere on the ring
        fitted = fit_pieces(np.array([shapely.Polygon((np.roll(kept, turned, axis=0) - low) * (1, -1))]),
                            np.ones(1, np.int8), np.array([[size[0], 0.0, size[1]]]),
                            np.array([shapely.Polygon((ring - low) * (1, -1))]), moves=moves)
        first = (fitted.coords[0] * fitted.extent[0, [0, 2]] + fitted.low[0, [0, 2]]) * (1, -1) + low
        np.testing.assert_allclose(first, step, atol=1e-6)
