"""Asset meshes: built-ins closed and outward in the unit box, files fitted to it, LoD, the library."""

import os
from pathlib import Path

import numpy as np
import pytest
import trimesh

from grammarc.errors import AssetError
from grammarc.io.rpk import open_rpk
from grammarc.model.assets import LOD_STAND_IN, asset_library, builtin_mesh, load_asset

KIT = Path(__file__).resolve().parents[2].parent / "shared" / "prt"
needs_kit = pytest.mark.skipif(not (KIT / "rpk").is_dir(), reason="PRT kit (../shared/prt) absent")


def test_builtins_are_closed_outward_unit_shapes():
    for name, n_triangles, polygons in (("cube", 12, {4: 6}), ("cylinder", 60, {4: 16, 16: 2})):
        shape = builtin_mesh(name)
        mesh = trimesh.Trimesh(shape.vertices, shape.faces, process=False)
        assert len(mesh.faces) == n_triangles
        assert mesh.bounds.tolist() == [[0, 0, 0], [1, 1, 1]]
        assert mesh.volume > 0 and mesh.is_winding_consistent
        outward = np.einsum("ij,ij->i", mesh.face_normals, mesh.triangles_center - 0.5)
        assert (outward > 0).all()
        assert dict(zip(*np.unique(shape.polygon_sizes, return_counts=True))) == polygons
    quad = builtin_mesh("builtin:quad")
    normals = trimesh.Trimesh(quad.vertices, quad.faces, process=False).face_normals
    np.testing.assert_allclose(normals, [[0, 0, 1], [0, 0, 1]], atol=1e-12)
    with pytest.raises(AssetError, match="unknown built-in"):
        builtin_mesh("builtin:sphere")
    with pytest.raises(AssetError, match="unknown built-in"):
        builtin_mesh("builtin:cone2")


@pytest.mark.parametrize("name, volume, sides", [
    ("L", 5 / 9, 6), ("U", 7 / 9, 8), ("T", 5 / 9, 8), ("H", 7 / 9, 12), ("cylinder6", 0.75, 6),
    ("cylinder40", np.pi / 4, 40),
])
def test_block_and_cylinder_builtins_are_closed_outward_prisms_filling_the_unit_box(name, volume, sides):
    """The paper's L, H, U, T blocks (wings a third thick) and cylinders of N sides, fitted to [0, 1]^3."""
    shape = builtin_mesh(f"builtin:{name}")
    mesh = trimesh.Trimesh(shape.vertices, shape.faces, process=True)
    assert mesh.is_watertight and mesh.is_winding_consistent
    assert mesh.bounds.tolist() == [[0, 0, 0], [1, 1, 1]]
    assert mesh.volume == pytest.approx(volume, rel=0.02 if name.startswith("cylinder") else 1e-12)
    assert dict(zip(*np.unique(shape.polygon_sizes, return_counts=True))) == {4: sides, sides: 2}


@pytest.mark.parametrize("name, volume, polygons", [
    ("cone8", np.sqrt(0.5) / 3, {3: 8, 8: 1}),  # a third of the octagonal prism's 0.7071
    ("cone64", np.pi / 12, {3: 64, 64: 1}),
    ("sphere8x4", None, {3: 16, 4: 16}),
    ("sphere64x32", np.pi / 6, {3: 128, 4: 64 * 30}),
])  # fmt: skip
def test_cone_and_sphere_builtins_are_closed_outward_meshes_filling_the_unit_box(name, volume, polygons):
    """CityEngine's primitiveCone and primitiveSphere with their segment counts, fitted to [0, 1]^3."""
    shape = builtin_mesh(f"builtin:{name}")
    mesh = trimesh.Trimesh(shape.vertices, shape.faces, process=True)
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0
    np.testing.assert_allclose(mesh.bounds, [[0, 0, 0], [1, 1, 1]], atol=1e-12)
    if volume is not None:
        assert mesh.volume == pytest.approx(volume, rel=0.01)
    assert dict(zip(*np.unique(shape.polygon_sizes, return_counts=True))) == polygons


