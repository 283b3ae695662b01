"""Measuring baked meshes as PRT's records are, comparing them, and the surface distance."""

import math

import numpy as np
import pytest
import trimesh
from conftest import needs_earcut, needs_kit, needs_scipy

from grammarc.conform import (
    compare,
    find_record,
    measure,
    surface_distance,
)
from grammarc.io.bake import bake
from grammarc.model.records import MeshChunk


def box(size, origin=(0, 0, 0)):
    """A baked record of one cube instance: the box of ``size`` at ``origin``."""
    xform = np.concatenate([np.diag(size), np.asarray(origin, float)[:, None]], axis=1)
    return bake({"assets": ["builtin:cube"], "asset": np.zeros(1, np.int32), "xform": xform[None]})


def courtyard_prism(height: float):
    """The mesh table of the courtyard footprint (40 x 40, a 20 x 20 hole) extruded by ``height``:
    bottom and top with holes, and the 8 side walls, as grammarc emits a holed prism."""
    out = [(0, 0), (0, 40), (40, 40), (40, 0)]  # (x, z) counter-clockwise from +y, as the kit's file
    hole = [(10, 10), (30, 10), (30, 30), (10, 30)]

    def ring(points, y):
        return [[x, y, z] for x, z in points]

    faces = [[ring(out[::-1], 0), ring(hole[::-1], 0)], [ring(out, height), ring(hole, height)]]
    for points in (out, hole):  # the hole runs the other way round: its walls face into the courtyard
        for (x0, z0), (x1, z1) in zip(points, points[1:] + points[:1]):
            faces.append([[[x0, 0, z0], [x1, 0, z1], [x1, height, z1], [x0, height, z0]]])
    rings = [np.array(r, float) for f in faces for r in f]
    mesh = MeshChunk(
        vertices=np.concatenate(rings).astype(np.float32),
        ring_offsets=np.concatenate([[0], np.cumsum([len(r) for r in rings])]).astype(np.int64),
        face_offsets=np.concatenate([[0], np.cumsum([len(f) for f in faces])]).astype(np.int64),
        lot=np.zeros(len(faces), np.int32), symbol=np.zeros(len(faces), np.int32),
    )  # fmt: skip
    return bake({"assets": ["builtin:cube"], "asset": np.zeros(0, np.int32), "xform": np.zeros((0, 3, 4)),
                 "mesh": mesh})


def test_measure_and_compare_synthetic():
    measured = measure(box([30, 5, 20]))
    assert measured == {
        "bbox_min": [0, 0, 0], "bbox_max": [30, 5, 20], "bbox_size": [30, 5, 20], "surface_area": 1700.0,
        "n_triangles": 12, "n_faces": 6, "face_sizes": {4: 6},
    }  # fmt: skip
    expected = {"bbox_min": [0, 0, 0], "bbox_max": [30, 5, 20], "surface_area": 1700.0, "n_faces": 6,
                "n_triangles": 12}
    verdict = compare(measured, expected, faces_tol=0)
    assert verdict.passed and verdict and verdict.faces_ok
    assert verdict.bbox_deviation == 0 and verdict.area_rel_error == 0 and verdict.face_difference == 0
    assert verdict.summary.startswith("PASS ")

    taller = compare(measure(box([30, 5.01, 20])), expected)
    assert not taller.passed and not taller.bbox_ok and not taller.area_ok
    assert taller.bbox_deviation == pytest.approx(0.01, abs=1e-6)
    assert taller.area_rel_error == pytest.approx(0.5 * 2 * 0.01 / 1700 * 100, rel=1e-3)
    assert taller.summary.startswith("FAIL bbox 0.01 m > 0.0001")

    more_faces = dict(measured, n_faces=9)
    assert compare(more_faces, expected).passed  # face counts are reported, not checked, by default
    strict = compare(more_faces, expected, faces_tol=2)
    assert not strict.passed and strict.faces_ok is False and strict.face_difference == 3
    assert "faces 9 / 6 (+3 > 2)" in strict.summary


