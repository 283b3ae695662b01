"""Instanced USD: the layers read back with pxr give the record's instances, in tiles far from the origin."""

import numpy as np
import pytest
from writers_city import TEXTURED, TEXTURED_GROUND, city, glb_city, nearest_uv, textured_city, world

pxr = pytest.importorskip("pxr")
from pxr import Usd, UsdGeom

from grammarc.io.usd import tiles_folder


def instancers(path):
    stage = Usd.Stage.Open(str(path))
    return stage, [UsdGeom.PointInstancer(p) for p in stage.Traverse() if p.IsA(UsdGeom.PointInstancer)]


@pytest.mark.parametrize("suffix", [".usda", ".usdc"])
def test_usd_round_trip(tmp_path, suffix):
    record, path, counts = city(tmp_path, f"city{suffix}", tile_size=100.0)
    stage, found = instancers(path)
    assert UsdGeom.GetStageUpAxis(stage) == "Y" and stage.GetDefaultPrim().GetName() == "City"
    assert counts["instances"] == len(record["asset"]) and counts["tiles"] == len(found) == 3  # z = -300 parts two rows
    ids, xforms, assets = [], [], []
    for instancer in found:
        tile = UsdGeom.Xformable(instancer.GetPrim()).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
        origin = np.array(tile.ExtractTranslation())
        positions = np.array(instancer.GetPositionsAttr().Get(), float) + origin
        orientations = np.array([[*q.GetImaginary(), q.GetReal()] for q in instancer.GetOrientationsAttr().Get()])
        xforms.append(world(positions, orientations, np.array(instancer.GetScalesAttr().Get())))
        ids.append(np.array(instancer.GetIdsAttr().Get()))
        targets = instancer.GetPrototypesRel().GetTargets()
        names = [stage.GetPrimAtPath(t).GetCustomDataByKey("grammarc:asset") for t in targets]
        assets.append(np.array(names)[np.array(instancer.GetProtoIndicesAttr().Get())])
    ids = np.concatenate(ids)
    order = np.argsort(ids)
    assert (ids[order] == np.arange(len(record["asset"]))).all()
    # the same instances: assets, positions exact to float32 in the tile, rotations to quath's precision
    assert (np.concatenate(assets)[order] == record["assets"][record["asset"]]).all()
    got = np.concatenate(xforms)[order]
    np.testing.assert_allclose(got[:, :, 3], record["xform"][:, :, 3], atol=2e-3)
    size = np.linalg.norm(record["xform"][:, :, :3], axis=1)[:, None, :]
    assert (np.abs(got[:, :, :3] - record["xform"][:, :, :3]) <= 2e-3 * size + 1e-5).all()
    # the roof polygons: a Mesh per tile with their triangles
    meshes = [UsdGeom.Mesh(p) for p in stage.Traverse() if p.IsA(UsdGeom.Mesh) and p.GetName() == "Meshes"]
    assert sum(len(m.GetFaceVertexCountsAttr().Get()) for m in meshes) == counts["mesh_triangles"] > 0
    assert (tiles_folder(path) / f"prototypes{'.usda' if suffix == '.usda' else '.usdc'}").is_file()


def test_a_failed_usd_build_leaves_nothing(tmp_path):
    from grammarc.io.usd import UsdWriter

    with pytest.raises(RuntimeError), UsdWriter(tmp_path / "c.usdc", assets=["builtin:cube"], symbols=["A"],
                                                 meta={}) as writer:
        raise RuntimeError("derivation failed")
    assert writer._state == "aborted" and sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_glb_asset_is_its_own_prototype(tmp_path):
    """The prototype Mesh of a GLB asset holds the asset's triangles, in its unit box."""
    _, path, triangles = glb_city(tmp_path, "masts.usda")
    stage = Usd.Stage.Open(str(tiles_folder(path) / "prototypes.usda"))
    (mesh,) = [UsdGeom.Mesh(p) for p in stage.Traverse()
               if p.IsA(UsdGeom.Mesh) and p.GetCustomDataByKey("grammarc:asset") == "mast.glb"]
    assert len(mesh.GetFaceVertexCountsAttr().Get()) == triangles
    points = np.array(mesh.GetPointsAttr().Get())
    np.testing.assert_allclose([points.min(0), points.max(0)], [[0, 0, 0], [1, 1, 1]], atol=1e-6)