def write_obj(path, text: str):
    path.write_text(text, encoding="utf-8")
    return path


def test_obj_asset_fitted_to_the_unit_box_counts_its_face_lines(tmp_path):
    # A pentagon on z = 2 and a triangle standing on its edge 1-5, in a box 2 x 5 x 3 away from the origin.
    write_obj(tmp_path / "gable.obj", "v 2 2 2\nv 4 2 2\nv 4 6 2\nv 3 7 2\nv 2 6 2\nv 2 4 5\n"
              "f 1 2 3 4 5\nf 1 5 6\nf 1 2\n")  # a two-vertex face is not a polygon: dropped
    shape = load_asset("gable.obj", [tmp_path])
    np.testing.assert_allclose(shape.vertices[[0, 3, 5]], [[0, 0, 0], [0.5, 1, 0], [0, 0.4, 1]])
    assert shape.polygon_sizes.tolist() == [5, 3] and shape.faces.tolist() == [[0, 1, 2], [0, 2, 3],
                                                                               [0, 3, 4], [0, 4, 5]]
    with pytest.raises(ValueError, match="read-only"):
        shape.vertices[0, 0] = 1.0  # cached and shared


def test_lod_substitutes_a_sibling_file_and_builtin_stands_in_for_a_missing_one(tmp_path):
    write_obj(tmp_path / "w.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    write_obj(tmp_path / "w.low.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")
    assert load_asset("w.obj", [tmp_path]).n_triangles == 2
    assert load_asset("w.obj", [tmp_path], lod="low").n_triangles == 1
    assert load_asset("w.obj", [tmp_path], lod="high").n_triangles == 2  # no w.high.obj: the file itself
    assert load_asset("gone.obj", [tmp_path], lod=LOD_STAND_IN) is builtin_mesh("builtin:cube")
    with pytest.raises(AssetError, match="not found .*--lod builtin"):
        load_asset("gone.obj", [tmp_path])
    with pytest.raises(AssetError, match="leaves the asset folders"):
        load_asset("../w.obj", [tmp_path])


def test_a_file_is_read_again_when_it_changes(tmp_path):
    path = write_obj(tmp_path / "w.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")
    assert load_asset("w.obj", [tmp_path]) is load_asset("w.obj", [tmp_path])  # cached
    write_obj(path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n")
    stat = path.stat()
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1_000_000))
    assert load_asset("w.obj", [tmp_path]).n_triangles == 2


def test_the_library_loads_what_is_used_from_the_roots_the_meta_names(tmp_path):
    write_obj(tmp_path / "w.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")
    library = asset_library(["builtin:cube", "w.obj", "gone.obj"], {"meta": {"grammar": str(tmp_path / "g.cga")}})
    assert library[1].n_triangles == 1 and library[0] is builtin_mesh("builtin:cube")
    assert library.triangles(np.array([2, 3, 0])) == 2 * 12 + 3 * 1  # the unused missing asset is not loaded
    with pytest.raises(AssetError, match="not found"):
        library[2]
    assert asset_library(["w.obj"], {}, [tmp_path])[0].n_triangles == 1  # roots given: the meta is not read


@needs_kit
def test_candler_assets(tmp_path):
    # CityEngine's own assets: each fills the unit box, and counts its OBJ faces as polygons.
    pytest.importorskip("py7zr")
    with open_rpk(KIT / "rpk" / "candler.rpk", tmpdir=tmp_path) as rpk:
        for path in sorted(rpk.assets_root.rglob("*.obj")):
            name = path.relative_to(rpk.assets_root).as_posix()
            shape = load_asset(name, rpk.asset_roots)
            np.testing.assert_allclose([shape.vertices.min(0), shape.vertices.max(0)], [[0] * 3, [1] * 3])
            f_lines = [line.split() for line in path.read_text().splitlines() if line.startswith("f ")]
            assert shape.polygon_sizes.tolist() == [len(f) - 1 for f in f_lines]
            assert shape.n_triangles == sum(len(f) - 3 for f in f_lines)


