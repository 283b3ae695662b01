"""Street frames of lots and edges that lie along their streets."""

from __future__ import annotations

import numpy as np

from grammarc.geometry.footprint import lot_scopes
from grammarc.geometry.streets import ALONG, along_street, lot_streets
from grammarc.io.lots import lots_from_polygons

RECT = [np.array([[0, 0], [30, 0], [30, 20], [0, 20]], float)]


def streets_of(street):
    lots = lots_from_polygons([RECT], street=[street])
    _, axes, _, _ = lot_scopes(lots)
    return lot_streets(lots.vertices, lots.ring_offsets, lots.lot_offsets, lots.street, axes), axes


def test_the_street_frame_faces_the_street_and_falls_back_to_the_lots_frame():
    streets, _ = streets_of([0, 0, 5, 0])  # north edge (map y = 20: world z = -20)
    # z towards the street, x to the right of someone in the street looking at the lot (as object.right)
    np.testing.assert_allclose(streets.axes[0], [[-1, 0, 0], [0, 1, 0], [0, 0, -1]], atol=1e-12)
    assert streets.lot_offsets.tolist() == [0, 1]
    streets, axes = streets_of([0, 3, 5, 0])  # a corner: z between east (+x) and north (-z), by length
    z = np.array([20.0, 0, -30.0]) / np.hypot(20, 30)
    np.testing.assert_allclose(streets.axes[0, 2], z, atol=1e-12)
    streets, axes = streets_of(None)
    np.testing.assert_array_equal(streets.axes, axes)
    assert streets.lot_offsets.tolist() == [0, 0]


def test_an_edge_lies_along_a_street_when_both_ends_are_on_it_and_it_faces_out():
    streets, _ = streets_of([0, 0, 5, 0])
    north = np.array([0.0, 0, -1])
    start = np.array([[5.0, 0, -20], [5.0, 3, -20], [5.0, 0, -20 + 2 * ALONG], [5.0, 0, -20], [0.0, 0, 0]])
    end = np.array([[20.0, 0, -20], [20.0, 3, -20], [20.0, 0, -20], [20.0, 0, -20], [30.0, 0, 0]])
    normal = np.array([north, north, north, -north, -north])
    got = along_street(streets, np.zeros(5, dtype=np.int64), start, end, normal)
    # on it, on it higher up (a facade's bottom edge is at its own height: no), off by 2 cm, facing in, south
    assert got.tolist() == [True, False, False, False, False]
