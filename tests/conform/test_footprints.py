"""Random footprints by class: valid, oriented as GeoJSON wants, of the class's make, and reproducible."""

import numpy as np
import pytest

from grammarc.conform.footprints import CLASSES, footprint


@pytest.mark.parametrize("kind", list(CLASSES))
def test_footprints_are_valid_oriented_polygons(kind):
    for seed in range(60):
        polygon = footprint(kind, seed)
        assert polygon.is_valid and polygon.geom_type == "Polygon", (kind, seed)
        assert polygon.exterior.is_ccw and not any(h.is_ccw for h in polygon.interiors)


def test_a_footprint_is_a_function_of_class_and_seed():
    a, b = footprint("concave", 7), footprint("concave", 7)
    assert np.asarray(a.exterior.coords).tobytes() == np.asarray(b.exterior.coords).tobytes()
    assert not footprint("concave", 8).equals(a)
    assert not footprint("convex", 7).equals(a)


def test_classes_make_what_they_say():
    def reflex(polygon):
        ring = np.asarray(polygon.exterior.coords)[:-1]
        edges = np.roll(ring, -1, axis=0) - ring
        cross = edges[:, 0] * np.roll(edges, -1, axis=0)[:, 1] - edges[:, 1] * np.roll(edges, -1, axis=0)[:, 0]
        return int((cross < 0).sum())

    seeds = range(40)
    assert all(reflex(footprint("convex", s)) == 0 for s in seeds)
    assert all(reflex(footprint("concave", s)) > 0 for s in seeds)
    assert all(reflex(footprint("L", s)) == 1 and len(footprint("L", s).exterior.coords) == 7 for s in seeds)
    assert all(reflex(footprint("U", s)) == 2 and reflex(footprint("H", s)) == 4 for s in seeds)
    assert all(len(footprint("courtyard", s).interiors) == 1 for s in seeds)
    assert all(2 <= len(footprint("holes", s).interiors) <= 4 for s in seeds)
    assert all(2 <= footprint("tiny", s).area <= 10 + 1e-9 for s in seeds)
    thin = [footprint("thin", s) for s in seeds]
    assert all(p.length ** 2 / p.area > 20 for p in thin)  # long and narrow
    far = [footprint("far", s).centroid for s in seeds]
    assert all(p.x > 2e5 and p.y > 3e6 for p in far)


def test_acute_corners_reach_ten_degrees():
    def smallest_angle(polygon):
        ring = np.asarray(polygon.exterior.coords)[:-1]
        a, b = np.roll(ring, 1, axis=0) - ring, np.roll(ring, -1, axis=0) - ring
        cos = (a * b).sum(1) / np.linalg.norm(a, axis=1) / np.linalg.norm(b, axis=1)
        return np.degrees(np.arccos(np.clip(cos, -1, 1))).min()

    angles = [smallest_angle(footprint("acute", s)) for s in range(60)]
    assert min(angles) < 15 and max(angles) <= 35 + 1e-6 and min(angles) >= 10 - 1e-6


def test_near_degenerate_lots_have_near_collinear_or_near_duplicate_vertices():
    def shortest_edge_or_flattest_corner(polygon):
        ring = np.asarray(polygon.exterior.coords)[:-1]
        edges = np.roll(ring, -1, axis=0) - ring
        length = np.linalg.norm(edges, axis=1)
        following = np.roll(edges, -1, axis=0)
        height = np.abs(edges[:, 0] * following[:, 1] - edges[:, 1] * following[:, 0]) / np.maximum(
            np.linalg.norm(edges + following, axis=1), 1e-300)
        return min(length.min(), height.min())

    assert all(shortest_edge_or_flattest_corner(footprint("near_degenerate", s)) < 0.02 for s in range(30))
