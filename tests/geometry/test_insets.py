"""Mitred insets: GEOS's buffer, and the nearly collapsing insets it finds empty where PRT keeps them."""

import numpy as np
import shapely

from grammarc.geometry.insets import mitred_insets

#: Candler's roof on fuzz lot candler.tiny.44289 (seed 44000), in its scope: 1.64 m across at its widest
#: inscribed circle (radius 0.8217), so ``offset(-0.8)`` leaves a sliver. GEOS (3.14) finds that buffer empty
#: (its 7-coordinate ring fails the inverted-ring check); PRT keeps the inside face: its roof pipes stand on
#: it (pipe rims 0.7 m high, whose cubes' corners grammarc now matches within 1e-4 m).
ROOF = shapely.from_wkt("POLYGON ((0.31 0.143, 0 1.739, 0.712 1.89, 3.777 0.367, 2.814 0, 0.751 0, 0.31 0.143))")


def _corners(polygon):
    return np.array(sorted(map(tuple, np.asarray(polygon.exterior.coords)[:-1])))


def test_a_nearly_collapsing_inset_is_the_sliver_its_edges_leave():
    (inset,) = mitred_insets(np.array([ROOF]), np.array([-0.8]))
    assert not shapely.is_empty(inset)
    # where the lines of the roof's left, diagonal and bottom edges meet, moved 0.8 in
    expected = [(0.98553707, 0.86075826), (0.99733849, 0.8), (1.10781159, 0.8)]
    assert np.allclose(_corners(inset), expected, atol=1e-7)
    assert shapely.is_valid(inset)


def test_insets_geos_finds_are_its_own_and_a_collapsed_one_stays_empty():
    polygons = np.array([ROOF, ROOF, shapely.box(0, 0, 4, 2)])
    distance = np.array([-0.7, -0.83, -0.5])
    insets = mitred_insets(polygons, distance)
    plain = shapely.buffer(polygons, distance, join_style="mitre", mitre_limit=1e6)
    assert shapely.equals_exact(insets[0], plain[0], tolerance=0)
    assert shapely.is_empty(insets[1])  # deeper than the inscribed circle's 0.8217
    assert shapely.equals_exact(insets[2], plain[2], tolerance=0)


def test_outward_offsets_are_geos_buffers():
    (grown,) = mitred_insets(np.array([ROOF]), np.array([0.3]))
    assert shapely.equals_exact(grown, shapely.buffer(ROOF, 0.3, join_style="mitre", mitre_limit=1e6), tolerance=0)
