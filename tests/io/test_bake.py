"""Baking records into meshes: mirrored and flat transforms, polygons with holes, OBJ assets, the size
guard, and the mesh writers."""

import importlib.util
import tracemalloc

import numpy as np
import pytest
import trimesh
from writers_city import COLOURED, PNG, RED, SEE_THROUGH_GREEN, TEXTURED, textured_city

from grammarc.errors import AssetError, UsageError
from grammarc.io import OutputOptions, writer_for
from grammarc.io import bake as bake_module
from grammarc.io.bake import BakedWriter, bake, count_triangles
from grammarc.io.npz import InstanceWriter, read_instances
from grammarc.model.assets import builtin_mesh
from grammarc.model.records import MeshChunk, TerminalChunk

needs_earcut = pytest.mark.skipif(importlib.util.find_spec("mapbox_earcut") is None,
                                  reason="mapbox-earcut not installed")
ASSETS = ["builtin:cube", "builtin:quad", "builtin:cylinder"]


def xform(linear, offset) -> np.ndarray:
    """(3, 4) float32 from a (3, 3) linear part (columns: scope axes times sizes) and an offset."""
    return np.concatenate([np.asarray(linear, float), np.asarray(offset, float)[:, None]], axis=1).astype(
        np.float32
    )


def rotation_y(degrees: float) -> np.ndarray:
    a = np.radians(degrees)
    return np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])


def record(asset, xforms, mesh=None, assets=ASSETS) -> dict:
    out = {"assets": assets, "asset": np.asarray(asset, np.int32), "xform": np.asarray(xforms, np.float32)}
    if mesh is not None:
        out["mesh"] = mesh
    return out


def mesh_chunk(faces: list[list[np.ndarray]]) -> MeshChunk:
    """A MeshChunk of faces given as lists of rings (outline first), each (n, 3)."""
    rings = [ring for face in faces for ring in face]
    ring_sizes = [len(r) for r in rings]
    return MeshChunk(
        vertices=np.concatenate(rings).astype(np.float32),
        ring_offsets=np.concatenate([[0], np.cumsum(ring_sizes)]).astype(np.int64),
        face_offsets=np.concatenate([[0], np.cumsum([len(f) for f in faces])]).astype(np.int64),
        lot=np.zeros(len(faces), np.int32),
        symbol=np.zeros(len(faces), np.int32),
    )


def test_cube_instance():
    # Sizes 2, 3, 4 along the scope axes, turned 30 degrees about y, at (5, 1, -2).
    linear = rotation_y(30) * [2, 3, 4]
    mesh = bake(record([0], [xform(linear, [5, 1, -2])]))
    assert len(mesh.faces) == 12
    corners = np.array([[i & 1, i >> 1 & 1, i >> 2 & 1] for i in range(8)]) @ linear.T + [5, 1, -2]
    np.testing.assert_allclose(mesh.bounds, [corners.min(0), corners.max(0)], atol=1e-5)
    assert mesh.area == pytest.approx(2 * (2 * 3 + 3 * 4 + 4 * 2), rel=1e-6)
    assert mesh.volume == pytest.approx(24, rel=1e-6)  # positive: faces outward
    assert mesh.metadata == {"n_instances": 1, "n_mesh_faces": 0, "n_polygons": 6, "n_holes": 0,
                             "face_sizes": {4: 6}}


def test_mirrored_cube_still_faces_outward():
    mirror, plain = xform(np.diag([-2, 3, 4]), [0, 0, 0]), xform(np.diag([2, 3, 4]), [9, 0, 0])
    mirrored = bake(record([0, 0], [mirror, plain]))
    assert mirrored.volume == pytest.approx(48, rel=1e-6)
    assert mirrored.bounds.tolist() == [[-2, 0, 0], [11, 3, 4]]


