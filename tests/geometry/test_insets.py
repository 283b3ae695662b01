"""Mitred insets: GEOS's buffer, and the nearly collapsing insets it finds empty where PRT keeps them."""

import numpy as np
import shapely

from grammarc.geometry.insets import SKELETON_VERTICES, mitred_insets

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


#: Massing's fuzz lot concave.57869 (seed 57000), whose ``offset(-2.407)`` closes the arm between its reflex
#: corners (-2.08, 6.53) and (-3.89, 6.12). GEOS's mitred buffer cuts the first corner's whole mitre out of
#: the inset, a 3 cm notch (3.7e-4 m^2) past the line of the edge moved in from the second corner: three
#: edges too many, and the massing tiers' per-edge setbacks went to the wrong edges (15 % of the model's
#: area off). PRT's inset (its border faces' inner corners, in its OBJ to the millimetre) has 12 corners.
ARM_LOT = shapely.from_wkt(
    "POLYGON ((-3.891736 6.122762, -10.165971 10.086173, -6.887528 5.601032, -9.70778 -0.483269, "
    "-10.539257 -9.342018, -7.216078 -6.859712, -4.832137 -12.575148, -1.411381 -10.546682, 6.299642 -3.682399, "
    "11.960409 1.49145, 10.174947 10.272838, 6.84416 9.023083, -2.080788 6.533831, -2.613202 11.996206, "
    "-3.891736 6.122762))")
PRT_ARM_INSET = [(-7.636, -4.169), (-6.183, -3.084), (-3.677, -9.092), (-2.839, -8.595), (4.687, -1.895),
                 (9.33, 2.348), (8.378, 7.028), (7.592, 6.733), (-1.87, 4.094), (-2.271, 2.252), (-4.991, 3.97),
                 (-7.35, -1.12)]


def test_an_arm_the_offset_closes_leaves_no_notch_of_its_reflex_corner():
    (inset,) = mitred_insets(np.array([ARM_LOT]), np.array([-2.407]))
    geos = shapely.buffer(ARM_LOT, -2.407, join_style="mitre", mitre_limit=1e6)
    assert len(geos.exterior.coords) - 1 == 15  # GEOS's, with the notch
    assert np.allclose(_corners(inset), sorted(PRT_ARM_INSET), atol=1e-3)
    assert shapely.area(shapely.difference(geos, inset)) < 1e-9  # it holds GEOS's
    assert abs(inset.area - geos.area - 3.7e-4) < 1e-5


def test_an_inset_whose_skeleton_adds_nothing_stays_geos_own():
    # an L: its reflex corner's mitre is the wavefront's too
    ell = shapely.from_wkt("POLYGON ((0 0, 10 0, 10 4, 4 4, 4 10, 0 10, 0 0))")
    (inset,) = mitred_insets(np.array([ell]), np.array([-1.0]))
    plain = shapely.buffer(ell, -1.0, join_style="mitre", mitre_limit=1e6)
    assert shapely.equals_exact(inset, plain, tolerance=0)


#: Massing's random concave lot 1407 (``footprint("concave", 1407)``) moved in 2 m: a spike's reflex roots end
#: early in the wavefront. PRT's inside face (``offset(-2)``, measured through PyPRT: 413.532 m^2, 12 corners,
#: listed here as its OBJ gives them) is the wavefront's; GEOS's mitred buffer leaves 408.260 m^2.
SPIKED_LOT = shapely.from_wkt(
    "POLYGON ((-13.520627 1.04132, -0.917625 -20.413516, 11.010054 -6.822771, 12.808712 -4.937492, "
    "19.915755 2.272079, 17.222742 2.152431, 13.146719 2.518362, -3.2589 21.699995, -4.114495 8.533476, "
    "-8.722696 11.379524, -13.614815 7.074535, -18.639879 3.755079, -15.909876 2.031615, -23.86759 3.624048, "
    "-13.520627 1.04132))")
PRT_SPIKED_INSET = [(-12.221, 2.778), (-0.595, -17.014), (9.534, -5.472), (11.373, -3.545), (15.19, 0.327),
                    (12.156, 0.599), (-1.582, 16.662), (-2.334, 5.083), (-8.513, 8.9), (-12.397, 5.482),
                    (-14.954, 3.793), (-14.082, 3.243)]


def test_the_inset_of_a_spiked_lot_is_prts_wavefront():
    (inset,) = mitred_insets(np.array([SPIKED_LOT]), np.array([-2.0]))
    assert abs(shapely.buffer(SPIKED_LOT, -2.0, join_style="mitre", mitre_limit=1e6).area - 408.260) < 1e-3
    assert abs(inset.area - 413.532) < 0.02  # (PRT's corners to the millimetre)
    assert np.allclose(_corners(inset), sorted(PRT_SPIKED_INSET), atol=1e-3)


def test_a_face_of_many_vertices_keeps_geos_inset():
    # the spiked lot with a point every 5 cm along its edges: past SKELETON_VERTICES, no skeleton is taken
    dense = shapely.segmentize(SPIKED_LOT, 0.05)
    assert shapely.get_num_coordinates(dense) > SKELETON_VERTICES
    (inset,) = mitred_insets(np.array([dense]), np.array([-2.0]))
    assert abs(inset.area - 408.260) < 1e-3
