"""Roof meshes: hip, gable, shed and pyramid against their analytic volumes, closed and outward-facing."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from test_skeleton import COURTYARD, L_SHAPE, OCTAGON, RECT, random_polygon

from grammarc.geometry.roofs import ENVELOPE, GABLE, GAMBREL, HIP, MANSARD, PYRAMID, SHED, roof_meshes

TAN30 = np.tan(np.radians(30))


def roof(kind, rings, value=30.0, *, plane=2, by_height=False, overhang=0.0, index=0, cap=np.inf, even=False,
         edges=None, required=True):
    """The roof mesh of one polygon given in real units: faces as lists of (V, 3) rings in (a, b, h).
    ``edges``: an envelope's (base height, angle) under the edge from each vertex; else sides of None, as
    the backend gives the other roofs. Not ``required``: None where the roof could not be made."""
    pts = np.concatenate([np.asarray(r, dtype=float) for r in rings])
    low, size = pts.min(axis=0), np.ptp(pts, axis=0)
    ring_offsets = np.cumsum([0] + [len(r) for r in rings]).astype(np.int64)
    edge_base, edge_angle = (None, None) if edges is None else np.asarray(edges, float).T.copy()
    verts, ro, fo, mo, ok = roof_meshes(
        kind, (pts - low) / size, ring_offsets, np.array([0, len(rings)]), np.array([plane], np.int8),
        size[:1], size[1:], np.array([value]), by_height, np.array([overhang]), np.array([index]),
        np.array([cap]), np.array([even]), edge_base, edge_angle)
    if not required and not ok.all():
        return None
    assert ok.all() and list(mo) == [0, len(fo) - 1]
    return [[verts[ro[r]:ro[r + 1]] + [*low, 0] for r in range(fo[f], fo[f + 1])] for f in range(len(fo) - 1)]


def volume(faces):
    """Signed volume enclosed by the faces (positive when they face outward), by fans of tetrahedra."""
    return sum(np.dot(ring[0], np.cross(ring[j], ring[j + 1])) / 6
               for rings in faces for ring in rings for j in range(1, len(ring) - 1))


def unmatched_edges(faces):
    """Directed edges without their reverse in another face: none for a closed, consistently wound mesh."""
    edges = Counter()
    for rings in faces:
        for ring in rings:
            keys = [tuple(np.round(p, 6)) for p in ring]
            for a, b in zip(keys, keys[1:] + keys[:1]):
                edges[(a, b)] += 1
    return sum(n for (a, b), n in edges.items() if edges[(b, a)] != n)


def test_hip_roof_on_a_rectangle_has_the_analytic_volume_and_ridge():
    faces = roof(HIP, RECT)
    length, width = 10.0, 4.0
    height = width / 2 * TAN30
    # a gable prism less the two hip wedges
    assert volume(faces) == pytest.approx(length * width * height / 2 - width**2 * height / 6)
    ridge = {tuple(p) for f in faces for r in f for p in np.round(r, 9) if abs(p[2] - height) < 1e-9}
    assert ridge == {(2.0, 2.0, round(height, 9)), (8.0, 2.0, round(height, 9))}
    assert len(faces) == 5 and unmatched_edges(faces) == 0


def test_gable_roof_turns_the_hip_ends_into_vertical_gables():
    faces = roof(GABLE, RECT)
    height = 2 * TAN30
    assert volume(faces) == pytest.approx(10 * 4 * height / 2)
    normals = [np.cross(f[0][1] - f[0][0], f[0][2] - f[0][1]) for f in faces[1:]]
    assert sum(abs(n[2]) < 1e-9 for n in normals) == 2 and unmatched_edges(faces) == 0


def test_gable_roof_of_a_square_has_one_ridge_and_an_octagon_keeps_its_hips():
    square = roof(GABLE, [[(0, 0), (6, 0), (6, 6), (0, 6)]])
    assert volume(square) == pytest.approx(6 * 6 * 3 * TAN30 / 2) and unmatched_edges(square) == 0
    octagon_hip, octagon_gable = roof(HIP, OCTAGON), roof(GABLE, OCTAGON)
    assert volume(octagon_gable) == pytest.approx(volume(octagon_hip))


def test_shed_rises_from_its_edge_and_pyramid_from_the_vertex_average():
    shed = roof(SHED, RECT, 45.0, index=1)  # edge 1 is x = 10: the roof rises towards x = 0
    assert volume(shed) == pytest.approx(4 * 10 * 10 / 2) and unmatched_edges(shed) == 0
    assert max(p[2] for f in shed for r in f for p in r) == pytest.approx(10.0)
    pyramid = roof(PYRAMID, RECT, 45.0)
    assert volume(pyramid) == pytest.approx(40 * 2 / 3) and unmatched_edges(pyramid) == 0


@pytest.mark.parametrize("kind", [HIP, GABLE, SHED, PYRAMID])
def test_by_height_gives_the_roof_that_height(kind):
    faces = roof(kind, L_SHAPE, 3.5, by_height=True)
    assert max(p[2] for f in faces for r in f for p in r) == pytest.approx(3.5)


def test_overhang_is_measured_on_the_roof_plane():
    faces = roof(HIP, RECT, overhang=2.0)
    eaves = min(p[2] for f in faces for r in f for p in r)
    assert eaves == pytest.approx(-2.0 * np.sin(np.radians(30)))
    assert faces[1][0][0][:2] == pytest.approx([-2 * np.cos(np.radians(30))] * 2)


def test_faces_of_a_store_plane_one_polygon_face_out_in_scope_axes():
    """Plane 1 maps (a, b, h) onto scope (x, z, y), a mirror: its (counter-clockwise around +y) input
    runs clockwise in (a, b), and the faces keep facing out of the roof after the mirror."""
    flipped = [[(p[0], -p[1]) for p in RECT[0]][::-1]]
    faces = roof(HIP, flipped, plane=1)
    assert volume(faces) < 0  # in (a, b, h); positive in (x, y, z) = (a, h, b)
    assert unmatched_edges(faces) == 0


def test_collinear_and_repeated_vertices_do_not_change_the_roof():
    noisy = [[(0, 0), (5, 0), (10, 0), (10, 0), (10, 4), (0, 4)]]
    assert volume(roof(HIP, noisy)) == pytest.approx(volume(roof(HIP, RECT)))


def test_courtyard_hip_roof_is_a_ring_of_constant_section():
    faces = roof(HIP, COURTYARD)
    assert volume(faces) == pytest.approx(10 * 5 * TAN30 / 2 * 120)  # section times centre line
    assert unmatched_edges(faces) == 0


def test_gambrel_and_mansard_break_at_a_third_of_the_inset_with_two_slopes():
    """A 10 x 4 gambrel: 70 degrees up to 2/3 m in, 30 degrees to the ridge 2 m in; a prism of that
    section. The mansard has the same planes on its long sides and hips at its ends."""
    steep, knee = np.tan(np.radians(70)), 2 / 3
    ridge = knee * steep + (2 - knee) * TAN30
    section = 2 * (knee * knee * steep / 2 + (2 - knee) * knee * steep + (2 - knee) ** 2 * TAN30 / 2)
    gambrel, mansard = roof(GAMBREL, RECT), roof(MANSARD, RECT)
    assert volume(gambrel) == pytest.approx(10 * section)
    assert max(p[2] for f in gambrel for r in f for p in r) == pytest.approx(ridge)
    assert volume(mansard) < volume(gambrel) and unmatched_edges(gambrel) == unmatched_edges(mansard) == 0
    assert len(gambrel) == 1 + 2 * 4  # every plane in two: below and above the break


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 2**32 - 1), st.booleans(), st.sampled_from([HIP, GABLE, MANSARD, GAMBREL]))
def test_roofs_of_random_concave_polygons_are_closed_and_face_out(seed, hole, kind):
    rings = random_polygon(seed, hole)
    faces = roof(kind, rings)
    assert volume(faces) > 0
    if kind == GAMBREL:
        # a gambrel moves the break points of irregular gable ends too, which can fold the planes next
        # to them over each other (1 footprint in ~700 here): only its volume is checked
        return
    # the planes cover the footprint once, seen from above
    covered = sum((r[:, 0] * np.roll(r[:, 1], -1) - np.roll(r[:, 0], -1) * r[:, 1]).sum() / 2
                  for f in faces[1:] for r in f)
    assert covered == pytest.approx(shapely.Polygon(rings[0], rings[1:]).area, rel=1e-9)
    if kind in (HIP, GABLE):
        assert unmatched_edges(faces) == 0
    # two-slope roofs cut non-monotone planes at the break into parts that may meet along the break in
    # zero-width bridges, whose edges have no twin


def planar(ring):
    """Whether a ring's points lie in one plane (its best fit's smallest singular value is ~0)."""
    centred = ring - ring.mean(axis=0)
    return np.linalg.svd(centred, compute_uv=False)[-1] < 1e-7


def test_even_hip_roof_levels_the_ridge_of_a_trapezoid():
    """As the reference's trapezoid shows: a hip roof's ridge slopes where the eaves are not parallel;
    with ``even`` its nodes take their mean height, the ridge is level and the faces by it are no longer
    planar. The mesh stays closed."""
    trapezoid = [[(0, 0), (12, 0), (12, 4), (0, 8)]]
    plain, even = roof(HIP, trapezoid, 45.0), roof(HIP, trapezoid, 45.0, even=True)
    tops = [{round(p[2], 9) for f in faces[1:] for r in f for p in r if p[2] > 1e-9} for faces in (plain, even)]
    assert len(tops[0]) == 2 and len(tops[1]) == 1
    assert tops[1].pop() == pytest.approx(np.mean(sorted(tops[0])))
    assert unmatched_edges(even) == 0 and not all(planar(f[0]) for f in even)
    # a rectangle's ridge is level already: even changes nothing
    assert np.allclose(np.concatenate([r for f in roof(HIP, RECT) for r in f]),
                       np.concatenate([r for f in roof(HIP, RECT, even=True) for r in f]))


def test_even_gable_roof_keeps_vertical_gables():
    trapezoid = [[(0, 0), (12, 0), (12, 4), (0, 8)]]
    faces = roof(GABLE, trapezoid, 30.0, even=True)
    heights = {round(p[2], 9) for f in faces for r in f for p in r}
    assert len(heights) == 2 and unmatched_edges(faces) == 0


def envelope(rings, edges, cap=np.inf, required=True):
    return roof(ENVELOPE, rings, 45.0, cap=cap, edges=edges, required=required)


def random_sides(seed, hole):
    """A random outline and an envelope's (base, angle) per edge: walls of one height under the sloped
    sides (bases that differ move the slopes below the highest base as the vertices' paths run, and a
    short edge may vanish there: that is refused), any height under the vertical ones."""
    rings = random_polygon(seed, hole)
    rng = np.random.default_rng(seed)
    n = sum(len(r) for r in rings)
    angle = rng.choice([30.0, 45.0, 60.0, 90.0], n)
    return rings, np.stack([np.where(angle < 90, 0.5, rng.uniform(0, 3, n)), angle], axis=1)


def test_envelope_with_a_slope_per_side_is_the_analytic_gable_profile():
    """A 10 x 4 rectangle (front b = 0, back b = 4): front 3 m walls, back 1 m walls, both at 45
    degrees, the short sides vertical: the profile (0, 0) (4, 0) (4, 1) (1, 4) (0, 3), 11 m2, times 10."""
    faces = envelope([[(0, 0), (10, 0), (10, 4), (0, 4)]], [(3, 45), (0, 90), (1, 45), (0, 90)])
    assert volume(faces) == pytest.approx(110.0)
    assert unmatched_edges(faces) == 0 and all(planar(r) for f in faces for r in f)
    assert max(p[2] for f in faces for r in f for p in r) == pytest.approx(4.0)
    # walls and slopes are faces of their own: bottom, 2 walls and 2 slopes, 2 gable ends
    assert len(faces) == 7


@pytest.mark.parametrize("rings", [RECT, L_SHAPE, COURTYARD])
def test_envelope_with_one_slope_all_round_by_edges_is_the_hip_envelope(rings):
    """Sides that differ take the weighted skeleton, equal ones the hip envelope lifted on its walls:
    one side a millionth of a degree off gives the same solid the other way."""
    n = sum(len(r) for r in rings)
    hip = roof(ENVELOPE, rings, 40.0, overhang=1.0, cap=2.0, edges=[(1.0, 40.0)] * n)
    weighted = envelope(rings, [(1.0, 40.0)] * (n - 1) + [(1.0, 40.000001)], cap=2.0)
    assert volume(weighted) == pytest.approx(volume(hip), rel=1e-5)
    assert unmatched_edges(weighted) == 0


@pytest.mark.parametrize("kind", [HIP, GABLE, PYRAMID, ENVELOPE])
def test_sides_of_none_are_the_same_all_round(kind):
    """Sides of None (the roofs other than envelopes, compiled without the weighted envelope) give the
    roof that sides of one base height and angle all round give."""
    cap = 2.0 if kind == ENVELOPE else np.inf
    same = [(0.0, 30.0)] * sum(map(len, COURTYARD))
    plain = roof(kind, COURTYARD, cap=cap)
    sided = roof(kind, COURTYARD, cap=cap, edges=same)
    assert len(plain) == len(sided)
    for a, b in zip(plain, sided):
        assert all(np.array_equal(p, q) for p, q in zip(a, b))


def test_envelope_of_vertical_sides_is_the_prism_up_to_the_cap():
    faces = envelope(L_SHAPE, [(0, 90)] * 6, cap=5.0)
    area = shapely.Polygon(L_SHAPE[0]).area
    assert volume(faces) == pytest.approx(5 * area) and unmatched_edges(faces) == 0


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31), hole=st.booleans())
def test_envelopes_with_random_sides_are_closed_and_face_out(seed, hole):
    """Where the weighted skeleton closes (``test_envelopes_with_random_sides_are_nearly_always_made``
    counts where it does not: the lot is then reported), the envelope is a closed solid facing out."""
    rings, edges = random_sides(seed, hole)
    faces = envelope(rings, edges, required=False)
    assume(faces is not None)
    assert unmatched_edges(faces) == 0 and volume(faces) > 0
    # cut flat, non-monotone faces may leave zero-width bridges along the cut (as two-slope roofs do)
    assert 0 < volume(envelope(rings, edges, cap=2.0)) < volume(faces)


def test_envelopes_with_random_sides_are_nearly_always_made():
    """The weighted skeleton with walls (speed 0) among sloped sides does not close on a few random
    outlines (1 of these 400): those lots are reported, never given a broken mesh."""
    made = [envelope(*random_sides(seed, hole), required=False) is not None
            for seed in range(200) for hole in (False, True)]
    assert sum(made) >= 0.99 * len(made)