@pytest.mark.parametrize("n", [0, 1, 50])
def test_expansion_matches_plain_reference(monkeypatch, n):
    # Blocks of 3 cubes, so that the block loop runs; random transforms, about half of them mirroring.
    monkeypatch.setattr(bake_module, "_BLOCK_VERTICES", 24)
    rng = np.random.default_rng(n)
    asset = rng.integers(0, 3, n)
    xforms = rng.normal(size=(n, 3, 4)).astype(np.float32)
    mesh = bake(record(asset, xforms))
    expected_vertices, expected_faces, base = [], [], 0
    for a in (0, 1, 2):  # instances grouped by asset, each group in record order
        shape = builtin_mesh(ASSETS[a])
        for x in xforms[asset == a].astype(float):
            expected_vertices.append(shape.vertices @ x[:, :3].T + x[:, 3])
            faces = shape.faces + base
            expected_faces.append(faces[:, [0, 2, 1]] if np.linalg.det(x[:, :3]) < 0 else faces)
            base += len(shape.vertices)
    if n:
        np.testing.assert_allclose(mesh.vertices, np.concatenate(expected_vertices), atol=1e-9)
        np.testing.assert_array_equal(mesh.faces, np.concatenate(expected_faces))
    else:
        assert mesh.vertices.shape == (0, 3) and mesh.faces.shape == (0, 3)
    assert mesh.metadata["n_instances"] == n


def test_quads_negative_and_zero_columns():
    # Columns (scope axes k+1, k+2 times sizes, then zero): the quad's normal is col0 x col1.
    facade = xform([[-3, 0, 0], [0, 2, 0], [0, 0, 0]], [3, 0, 0])  # col0 -x, col1 +y: normal -z
    roof = xform([[0, 4, 0], [0, 0, 0], [5, 0, 0]], [0, 6, 0])  # col0 +z, col1 +x: normal +y
    flat = xform([[1, 0, 0], [0, 0, 0], [0, 0, 0]], [0, 0, 0])  # an edge: no area
    mesh = bake(record([1, 1, 1], [facade, roof, flat]))
    assert len(mesh.faces) == 6
    np.testing.assert_allclose(mesh.area_faces, [3, 3, 10, 10, 0, 0], atol=1e-6)
    np.testing.assert_allclose(mesh.face_normals[:4], [[0, 0, -1]] * 2 + [[0, 1, 0]] * 2, atol=1e-6)
    np.testing.assert_allclose(mesh.bounds, [[0, 0, 0], [4, 6, 5]], atol=1e-6)
    assert mesh.metadata["face_sizes"] == {4: 3}


def test_cylinder_area_close_to_analytic():
    # Radius 1 (scope 2 x 2), height 3: 2 pi r h + 2 pi r^2 for a true cylinder.
    mesh = bake(record([2], [xform(np.diag([2, 3, 2]), [10, 0, 10])]))
    polygon = 16 * 2 * np.sin(np.pi / 16) * 3 + 2 * 8 * np.sin(2 * np.pi / 16)  # the 16-gon prism exactly
    assert mesh.area == pytest.approx(polygon, rel=1e-6)
    assert mesh.area == pytest.approx(2 * np.pi * 3 + 2 * np.pi, rel=0.02)
    np.testing.assert_allclose(mesh.bounds, [[10, 0, 10], [12, 3, 12]], atol=1e-6)
    assert mesh.metadata["n_polygons"] == 18


def tilt(points) -> np.ndarray:
    """Points of the x-z plane (y = 0) turned 40 degrees about x and moved: a polygon in a tilted plane."""
    a = np.radians(40)
    turn = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    return np.asarray(points, float) @ turn.T + [100, 20, -50]