def test_a_file_asset_keeps_its_bounds_in_its_own_units(tmp_path):
    (tmp_path / "post.obj").write_text("v -1 0 2\nv 1 0 2\nv 1 3 2\nv -1 3 2.5\nf 1 2 3 4\n")
    mesh = load_asset("post.obj", [tmp_path])
    np.testing.assert_array_equal(mesh.bounds, [[-1, 0, 2], [1, 3, 2.5]])
    np.testing.assert_array_equal(builtin_mesh("quad").bounds, [[0, 0, 0], [1, 1, 0]])


def box_scene():
    """Two boxes 1 x 2 x 3 placed by their nodes at x = 10 and y = 5: a scene whose transforms count."""
    box = trimesh.creation.box(extents=(1, 2, 3))
    scene = trimesh.Scene()
    scene.add_geometry(box, transform=trimesh.transformations.translation_matrix((10, 0, 0)))
    scene.add_geometry(box, transform=trimesh.transformations.translation_matrix((0, 5, 0)))
    return scene


@pytest.mark.parametrize("suffix", ["glb", "gltf"])
def test_gltf_scenes_load_with_their_node_transforms(tmp_path, suffix):
    box_scene().export(tmp_path / f"pair.{suffix}")
    mesh = load_asset(f"pair.{suffix}", [tmp_path])
    np.testing.assert_allclose(mesh.bounds, [[-0.5, -1, -1.5], [10.5, 6, 1.5]])  # y-up metres: as written
    np.testing.assert_allclose([mesh.vertices.min(0), mesh.vertices.max(0)], [[0] * 3, [1] * 3])
    assert mesh.n_triangles == mesh.n_polygons == 24


def collada(tmp_path, name: str, asset: str = "") -> Path:
    """A Collada box 1 x 2 x 3 (trimesh's writer), its ``<asset>`` holding ``asset`` instead of Y_UP."""
    pytest.importorskip("collada")
    text = trimesh.exchange.dae.export_collada(trimesh.creation.box(extents=(1, 2, 3)))
    text = text.decode() if isinstance(text, bytes) else text
    (tmp_path / name).write_text(text.replace("<up_axis>Y_UP</up_axis>", asset or "<up_axis>Y_UP</up_axis>"))
    return tmp_path / name


def test_collada_is_read_in_metres_with_its_up_axis_turned_to_y(tmp_path):
    collada(tmp_path, "y.dae")
    collada(tmp_path, "z.dae", '<unit meter="0.01" name="centimeter"/><up_axis>Z_UP</up_axis>')
    collada(tmp_path, "x.dae", "<up_axis>X_UP</up_axis>")
    np.testing.assert_allclose(load_asset("y.dae", [tmp_path]).bounds, [[-0.5, -1, -1.5], [0.5, 1, 1.5]])
    # z-up: its z (3 cm) is the height, its y (2 cm) the depth, turned -90 degrees about x
    np.testing.assert_allclose(load_asset("z.dae", [tmp_path]).bounds,
                               [[-0.005, -0.015, -0.01], [0.005, 0.015, 0.01]])
    # x-up: its x (1) is the height, its y (2) along -x
    np.testing.assert_allclose(load_asset("x.dae", [tmp_path]).bounds, [[-1, -0.5, -1.5], [1, 0.5, 1.5]])
    assert load_asset("z.dae", [tmp_path]).n_triangles == 12


