"""backend/operations/texture.py in derivations: setupProjection and projectUV as the reference's examples
use them, the UV edits, and splits in texture space (``split(u|v, uvSpace|unitSpace, uvSet)``).

The lots are map rectangles (``derivations``): scope x = world +x, y up, z = world +z. A quad record's
texture coordinates are ``uv[:, :, :3] @ p + uv[:, :, 3]`` at the unit square's corners p.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import LOT_ZOO
from derivations import names, rect, run

#: The unit square's corners: the quad's origin, its first column's end, the far corner, the second's.
CORNERS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
#: A 12 x 8 lot extruded 6 high: its front face is 12 wide (world x) and 6 high.
FRONT = "Lot --> extrude(6) comp(f){ front : Front }\n"


def corner_uv(r, row=None):
    """(n, 4, 2): the texture coordinates at the corners of each record (or of the rows ``row``)."""
    maps = r["uv"].astype(float) if row is None else r["uv"][row].astype(float)
    return np.einsum("nij,cj->nci", maps[..., :3], CORNERS) + maps[:, None, :, 3]


def corner_xyz(r, row=None):
    x = r["xform"].astype(float) if row is None else r["xform"][row].astype(float)
    return np.einsum("nij,cj->nci", x[..., :3], CORNERS) + x[:, None, :, 3]


def test_setup_projection_and_project_uv_tile_the_facade(write):
    """The reference's standard facade texture: tiles 1.5 m wide and 1 m high from the scope's origin."""
    r = run(write, FRONT + "Front --> setupProjection(0, scope.xy, 1.5, 1) projectUV(0) F.\n", [rect(12, 8)])
    uv, xyz = corner_uv(r)[0], corner_xyz(r)[0]
    origin = xyz[0]
    along, up = xyz[:, 0] - origin[0], xyz[:, 1] - origin[1]
    np.testing.assert_allclose(uv[:, 0], along / 1.5, atol=1e-5)
    np.testing.assert_allclose(uv[:, 1], up / 1.0, atol=1e-5)
    assert uv[:, 0].max() == pytest.approx(8.0)  # 12 m of 1.5 m tiles


def test_texture_coordinates_stay_continuous_across_a_split(write):
    """Set up once on the facade, projected on each tile: the tiles' u runs on from one to the next."""
    r = run(write, FRONT + "Front --> setupProjection(0, scope.xy, 2, 3) split(x){ ~3 : T }*\n"
            "T --> projectUV(0) T.\n", [rect(12, 8)])
    uv = corner_uv(r)
    order = np.argsort(uv[:, 0, 0])
    starts, ends = uv[order, 0, 0], uv[order, 1, 0]
    np.testing.assert_allclose(starts, [0, 1.5, 3, 4.5], atol=1e-5)
    np.testing.assert_allclose(ends[:-1], starts[1:], atol=1e-5)  # no seam between the tiles
    np.testing.assert_allclose(uv[:, 3, 1], 2.0, atol=1e-5)  # 6 m of 3 m tiles


@pytest.mark.parametrize("width, u_end", [("'1", 1.0), ("'0.5", 2.0), ("~5", 2.0), ("~2", 6.0), ("-3", -4.0)])
def test_relative_floating_and_mirrored_texture_sizes(write, width, u_end):
    """``'0.5``: two tiles across the scope; ``~5`` on 12 m: two whole tiles; a negative width mirrors."""
    r = run(write, FRONT + f"Front --> setupProjection(0, scope.xy, {width}, 1) projectUV(0) F.\n", [rect(12, 8)])
    uv = corner_uv(r)[0]
    assert (uv[0, 0], uv[1, 0]) == (pytest.approx(0, abs=1e-6), pytest.approx(u_end, abs=1e-5))


def test_world_projection_ignores_the_scope(write):
    """``world.xz`` with offsets: u = (x - 1) / 4, v = (z - 2) / 4 in the world, whatever the scope."""
    r = run(write, "Lot --> r(0, 30, 0) setupProjection(0, world.xz, 4, 4, 1, 2) projectUV(0) L.\n",
            [rect(12, 8)])
    uv, xyz = corner_uv(r)[0], corner_xyz(r)[0]
    np.testing.assert_allclose(uv[:, 0], (xyz[:, 0] - 1) / 4, atol=1e-5)
    np.testing.assert_allclose(uv[:, 1], (xyz[:, 2] - 2) / 4, atol=1e-5)


@pytest.mark.parametrize("edit, u, v", [
    ("translateUV(0, 0.5, -1)", [0.5, 12.5], [-1, 5]),
    ("scaleUV(0, 0.5, 2)", [0, 6], [0, 12]),
    ("rotateUV(0, 90)", [0, -6], [0, 12]),  # counter-clockwise: (u, v) -> (-v, u)
    ("tileUV(0, 3, 0)", [0, 4], [0, 6]),
    ("tileUV(0, ~5, '0.5)", [0, 2], [0, 2]),
    ("normalizeUV(0, uv, collectiveAllFaces)", [0, 1], [0, 1]),
    ("normalizeUV(0, uvUniform, separatePerFace)", [0, 1], [0, 0.5]),
    ("normalizeUV(0, v, collectiveAllFaces)", [0, 12], [0, 1]),
])
def test_uv_edits(write, edit, u, v):
    """The facade in metres (1 m tiles: u 0..12, v 0..6), then one edit; u and v at its origin and far
    corner."""
    r = run(write, FRONT + f"Front --> setupProjection(0, scope.xy, 1, 1) projectUV(0) {edit} F.\n",
            [rect(12, 8)])
    uv = corner_uv(r)[0]
    np.testing.assert_allclose(uv[[0, 2], 0], u, atol=1e-5)
    np.testing.assert_allclose(uv[[0, 2], 1], v, atol=1e-5)