@needs_earcut
def test_polygons_with_holes_concave_and_convex():
    # (x, z) rings with normal +y before tilting: counter-clockwise seen from +y goes +x -> -z.
    outline = [[0, 0, 0], [10, 0, 0], [10, 0, -10], [0, 0, -10]]
    hole = [[3, 0, -3], [3, 0, -7], [7, 0, -7], [7, 0, -3]]  # opposite order, 4 x 4
    ell = [[0, 0, 0], [6, 0, 0], [6, 0, -2], [2, 0, -2], [2, 0, -6], [0, 0, -6]]  # 20 m2
    pentagon = [[0, 0, 0], [4, 0, 0], [5, 0, -3], [2, 0, -5], [-1, 0, -3]]
    faces = [[tilt(outline), tilt(hole)], [tilt(ell)], [tilt(pentagon)]]
    mesh = bake(record([], np.zeros((0, 3, 4)), mesh_chunk(faces)))
    x, z = np.array(pentagon)[:, 0], np.array(pentagon)[:, 2]
    pentagon_area = 0.5 * abs(np.dot(x, np.roll(z, -1)) - np.dot(z, np.roll(x, -1)))  # shoelace
    assert mesh.area == pytest.approx(100 - 16 + 20 + pentagon_area, rel=1e-6)
    assert len(mesh.faces) == (8 + 2 - 2) + (6 - 2) + (5 - 2)  # V + 2H - 2 per face
    normal = tilt([[0, 1, 0]])[0] - tilt([[0, 0, 0]])[0]
    np.testing.assert_allclose(mesh.face_normals, np.tile(normal, (len(mesh.faces), 1)), atol=1e-5)
    assert mesh.metadata == {"n_instances": 0, "n_mesh_faces": 3, "n_polygons": 4, "n_holes": 1,
                             "face_sizes": {4: 2, 5: 1, 6: 1}}


def write_obj(path, text: str):
    path.write_text(text, encoding="utf-8")
    return path


def test_obj_asset_normalized_to_unit_box(tmp_path):
    # A flat panel (z = 0.3 everywhere) spanning x -5..5, y 2..4: one quad and one pentagon.
    write_obj(tmp_path / "panel.obj", "v -5 2 0.3\nv 0 2 0.3\nv 5 2 0.3\nv 5 4 0.3\nv 0 4 0.3\nv -5 4 0.3\n"
              "f 1 2 5 6\nf 2 3 4 5\n")
    shape = record([0], [xform(np.diag([10, 2, 7]), [1, 1, 1])], assets=["panel.obj"])
    mesh = bake(shape, [tmp_path])
    np.testing.assert_allclose(mesh.bounds, [[1, 1, 1], [11, 3, 1]], atol=1e-6)  # flat axis stays at 0
    assert mesh.area == pytest.approx(20, rel=1e-6)
    assert len(mesh.faces) == 4
    assert mesh.metadata["n_polygons"] == 2 and mesh.metadata["face_sizes"] == {4: 2}
    assert count_triangles(shape, [tmp_path]) == 4


def test_asset_errors(tmp_path):
    with pytest.raises(AssetError, match="not found"):
        bake(record([0], [xform(np.eye(3), [0, 0, 0])], assets=["missing.obj"]), [tmp_path])
    with pytest.raises(AssetError, match="leaves the asset folders"):
        bake(record([0], [xform(np.eye(3), [0, 0, 0])], assets=["../x.obj"]), [tmp_path])
    # An unused asset is never loaded.
    assert len(bake(record([0], [xform(np.eye(3), [0, 0, 0])], assets=["builtin:cube", "missing.obj"])).faces)


def test_size_guard_raises_before_allocating():
    n = 5_000_000  # 60 M triangles, ~3.4 GB baked; the inputs are broadcast views, no memory
    big = {
        "assets": ASSETS,
        "asset": np.broadcast_to(np.int64(0), (n,)),
        "xform": np.broadcast_to(xform(np.eye(3), [0, 0, 0]), (n, 3, 4)),
    }
    tracemalloc.start()
    try:
        with pytest.raises(UsageError, match=r"60,000,000 triangles, more than the limit of 50,000,000"):
            bake(big)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 100_000_000  # bincount copies the broadcast asset column (40 MB); baking needs 3.4 GB
    with pytest.raises(UsageError, match="max_triangles"):
        bake(record([0, 0], [xform(np.eye(3), [0, 0, 0])] * 2), max_triangles=23)
    assert len(bake(record([0, 0], [xform(np.eye(3), [0, 0, 0])] * 2), max_triangles=24).faces) == 24