def test_measure_empty_and_unknown_polygons():
    empty = trimesh.Trimesh(np.zeros((0, 3)), np.zeros((0, 3), int), process=False)
    measured = measure(empty)
    assert all(math.isnan(x) for x in measured["bbox_min"]) and measured["surface_area"] == 0
    assert measured["n_faces"] is None and measured["n_triangles"] == 0
    verdict = compare(measured, {"bbox_min": [0, 0, 0], "bbox_max": [1, 1, 1], "surface_area": 6})
    assert not verdict.passed and verdict.face_difference is None and verdict.area_rel_error == 1
    plain = trimesh.creation.box(bounds=[[0, 0, 0], [1, 2, 3]])
    assert measure(plain)["n_faces"] is None and measure(plain, polygons=6)["n_faces"] == 6
    assert compare({"bbox_min": [0] * 3, "bbox_max": [0] * 3, "surface_area": 1},
                   {"bbox_min": [0] * 3, "bbox_max": [0] * 3, "surface_area": 0}).area_rel_error == math.inf


@needs_kit
def test_box_conforms_to_extrude_color(prt_reference):
    verdict = compare(measure(box([30, 5, 20])), find_record(prt_reference, "extrude_color", "rect_30x20"),
                      faces_tol=0)
    assert verdict.passed, verdict.summary
    assert verdict.triangle_difference == 0


@needs_kit
@needs_earcut
def test_holed_prism_counts_faces_as_prt(prt_reference):
    # PRT returns a face with holes as its outline plus a face per hole: 12 faces, 32 triangles, 3600 m2.
    mesh = courtyard_prism(5)
    assert mesh.metadata["n_polygons"] == 12 and mesh.metadata["n_holes"] == 2
    expected = find_record(prt_reference, "extrude_color", "courtyard_40x40")
    verdict = compare(measure(mesh), expected, faces_tol=0)
    assert verdict.passed, verdict.summary
    assert verdict.triangle_difference == 0
    assert mesh.volume == pytest.approx(1200 * 5)  # and every face points out


@needs_scipy
def test_surface_distance():
    # Exact but for points whose own triangle is not among the candidates: far below the 0.1 m spacing
    # of the sites, and far below the kit's 1e-4 m.
    a = box([10, 10, 10])
    assert surface_distance(a, a, n=2000) == pytest.approx(0, abs=1e-5)
    # The same box triangulated differently: still on each other's surface.
    subdivided = trimesh.creation.box(bounds=[[0, 0, 0], [10, 10, 10]]).subdivide().subdivide()
    assert surface_distance(a, subdivided, n=2000) == pytest.approx(0, abs=1e-5)
    # Two parallel squares 1 m apart, each over the other: every point is 1 m from the other square.
    square = trimesh.Trimesh([[0, 0, 0], [10, 0, 0], [10, 10, 0], [0, 10, 0]], [[0, 1, 2], [0, 2, 3]])
    lifted = square.copy()
    lifted.apply_translation([0, 0, 1])
    assert surface_distance(square, lifted, n=2000) == pytest.approx(1, abs=1e-5)
    # A box 0.5 m taller: the only excess is its top, lifted by 0.5, and the sides' extra band.
    assert 0 < surface_distance(a, box([10, 10.5, 10]), n=4000) < 0.5
    with pytest.raises(ValueError, match="no area"):
        surface_distance(a, trimesh.Trimesh(np.zeros((0, 3)), np.zeros((0, 3), int)))


@needs_scipy
def test_surface_distance_is_fast():
    import time

    a = trimesh.creation.icosphere(subdivisions=5)  # 20,480 triangles
    b = a.copy()
    b.apply_scale(1.01)
    started = time.perf_counter()
    distance = surface_distance(a, b)
    assert time.perf_counter() - started < 5  # ~0.7 s on the 2-core development machine
    assert distance == pytest.approx(0.01, rel=0.05)

