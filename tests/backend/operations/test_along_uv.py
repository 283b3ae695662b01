"""backend/operations/along_uv.py in derivations: ``insertAlongUV`` lays the asset along u (one copy per unit),
its depth across v in [0, 1] and its height along the scope's y or the face's normal, cut to the faces.

The lots are map rectangles (``derivations``): scope x = world +x, y up, z = world +z, origin (0, 0, -h); a
lot's texture set 0 is metres along its x (u) and z (v).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from derivations import face_area, mesh_faces, names, rect, run

#: A 10 x 4 lot whose u runs 0..5 along it and v 0..1 across it: five copies, each 2 m long and 4 m deep.
FIVE = "Lot --> scaleUV(0, 0.5, 0.25) insertAlongUV(0, \"builtin:cube\", 2) Fence.\n"


def vertices(r) -> np.ndarray:
    return r["mesh"].vertices.astype(float)


def test_one_copy_per_unit_of_u_fills_the_face(write):
    r = run(write, FIVE, [rect(10, 4)])
    faces = mesh_faces(r)
    assert len(r["xform"]) == 0 and len(faces) == 5 * 12  # a mesh, not instances: the cube's triangles
    v = vertices(r)
    np.testing.assert_allclose(v.min(axis=0), [0, 0, -4], atol=1e-5)
    np.testing.assert_allclose(v.max(axis=0), [10, 2, 0], atol=1e-5)
    assert set(np.round(v[:, 0], 5)) == {0, 2, 4, 6, 8, 10}
    assert sum(face_area(f) for f in faces) == pytest.approx(5 * 2 * (2 * 2 + 2 * 4 + 2 * 4), rel=1e-5)
    # every face looks out of its copy, though this texture space mirrors the asset: the closed copies'
    # signed volume is theirs
    volume = sum(np.dot(f[0][0], np.cross(f[0][1], f[0][2])) for f in faces) / 6
    assert volume == pytest.approx(5 * 2 * 2 * 4, rel=1e-5)
    assert set(names(r)) == set() and set(np.asarray(r["mesh"].symbol)) == {r["symbols"].tolist().index("Fence")}


def test_the_last_copy_is_cut_where_the_face_ends(write):
    """u runs 0..2.5: two whole copies 4 m long and half of a third."""
    r = run(write, "Lot --> scaleUV(0, 0.25, 0.25) insertAlongUV(0, \"builtin:cube\", 2) Fence.\n", [rect(10, 4)])
    v = vertices(r)
    assert v[:, 0].max() == pytest.approx(10, abs=1e-5)
    assert set(np.round(v[:, 0], 5)) == {0, 4, 8, 10}


def test_a_triangle_takes_the_asset_cut_at_its_edges(write):
    """The hypotenuse of the map triangle (0, 0), (10, 0), (0, 10) is x - z = 10 in the world."""
    triangle = [np.array([[0, 0], [10, 0], [0, 10]], float)]
    r = run(write, "Lot --> scaleUV(0, 0.1, 0.1) insertAlongUV(0, \"builtin:cube\", 1) Fence.\n", [triangle])
    v = vertices(r)
    assert (v[:, 0] - v[:, 2]).max() == pytest.approx(10, abs=1e-4)
    assert v[:, 1].min() == pytest.approx(0, abs=1e-6) and v[:, 1].max() == pytest.approx(1, abs=1e-6)
    assert sum(face_area(f) for f in mesh_faces(r)) > 0


def test_vertex_normal_lifts_the_asset_off_a_facade(write):
    """The 12 x 6 front face with u, v across it in [0, 1]: one copy standing 0.5 m out of the wall."""
    r = run(write, "Lot --> extrude(6) comp(f){ front : F }\n"
            "F --> setupProjection(0, scope.xy, '1, '1) projectUV(0) "
            "insertAlongUV(0, \"builtin:cube\", 0.5, vertex.normal, alignPosition) Relief.\n", [rect(12, 8)])
    v = vertices(r)
    extent = v.max(axis=0) - v.min(axis=0)
    np.testing.assert_allclose(sorted(extent), [0.5, 6, 12], atol=1e-5)
    assert len(mesh_faces(r)) == 12


def test_keep_position_puts_the_assets_own_origin_on_the_face(write, tmp_path):
    """An asset from y = -1 to 1 in its own units, 2 m high: its origin on the lot, half of it below."""
    (tmp_path / "post.obj").write_text("".join(f"v {x} {y} {z}\n" for x in (0, 1) for y in (-1, 1) for z in (0, 1))
                                       + "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n")
    for mode, low in (("alignPosition", 0.0), ("keepPosition", -1.0)):
        r = run(write, f"Lot --> normalizeUV(0, uv, collectiveAllFaces) "
                f"insertAlongUV(0, \"post.obj\", 2, scope.y, {mode}) Post.\n", [rect(2, 2)])
        v = vertices(r)
        assert (v[:, 1].min(), v[:, 1].max()) == (pytest.approx(low, abs=1e-5), pytest.approx(low + 2, abs=1e-5))


def test_the_scope_fits_the_inserted_geometry(write):
    r = run(write, "Lot --> scaleUV(0, 0.5, 0.25) insertAlongUV(0, \"builtin:cube\", 2) "
            "report(\"sy\", scope.sy) report(\"sx\", scope.sx) Fence.\n", [rect(10, 4)])
    totals = r["reports"].table(r["reports"].totals())
    assert totals["sy_sum"] == pytest.approx(2) and totals["sx_sum"] == pytest.approx(10)


def test_a_shape_without_texture_coordinates_fails_its_lot(write):
    r = run(write, "Lot --> projectUV(1) insertAlongUV(1, \"builtin:cube\", 2) Fence.\n", [rect(10, 4)])
    (bad,) = r["bad"]
    assert "`insertAlongUV` of a shape without texture coordinates of set 1" in bad.reason


def test_copy_uv_gives_a_set_the_coordinates_of_another(write):
    """Set 1 has none of its own; after copyUV(0, 1) it splits as set 0 would: 0.5 of u is 5 m."""
    r = run(write, "Lot --> scaleUV(0, 0.1, 0.25) copyUV(0, 1) split(u, uvSpace, 1){ 0.5 : A. | ~1 : B. }\n",
            [rect(10, 4)])
    areas = {n: round(float(np.linalg.norm(np.cross(x[:, 0], x[:, 1]))), 5) for n, x in zip(names(r), r["xform"])}
    assert areas == {"A": 20.0, "B": 20.0}
    r = run(write, "Lot --> scaleUV(0, 0.1, 0.25) split(u, uvSpace, 1){ 0.5 : A. | ~1 : B. }\n", [rect(10, 4)])
    assert len(r["bad"]) == 1


def test_a_fence_of_posts_and_panels_along_a_strip(write, tmp_path):
    """As ESRI.lib's fences do: the strip split along u into posts and panels, each normalized and given its
    asset along u (the props example's GLB assets), the posts 1.2 m high, the panels 1 m."""
    for name in ("post.glb", "panel.glb"):
        shutil.copy(Path(__file__).parents[3] / "examples" / "props" / "assets" / "fence" / name, tmp_path / name)
    r = run(write, "Lot --> split(u, unitSpace, 0){ { 0.2 : Post | ~2 : Panel }* | 0.2 : Post }\n"
            "Post --> normalizeUV(0, uv, collectiveAllFaces) insertAlongUV(0, \"post.glb\", 1.2) Post.\n"
            "Panel --> normalizeUV(0, uv, collectiveAllFaces) insertAlongUV(0, \"panel.glb\", 1) Panel.\n",
            [rect(22.2, 0.2)])
    mesh = r["mesh"]
    face_symbol = np.array([str(s) for s in r["symbols"][mesh.symbol]])
    v = vertices(r)
    vertex_symbol = np.repeat(face_symbol, np.diff(mesh.ring_offsets[mesh.face_offsets]))
    posts, panels = v[vertex_symbol == "Post"], v[vertex_symbol == "Panel"]
    assert posts[:, 1].max() == pytest.approx(1.2, abs=1e-5) and panels[:, 1].max() == pytest.approx(1, abs=1e-5)
    np.testing.assert_allclose(v.min(axis=0), [0, 0, -0.2], atol=1e-5)
    np.testing.assert_allclose(v.max(axis=0), [22.2, 1.2, 0], atol=1e-5)
    # ten panels of 2 m between eleven posts: each post's asset within its 0.2 m
    cells = np.floor(posts[:, 0] / 2.2 + 1e-6)
    assert set(cells.astype(int)) == set(range(11))
    assert (posts[:, 0] - 2.2 * cells <= 0.2 + 1e-5).all()


def test_a_texture_scale_of_billions_of_copies_fails_its_lot_before_they_are_made(write):
    """``scaleUV`` by 1e9 lays 3e10 copies along a 30 m lot (1e30: more than int64 counts): its lot fails
    with the count, the copies counted before any is made; the other lots derive."""
    text = 'attr k = 0.5\nLot --> scaleUV(0, k, 0.25) insertAlongUV(0, "builtin:cube", 2) Fence.\n'
    r = run(write, text, [rect(30, 4)] * 3, lot_attrs={"k": np.array([0.5, 1e9, 1e30])})
    assert np.unique(r["mesh"].lot).tolist() == [0]
    assert [(b.index, b.reason.split(" in rule")[0]) for b in r["bad"]] == [
        (1, "more than 2,000,000 shapes (30,000,000,000)"), (2, "more than 2,000,000 shapes (beyond counting)")]