def chunks():
    """Two chunks: cubes and quads, and a mesh face (a 10 x 10 square with a 4 x 4 hole)."""
    first = TerminalChunk(
        asset=np.array([0, 1], np.int32),
        xform=np.stack([xform(np.diag([1, 2, 3]), [0, 0, 0]),
                        xform([[2, 0, 0], [0, 2, 0], [0, 0, 0]], [5, 0, 0])]),
        lot=np.zeros(2, np.int32), symbol=np.zeros(2, np.int32), mesh=MeshChunk.empty(),
    )  # fmt: skip
    outline = np.array([[0, 0, 0], [10, 0, 0], [10, 0, -10], [0, 0, -10.0]])
    hole = np.array([[3, 0, -3], [3, 0, -7], [7, 0, -7], [7, 0, -3.0]])
    second = TerminalChunk(
        asset=np.array([0], np.int32), xform=xform(np.eye(3), [20, 0, 0])[None],
        lot=np.ones(1, np.int32), symbol=np.zeros(1, np.int32), mesh=mesh_chunk([[outline, hole]]),
    )  # fmt: skip
    return [first, second]


@needs_earcut
@pytest.mark.parametrize("suffix", [".obj", ".ply", ".stl", ".glb"])
def test_writers_round_trip(tmp_path, suffix):
    path = tmp_path / f"city{suffix}"
    assert writer_for(path, OutputOptions(bake=True)) is BakedWriter
    with BakedWriter(path, assets=ASSETS, symbols=["A"], meta={"grammarc": "0", "grammar": "g.cga"}) as out:
        for chunk in chunks():
            out.write(chunk)
        counts = out.close()
    assert counts == {"instances": 3, "mesh_faces": 1, "mesh_vertices": 8, "triangles": 12 + 2 + 12 + 8,
                      "vertices": 8 + 4 + 8 + 8, "polygons": 6 + 1 + 6 + 2}
    loaded = trimesh.load(path, force="mesh", process=False)
    expected = bake({"assets": ASSETS, "asset": [0, 1, 0],
                     "xform": np.concatenate([c.xform for c in chunks()]),
                     "mesh": MeshChunk.concat([c.mesh for c in chunks()])})
    assert len(loaded.faces) == counts["triangles"]
    assert loaded.area == pytest.approx(expected.area, rel=1e-6)
    np.testing.assert_allclose(loaded.bounds, expected.bounds, atol=1e-5)
    if suffix in (".obj", ".ply"):  # these keep the vertices as written
        assert len(loaded.vertices) == counts["vertices"]
    written = [path.name] + (["city.mtl"] if suffix == ".obj" else [])  # an OBJ has its material library
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(written)  # no temporaries left


def test_writer_abort_leaves_no_file(tmp_path):
    path = tmp_path / "city.obj"
    with BakedWriter(path, assets=ASSETS, symbols=["A"], meta={}) as out:
        out.write(chunks()[0])
        out.abort()
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(RuntimeError), BakedWriter(path, assets=ASSETS, symbols=["A"], meta={}) as out:
        out.write(chunks()[0])
        raise RuntimeError("derivation failed")
    assert list(tmp_path.iterdir()) == []
    path.write_text("old")  # a file already there stays as it was
    out = BakedWriter(path, assets=ASSETS, symbols=["A"], meta={})
    out.write(chunks()[0])
    out.abort()
    assert path.read_text() == "old" and len(list(tmp_path.iterdir())) == 1
    with pytest.raises(ValueError, match="aborted"):
        out.write(chunks()[0])


def test_writer_limit_and_bad_input(tmp_path):
    out = BakedWriter(tmp_path / "city.ply", assets=ASSETS, symbols=["A"], meta={}, max_triangles=20)
    with pytest.raises(UsageError, match="passes 20 triangles"):
        out.write(chunks()[0])  # 14 triangles: fine
        out.write(chunks()[0])  # 28: refused, and the writer aborts
    with pytest.raises(ValueError, match="aborted"):
        out.close()
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(UsageError, match="format `.npz`"):
        BakedWriter(tmp_path / "city.npz", assets=ASSETS, symbols=[], meta={})
    bad = BakedWriter(tmp_path / "city.stl", assets=ASSETS[:1], symbols=[], meta={})
    with pytest.raises(ValueError, match="out of range"):
        bad.write(chunks()[0])