def test_instances_with_a_texture_are_bound_to_a_material_reading_it(tmp_path):
    from pxr import UsdShade

    stage = Usd.Stage.Open(str(textured_city(tmp_path, TEXTURED, ".usda")))
    shaders = [UsdShade.Shader(p) for p in stage.Traverse() if p.GetTypeName() == "Shader"]
    files = [s.GetInput("file").Get() for s in shaders if s.GetIdAttr().Get() == "UsdUVTexture"]
    assert files and all(f.resolvedPath == str(tmp_path / "tex" / "wall.png") for f in files)
    bound = [p for p in stage.Traverse() if UsdShade.MaterialBindingAPI(p).GetDirectBinding().GetMaterial()]
    assert bound and all("_m1" in str(p.GetPath()) for p in bound)


def test_the_polygons_carry_the_records_texture_coordinates_as_st(tmp_path):
    record = np.load(textured_city(tmp_path, TEXTURED_GROUND, ".npz"))
    stage = Usd.Stage.Open(str(textured_city(tmp_path, TEXTURED_GROUND, ".usda")))
    meshes = [UsdGeom.Mesh(p) for p in stage.Traverse() if p.IsA(UsdGeom.Mesh) and p.GetName() == "Meshes"]
    assert meshes
    for mesh in meshes:
        st = UsdGeom.PrimvarsAPI(mesh).GetPrimvar("st")
        assert st.GetInterpolation() == UsdGeom.Tokens.vertex
        assert st.GetTypeName() == "texCoord2f[]"
        tile = UsdGeom.Xformable(mesh.GetPrim()).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
        points = np.array(mesh.GetPointsAttr().Get(), float) + np.array(tile.ExtractTranslation())
        np.testing.assert_allclose(np.array(st.Get(), float), nearest_uv(record, points), atol=1e-5)
        assert np.ptp(np.array(st.Get(), float), axis=0).tolist() == pytest.approx([3.0, 3.0])  # 12 x 9 m


def test_polygons_without_texture_coordinates_have_no_st(tmp_path):
    untextured = TEXTURED_GROUND.replace("setupProjection(0, scope.xz, 4, 3) projectUV(0) ", "")
    stage = Usd.Stage.Open(str(textured_city(tmp_path, untextured, ".usda")))
    meshes = [UsdGeom.Mesh(p) for p in stage.Traverse() if p.IsA(UsdGeom.Mesh) and p.GetName() == "Meshes"]
    assert meshes and not any(UsdGeom.PrimvarsAPI(m).HasPrimvar("st") for m in meshes)


def test_a_build_stopped_before_its_root_is_in_place_leaves_the_old_root_with_its_old_tiles(tmp_path, monkeypatch):
    """The new tiles go to a folder of their own that the new root names: until the root is renamed, the
    old root keeps its tiles; the next build removes the stopped one's folder."""
    import os

    from grammarc.io.usd import read_usd

    record, path, counts = city(tmp_path, "city.usdc", tile_size=100.0)
    before = read_usd(path)
    assert len(before["asset"]) == counts["instances"] == len(record["asset"])
    replace = os.replace

    def stop_at_the_root(source, target):
        if os.fspath(target) == os.fspath(path):
            raise KeyboardInterrupt  # stopped between the tiles and the root
        replace(source, target)

    monkeypatch.setattr(os, "replace", stop_at_the_root)
    with pytest.raises(KeyboardInterrupt):
        city(tmp_path, "city.usdc", tile_size=1000.0)
    monkeypatch.setattr(os, "replace", replace)
    after = read_usd(path)
    assert len(after["asset"]) == len(before["asset"]) and np.array_equal(after["xform"], before["xform"])
    assert tiles_folder(path).is_dir() and len(list(tmp_path.glob("city.usdc.tiles*"))) == 2  # and the orphan
    city(tmp_path, "city.usdc", tile_size=1000.0)
    assert [p.name for p in tmp_path.glob("city.usdc.tiles*")] == [tiles_folder(path).name]
    assert len(read_usd(path)["asset"]) == len(before["asset"])
