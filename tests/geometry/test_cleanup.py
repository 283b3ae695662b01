"""cleanupGeometry on ragged meshes: repeated, close and collinear vertices, slivers, small, degenerate and
duplicate faces, coplanar faces joined (T-junctions too), each component's share, and the bounds a
random polygon's cleanup keeps."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from grammarc.geometry.cleanup import cleanup_meshes
from grammarc.geometry.convexify import convex_parts
from grammarc.ragged import offsets_from_counts

SQUARE = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]


def ragged(*meshes):
    """Ragged arrays of meshes given as lists of faces, each a list of rings of (x, y, z) points."""
    coords, ring_counts, face_counts = [], [], []
    for mesh in meshes:
        for face in mesh:
            face_counts.append(len(face))
            for ring in face:
                ring_counts.append(len(ring))
                coords.append(np.asarray(ring, float).reshape(-1, 3))
    return (np.concatenate(coords) if coords else np.zeros((0, 3)), offsets_from_counts(ring_counts),
            offsets_from_counts(face_counts), offsets_from_counts([len(m) for m in meshes]))


def faces_of(result):
    """The cleaned meshes back as lists of faces of rings (arrays)."""
    coords, ring_offsets, face_offsets, mesh_offsets = result
    return [[[coords[ring_offsets[r]:ring_offsets[r + 1]] for r in range(face_offsets[f], face_offsets[f + 1])]
             for f in range(mesh_offsets[m], mesh_offsets[m + 1])] for m in range(len(mesh_offsets) - 1)]


def clean(meshes, tolerance, component="all", **options):
    return faces_of(cleanup_meshes(*ragged(*meshes), np.full(len(meshes), float(tolerance)), component, **options))


def flat(points):
    """A ring in the plane z = 0 from (x, y) points."""
    return [[x, y, 0.0] for x, y in points]


def area(face):
    def ring(r):
        return np.linalg.norm(np.cross(r, np.roll(r, -1, axis=0)).sum(axis=0)) / 2
    return ring(face[0]) - sum(ring(h) for h in face[1:])


def test_repeated_vertices_go_at_tolerance_zero():
    [[face]] = clean([[[SQUARE[:2] + [SQUARE[1], [1, 1e-12, 0]] + SQUARE[2:]]]], 0, "edges")
    np.testing.assert_allclose(face[0], SQUARE)


@pytest.mark.parametrize("component, left", [("vertices", 4), ("all", 4), ("edges", 8), ("faces", 8)])
def test_collinear_vertices_go_with_vertices_and_all(component, left):
    ring = flat([(0, 0), (0.5, 0), (1, 0), (1, 0.5), (1, 1), (0.5, 1), (0, 1), (0, 0.5)])
    [[face]] = clean([[[ring]]], 0, component)
    assert len(face[0]) == left and area(face) == pytest.approx(1)


@pytest.mark.parametrize("tolerance, left", [(0.1, 4), (0.01, 5)])
def test_an_edge_shorter_than_the_merge_distance_collapses(tolerance, left):
    ring = flat([(0, 0), (10, 0), (10.05, 0.05), (10, 10), (0, 10)])
    [[face]] = clean([[[ring]]], tolerance, "edges")
    assert len(face[0]) == left


@pytest.mark.parametrize("tolerance, left", [(1.0, 4), (0.4, 5)])
def test_a_vertex_that_bends_its_edge_less_than_the_angle_goes(tolerance, left):
    bend = 5 * np.tan(np.radians(2.5))  # the edges turn by 5 degrees: within 10 (tolerance 1), not 4
    ring = flat([(0, 0), (5, -bend), (10, 0), (10, 10), (0, 10)])
    [[face]] = clean([[[ring]]], tolerance, "vertices")
    assert len(face[0]) == left


def test_a_fine_arc_loses_every_other_vertex_not_all():
    # a 40-gon turns by 9 degrees at each vertex: collinear at tolerance 1 (10 degrees), but each vertex
    # is measured from the last one kept, so a 20-gon (18 degree turns) stays
    angles = np.radians(np.arange(40) * 9)
    [[face]] = clean([[[flat(np.stack([np.cos(angles), np.sin(angles)], 1) * 20)]]], 1, "vertices")
    assert len(face[0]) == 20


def test_a_sliver_collapses_and_its_face_goes():
    sliver = flat([(0, 0), (10, 0), (10, 0.05), (0, 0.05)])
    sliver_faces, square_faces = clean([[[sliver]], [[SQUARE]]], 0.1, "vertices")
    assert sliver_faces == [] and np.array_equal(square_faces[0][0], SQUARE)


@pytest.mark.parametrize("component, kept", [("faces", False), ("all", False), ("vertices", True)])
def test_small_faces_go_with_faces_and_all(component, kept):
    small = (np.array(SQUARE) * 0.5).tolist()  # 0.25 m^2, edges longer than the merge distance 0.3
    assert bool(clean([[[small]]], 0.3, component)[0]) == kept
    assert clean([[[small]]], 0.3, component, keep_small=np.array([True]))[0]


def test_a_hole_that_collapses_goes_and_the_outline_stays():
    hole = flat([(5, 5), (5, 5.01), (5.01, 5.01), (5.01, 5)])
    [[face]] = clean([[[flat([(0, 0), (10, 0), (10, 10), (0, 10)]), hole]]], 0.05, "vertices")
    assert len(face) == 1 and area(face) == pytest.approx(100)


def test_duplicate_faces_either_way_round_go_with_faces():
    turned = SQUARE[2:] + SQUARE[:2]
    back = SQUARE[::-1]
    mesh = [[SQUARE], [turned], [back], [(np.array(SQUARE) + [0, 0, 1]).tolist()]]
    assert len(clean([mesh], 0, "faces")[0]) == 2
    assert len(clean([mesh], 0, "vertices")[0]) == 4


def test_degenerate_faces_go():
    line = [[0, 0, 0], [1, 0, 0], [2, 0, 0]]  # three distinct vertices, no area
    repeated = [[0, 0, 1], [1, 0, 1], [1, 0, 1]]  # two distinct vertices
    assert len(clean([[[SQUARE], [line], [repeated]]], 0, "faces")[0]) == 1
    assert len(clean([[[SQUARE], [line], [repeated]]], 0, "edges")[0]) == 2  # only the ring without 3 goes


def test_coplanar_faces_that_share_an_edge_join():
    right = (np.array(SQUARE) + [1, 0, 0]).tolist()
    [[face]] = clean([[[SQUARE], [right]]], 0, "edges")
    assert len(face) == 1 and area(face) == pytest.approx(2)
    assert len(face[0]) == 6  # the shared edge's ends stay: only `vertices` removes collinear ones
    [[face]] = clean([[[SQUARE], [right]]], 0, "all")
    assert len(face[0]) == 4


@pytest.mark.parametrize("degrees, tolerance, joined", [(90, 1, False), (5, 1, True), (5, 0.3, False)])
def test_faces_join_when_their_normals_meet_within_the_angle(degrees, tolerance, joined):
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    # 10 m squares: no vertex within the merge distance of another
    folded = (np.array([[1, 0, 0], [1 + c, 0, s], [1 + c, 1, s], [1, 1, 0]]) * 10).tolist()
    big = (np.array(SQUARE) * 10).tolist()
    assert len(clean([[[big], [folded]]], tolerance, "edges")[0]) == (1 if joined else 2)


@pytest.mark.parametrize("polygon, rings, vertices", [
    (shapely.Polygon([(0, 0), (30, 0), (30, 10), (10, 10), (10, 20), (0, 20)]), 1, [6]),
    (shapely.Polygon([(0, 0), (40, 0), (40, 40), (0, 40)], [[(10, 10), (10, 30), (30, 30), (30, 10)]]), 2,
     [4, 4]),
])
def test_convex_parts_join_back_across_their_t_junctions(polygon, rings, vertices):
    """convexify's cuts end on a neighbour's longer edge: the pieces share no edge until it is split."""
    parts, _ = convex_parts(np.array([polygon]))
    mesh = [[flat(np.asarray(p.exterior.coords)[:-1])] for p in shapely.orient_polygons(parts)]
    [[face]] = clean([mesh], 0, "all")
    assert len(face) == rings and [len(r) for r in face] == vertices
    assert area(face) == pytest.approx(polygon.area)


def test_meshes_of_a_batch_are_cleaned_each_as_alone():
    right = (np.array(SQUARE) + [1, 0, 0]).tolist()
    sliver = flat([(0, 0), (10, 0), (10, 0.05), (0, 0.05)])
    meshes = [[[SQUARE], [right]], [[sliver]], [[SQUARE], [SQUARE]]]
    together = faces_of(cleanup_meshes(*ragged(*meshes), np.array([0.0, 0.1, 0.0]), "all"))
    alone = [clean([m], t)[0] for m, t in zip(meshes, [0.0, 0.1, 0.0])]
    assert [[[r.tolist() for r in f] for f in m] for m in together] == \
        [[[r.tolist() for r in f] for f in m] for m in alone]
    assert faces_of(cleanup_meshes(*ragged(), np.zeros(0), "all")) == []


def noisy_star(seed):
    """A star-shaped polygon with repeated vertices and points put on (or just off) its edges."""
    rng = np.random.default_rng(seed)
    k = int(rng.integers(5, 25))
    angles = np.sort(rng.uniform(0, 2 * np.pi, k)) + np.arange(k) * 1e-3
    points = np.stack([np.cos(angles), np.sin(angles)], 1) * rng.uniform(5, 15, k)[:, None]
    ring = []
    for p, q in zip(points, np.roll(points, -1, axis=0)):
        ring.append(p)
        if rng.random() < 0.3:
            ring.append(p)
        if rng.random() < 0.3:
            ring.append(p + (q - p) * rng.uniform(0.1, 0.9) + rng.normal(0, 1e-3, 2))
    return np.array(ring)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.integers(0, 2**32 - 1), st.floats(0, 0.2), st.sampled_from(["vertices", "edges", "faces", "all"]))
def test_cleanup_never_adds_vertices_and_keeps_the_area_within_its_limits(seed, tolerance, component):
    ring = noisy_star(seed)
    before = shapely.Polygon(ring)
    [faces] = clean([[[flat(ring)]]], tolerance, component)
    assert sum(len(r) for f in faces for r in f) <= len(ring)
    # a vertex moves by at most the merge distance d; a collinear one cuts off a triangle whose sides are
    # at most the perimeter P long and meet within the angle
    d, sine, perimeter = tolerance, np.sin(np.radians(10 * tolerance)), before.length
    bound = d * perimeter + len(ring) * d * d + sine * perimeter ** 2 + 1e-9 * before.area
    if faces:
        assert abs(area(faces[0]) - before.area) <= bound
    else:
        assert component in ("faces", "all") and before.area <= tolerance + bound