@needs_earcut
def test_bake_read_instances_with_assets_from_meta(tmp_path):
    # A record on disk names its grammar; file assets resolve next to it.
    write_obj(tmp_path / "box.obj", "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nf 1 2 3 4\n")
    assets = [*ASSETS, "box.obj"]
    path = tmp_path / "city.npz"
    with InstanceWriter(path, assets=assets, symbols=["A"], meta={"grammar": str(tmp_path / "g.cga")}) as out:
        for chunk in chunks():
            out.write(chunk)
        out.write(TerminalChunk(
            asset=np.array([3], np.int32), xform=xform(np.diag([3, 3, 3]), [0, 50, 0])[None],
            lot=np.zeros(1, np.int32), symbol=np.zeros(1, np.int32), mesh=MeshChunk.empty(),
        ))  # fmt: skip
    mesh = bake(read_instances(path))
    assert len(mesh.faces) == 12 + 2 + 12 + 8 + 2
    assert mesh.area == pytest.approx(22 + 4 + 6 + 84 + 9, rel=1e-6)
    assert mesh.metadata["n_polygons"] == 6 + 1 + 6 + 2 + 1


def test_a_glb_asset_inserted_z_up_bakes_standing(tmp_path):
    """The baked city holds the GLB's triangles per instance, the z-up mast standing 6 m tall."""
    from writers_city import glb_city

    record, _, triangles = glb_city(tmp_path, "masts.npz")
    mesh = bake(record, [tmp_path])
    assert len(mesh.faces) == 3 * triangles
    np.testing.assert_allclose(mesh.bounds[:, 1], [0, 6], atol=1e-5)
    np.testing.assert_allclose(mesh.bounds[1, 0] - mesh.bounds[0, 0], 20 + 2, atol=1e-5)  # lots 10 m apart, 2 m vane


# ---------------------------------------------------------------------------- colours and textures baked

def test_a_baked_obj_has_a_group_per_lot_and_a_material_per_colour(tmp_path):
    text = textured_city(tmp_path, COLOURED, ".obj", bake=True).read_text()
    assert text.splitlines()[1] == "mtllib city.mtl"
    assert [line for line in text.splitlines() if line.startswith("g ")] == ["g lot_0", "g lot_1"]
    assert text.count("usemtl") == 4  # per lot: the roof's, then the walls'
    scene = trimesh.load(tmp_path / "city.obj", process=False)
    colours = {tuple(g.visual.material.diffuse[:3]) for g in scene.geometry.values()}
    assert colours == {(255, 0, 0), (0, 255, 0)}
    assert "d 0.501961" in (tmp_path / "city.mtl").read_text()


def test_a_baked_ply_has_vertex_colours(tmp_path):
    mesh = trimesh.load(textured_city(tmp_path, COLOURED, ".ply", bake=True), process=False)
    colours = mesh.visual.vertex_colors
    assert {tuple(c) for c in colours.tolist()} == {tuple(RED), tuple(SEE_THROUGH_GREEN)}
    roof = mesh.vertices[:, 1] > 5.9
    assert (colours[mesh.faces[np.all(roof[mesh.faces], axis=1)]] == RED).all()


def test_a_baked_glb_has_a_material_per_colour(tmp_path):
    scene = trimesh.load(textured_city(tmp_path, COLOURED, ".glb", bake=True), process=False)
    factors = sorted(g.visual.material.baseColorFactor.tolist() for g in scene.geometry.values())
    assert factors == sorted([RED, SEE_THROUGH_GREEN])
    assert sum(len(g.faces) for g in scene.geometry.values()) == 2 * (4 * 2 + 2)  # walls and roof of two lots


