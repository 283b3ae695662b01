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