def test_projection_waits_for_project_uv_and_delete_uv_removes_it(write):
    """A shape set up but not projected keeps its lot's coordinates (metres along the lot's x and z, from
    its scope's origin at world z = -8); one projected and deleted has none."""
    r = run(write, FRONT + "Front --> setupProjection(0, scope.xy, 2, 2) split(x){ 6 : A. | ~1 : B }\n"
            "B --> projectUV(0) deleteUV(0) B.\n", [rect(12, 8)])
    a = names(r).index("A")
    xyz, uv = corner_xyz(r, [a])[0], corner_uv(r, [a])[0]
    np.testing.assert_allclose(uv, np.stack([xyz[:, 0], xyz[:, 2] + 8], axis=1), atol=1e-5)
    assert np.isnan(r["uv"][names(r).index("B")]).all()


def test_polygons_get_texture_coordinates_per_vertex(write):
    """The L lot's footprint (a polygon of the mesh table) projected from above: u, v are x, z in metres."""
    r = run(write, "Lot --> setupProjection(0, world.xz, 2, 2) projectUV(0) L.\n", [LOT_ZOO["concave_L"]])
    mesh = r["mesh"]
    np.testing.assert_allclose(mesh.uv, mesh.vertices[:, [0, 2]] / 2, atol=1e-5)


# ------------------------------------------------------------------------------------------- splits


def test_split_u_in_uv_space_measures_texture_units(write):
    """2 m tiles: 1.5 units of u are 3 m; the rest of the 12 m facade goes to B."""
    r = run(write, FRONT + "Front --> setupProjection(0, scope.xy, 2, 1) projectUV(0) "
            "split(u, uvSpace, 0){ 1.5 : A. | ~1 : B. }\n", [rect(12, 8)])
    widths = dict(zip(names(r), np.linalg.norm(r["xform"][:, :, 0], axis=1)))
    assert widths == {"A": pytest.approx(3), "B": pytest.approx(9)}


def test_split_along_a_turned_texture_keeps_the_scope_axes(write):
    """u turned to run up the facade: split(u, unitSpace) cuts floors, 2 m then the rest, and each floor's
    scope keeps the facade's axes (x along the facade, 12 wide)."""
    r = run(write, FRONT + "Front --> setupProjection(0, scope.xy, 1, 1) projectUV(0) rotateUV(0, -90) "
            "split(u, unitSpace, 0){ 2 : A. | ~1 : B. }\n", [rect(12, 8)])
    x = r["xform"].astype(float)
    assert sorted(zip(names(r), np.round(np.linalg.norm(x[:, :, 1], axis=1), 6))) == [("A", 2), ("B", 4)]
    np.testing.assert_allclose(np.linalg.norm(x[:, :, 0], axis=1), 12, atol=1e-5)
    np.testing.assert_allclose(x[:, :, 0] / 12, [[1, 0, 0]] * 2, atol=1e-6)
    a = names(r).index("A")
    assert x[a, 1, 3] == pytest.approx(0, abs=1e-9)  # -90 degrees: (u, v) -> (v, -u), u grows upwards


def test_lot_texture_space_splits_the_lot_like_a_street(write):
    """A lot without projection has u along its scope's x and v along its depth, in metres: the street
    rules' split(v, unitSpace, 0) cut across it."""
    r = run(write, "Lot --> split(v, unitSpace, 0){ 5 : A. | ~1 : B. }\n", [rect(30, 20)])
    sizes = {n: tuple(np.round(np.linalg.norm(x[:, :2], axis=0), 6)) for n, x in zip(names(r), r["xform"])}
    assert sizes == {"A": (5, 30), "B": (15, 30)}  # a quad's columns: the lot's depth (z), then its x


def test_split_repeats_in_texture_space_and_queries_start_it(write):
    """v starts 3 below 0 (the offset moves v's 0 up the lot); ``-geometry.vMin`` brings the first cut to
    v = 0, as the street rules use it; then nine lanes of about 2 m fill the 17 m left."""
    r = run(write, "Lot --> setupProjection(0, scope.xz, 1, 1, 0, 3) projectUV(0) "
            "split(v, uvSpace, 0){ -geometry.vMin : S. | { ~2 : L. }* }\n", [rect(30, 20)])
    depths = sorted((n, round(float(np.linalg.norm(x[:, 0])), 6)) for n, x in zip(names(r), r["xform"]))
    assert depths == [("L", round(17 / 9, 6))] * 9 + [("S", 3)]


def test_split_of_a_surface_across_which_u_does_not_change_fails_its_lot(write):
    """u along world x on the right side face (normal world +x): nothing to split along."""
    r = run(write, "Lot --> extrude(6) comp(f){ right : R }\nR --> setupProjection(0, world.xy, 1, 1) "
            "projectUV(0) split(u, unitSpace, 0){ 1 : A. | ~1 : B. }\n", [rect(12, 8)])
    (bad,) = r["bad"]
    assert "`split(u, ...)` of a shape whose texture set 0 has no u across its surface" in bad.reason