#: A quad of an ASCII FBX 7.4 file, y-up or z-up by its GlobalSettings, its model moved 10 along x.
FBX = """; FBX 7.4.0 project file
FBXHeaderExtension:  {
\tFBXHeaderVersion: 1003
\tFBXVersion: 7400
}
GlobalSettings:  {
\tVersion: 1000
\tProperties70:  {
\t\tP: "UpAxis", "int", "Integer", "",UP
\t\tP: "UpAxisSign", "int", "Integer", "",1
\t\tP: "FrontAxis", "int", "Integer", "",FRONT
\t\tP: "FrontAxisSign", "int", "Integer", "",SIGN
\t\tP: "CoordAxis", "int", "Integer", "",0
\t\tP: "CoordAxisSign", "int", "Integer", "",1
\t}
}
Objects:  {
\tGeometry: 1000, "Geometry::quad", "Mesh" {
\t\tVertices: *12 {
\t\t\ta: 0,0,0,1,0,0,1,2,0,0,2,3
\t\t}
\t\tPolygonVertexIndex: *4 {
\t\t\ta: 0,1,2,-4
\t\t}
\t}
\tModel: 2000, "Model::quad", "Mesh" {
\t\tProperties70:  {
\t\t\tP: "Lcl Translation", "Lcl Translation", "", "A",10,0,0
\t\t}
\t}
}
Connections:  {
\tC: "OO",1000,2000
\tC: "OO",2000,0
}
"""


def test_fbx_is_read_through_assimp_with_its_transforms_and_axes(tmp_path):
    pytest.importorskip("assimp_py")
    (tmp_path / "y.fbx").write_text(FBX.replace("UP", "1").replace("FRONT", "2").replace("SIGN", "1"))
    (tmp_path / "z.fbx").write_text(FBX.replace("UP", "2").replace("FRONT", "1").replace("SIGN", "-1"))
    y = load_asset("y.fbx", [tmp_path])
    np.testing.assert_allclose(y.bounds, [[10, 0, 0], [11, 2, 3]])
    assert y.n_triangles == 2 and y.n_polygons == 2
    np.testing.assert_allclose(load_asset("z.fbx", [tmp_path]).bounds, [[10, 0, -2], [11, 3, 0]])


def write_3ds(path: Path, vertices, triangles) -> Path:
    """A minimal 3DS file: main chunk, editor, one named object with a triangle mesh."""
    import struct

    def chunk(kind, body):
        return struct.pack("<HI", kind, 6 + len(body)) + body

    points = chunk(0x4110, struct.pack("<H", len(vertices)) + np.asarray(vertices, "<f4").tobytes())
    faces = chunk(0x4120, struct.pack("<H", len(triangles))
                  + b"".join(struct.pack("<4H", *t, 0) for t in triangles))
    editor = chunk(0x3D3D, chunk(0x4000, b"part\0" + chunk(0x4100, points + faces)))
    path.write_bytes(chunk(0x4D4D, chunk(0x0002, struct.pack("<I", 3)) + editor))
    return path


def test_3ds_is_read_through_assimp_z_up_as_3ds_files_are(tmp_path):
    pytest.importorskip("assimp_py")
    write_3ds(tmp_path / "part.3ds", [[0, 0, 0], [1, 0, 0], [1, 2, 0], [0, 2, 3]], [(0, 1, 2), (0, 2, 3)])
    mesh = load_asset("part.3ds", [tmp_path])
    np.testing.assert_allclose(mesh.bounds, [[0, 0, -2], [1, 3, 0]])  # its z (3) is the height
    assert mesh.n_triangles == 2


def test_fbx_and_3ds_without_assimp_are_unsupported_formats(tmp_path, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "assimp_py", None)  # as if it were not installed
    (tmp_path / "a.fbx").write_text(FBX)
    write_3ds(tmp_path / "b.3ds", [[0, 0, 0], [1, 0, 0], [1, 1, 0]], [(0, 1, 2)])
    with pytest.raises(AssetError, match=r"unsupported asset format: FBX \(`a.fbx`; pip install"):
        load_asset("a.fbx", [tmp_path])
    with pytest.raises(AssetError, match="unsupported asset format: 3DS"):
        load_asset("b.3ds", [tmp_path])


def test_a_broken_file_is_an_asset_error(tmp_path):
    (tmp_path / "bad.glb").write_bytes(b"glTF not really")
    with pytest.raises(AssetError, match="cannot read asset .*bad.glb"):
        load_asset("bad.glb", [tmp_path])