def test_a_baked_obj_and_glb_reference_their_texture(tmp_path):
    textured_city(tmp_path, TEXTURED, ".obj", bake=True)
    assert "map_Kd tex/wall.png" in (tmp_path / "city.mtl").read_text()
    images = [g.visual.material.image for g in trimesh.load(tmp_path / "city.obj").geometry.values()]
    assert sum(image is not None for image in images) == 1
    scene = trimesh.load(textured_city(tmp_path, TEXTURED, ".glb", bake=True), process=False)
    textures = [g.visual.material.baseColorTexture for g in scene.geometry.values()]
    assert sorted(t is not None for t in textures) == [False, True]
    assert next(t for t in textures if t is not None).size == (2, 2)


def test_a_texture_outside_the_roots_is_not_read(tmp_path):
    (tmp_path / "inner").mkdir()
    (tmp_path / "tex").mkdir()
    (tmp_path / "tex" / "wall.png").write_bytes(PNG)  # beside the grammar's folder, not in it
    textured_city(tmp_path / "inner", TEXTURED.replace("tex/wall.png", "../tex/wall.png"), ".glb", bake=True)
    scene = trimesh.load(tmp_path / "inner" / "city.glb", process=False)
    assert all(g.visual.material.baseColorTexture is None for g in scene.geometry.values())


def test_a_bake_without_colours_or_textures_has_no_materials(tmp_path):
    plain = 'version "2023.0"\nLot --> extrude(6) comp(f){ top : setback(2){ all : Rim. | remainder : Top. } }\n'
    text = textured_city(tmp_path, plain, ".obj", bake=True).read_text()
    assert "usemtl" not in text and text.count("g lot_") == 2
    assert "red" not in textured_city(tmp_path, plain, ".ply", bake=True).read_bytes()[:400].decode("latin-1")
def textured_chunks():
    """``chunks()`` with texture coordinates: the first chunk's instances u = x, v = 2 z of their unit box
    (their world's x and z halved: their columns are 2 long), the second's none, its face u = x / 10."""
    first, second = chunks()
    uv = np.zeros((2, 2, 4), np.float32)
    uv[:, 0, 0], uv[:, 1, 2] = 1, 2
    mesh = second.mesh
    textured = MeshChunk(mesh.vertices, mesh.ring_offsets, mesh.face_offsets, mesh.lot, mesh.symbol,
                         uv=np.stack([mesh.vertices[:, 0] / 10, mesh.vertices[:, 2] / 10], axis=1))
    return [TerminalChunk(first.asset, first.xform, first.lot, first.symbol, first.mesh, uv=uv),
            TerminalChunk(second.asset, second.xform, second.lot, second.symbol, textured)]


@needs_earcut
@pytest.mark.parametrize("suffix", [".obj", ".glb"])
def test_writers_keep_texture_coordinates(tmp_path, suffix):
    """OBJ ``vt`` and glTF ``TEXCOORD_0``: an instance's map of its unit box, a face's per vertex, 0 for an
    instance without any."""
    path = tmp_path / f"city{suffix}"
    with BakedWriter(path, assets=ASSETS, symbols=["A"], meta={}) as out:
        for chunk in textured_chunks():
            out.write(chunk)
    loaded = trimesh.load(path, force="mesh", process=False)
    uv = loaded.visual.uv  # trimesh turns glTF's v (down the image) back
    cube = builtin_mesh("builtin:cube").vertices
    np.testing.assert_allclose(uv[:8], cube[:, [0, 2]] * [1, 2], atol=1e-6)
    np.testing.assert_allclose(uv[-8:], loaded.vertices[-8:][:, [0, 2]] / 10, atol=1e-6)
    # the second chunk's cube has none: after the first chunk's cube and quad in the streamed OBJ, after
    # the first cube in the GLB (its instances baked together, by asset)
    untextured = slice(12, 20) if suffix == ".obj" else slice(8, 16)
    np.testing.assert_allclose(uv[untextured], 0)


def test_untextured_obj_has_no_texture_coordinates(tmp_path):
    path = tmp_path / "city.obj"
    with BakedWriter(path, assets=ASSETS, symbols=["A"], meta={}) as out:
        out.write(chunks()[0])
    assert b"vt" not in path.read_bytes()
