"""Instanced glTF: trimesh opens the GLB, and its EXT_mesh_gpu_instancing nodes hold the record's
instances; a city past the size of a part is split into parts with an index."""

import json

import numpy as np
import pytest
import trimesh
from writers_city import TEXTURED, TEXTURED_GROUND, city, glb_city, nearest_uv, textured_city, world

from grammarc.io.gltf import MAX_BYTES, GltfWriter, _read_part, part_paths, written_parts
from grammarc.model.records import MeshChunk, TerminalChunk

pygltflib = pytest.importorskip("pygltflib")


def accessor(gltf, blob: bytes, index: int) -> np.ndarray:
    a = gltf.accessors[index]
    view = gltf.bufferViews[a.bufferView]
    dtype = {5126: np.float32, 5125: np.uint32, 5121: np.uint8}[a.componentType]
    width = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[a.type]
    data = np.frombuffer(blob, dtype, a.count * width, view.byteOffset + (a.byteOffset or 0))
    return data.reshape(a.count, width) if width > 1 else data


def instances(path) -> tuple[np.ndarray, list[str]]:
    """World transforms (n, 3, 4) and asset names of every instance of a GLB, tile by tile."""
    gltf = pygltflib.GLTF2().load(str(path))
    blob = gltf.binary_blob()
    xforms, names = [], []
    for tile in gltf.scenes[0].nodes:
        origin = np.array(gltf.nodes[tile].translation)
        for child in gltf.nodes[tile].children:
            node = gltf.nodes[child]
            if not node.extensions:
                continue
            attributes = node.extensions["EXT_mesh_gpu_instancing"]["attributes"]
            t, r, s = (accessor(gltf, blob, attributes[k]) for k in ("TRANSLATION", "ROTATION", "SCALE"))
            xforms.append(world(t + origin, r, s))
            names += [gltf.meshes[node.mesh].name] * len(t)
    return np.concatenate(xforms), names


def test_glb_holds_the_record_and_trimesh_opens_it(tmp_path):
    record, path, counts = city(tmp_path, "city.glb", tile_size=100.0)
    scene = trimesh.load(path)  # without the extension, a viewer shows each group's mesh once
    assert isinstance(scene, trimesh.Scene) and len(scene.geometry) >= 2
    got, names = instances(path)
    assert counts["instances"] == len(got) == len(record["asset"]) and counts["parts"] == 1
    # tiles group by asset and colour: match the record's rows by asset and position
    want = record["xform"].astype(float)
    wanted = np.lexsort(np.round(want[:, :, 3], 2).T)
    found = np.lexsort(np.round(got[:, :, 3], 2).T)
    np.testing.assert_allclose(got[found], want[wanted], atol=2e-5 * 40)
    assert [names[i] for i in found] == list(record["assets"][record["asset"]][wanted])
    gltf = pygltflib.GLTF2().load(str(path))
    colours = {tuple(np.round(m.pbrMetallicRoughness.baseColorFactor, 3)) for m in gltf.materials}
    assert (0.527, 0.051, 0.014, 1.0) in colours  # #c04020 in linear light


def test_a_large_city_is_split_into_parts(tmp_path):
    """Parts of at most ``max_bytes`` of binary (a tile is not split): city.glb, city.1.glb, ... and
    the index city.glb.json; together they hold every instance."""
    record, _, _ = city(tmp_path, "city.npz")
    path = tmp_path / "small.glb"
    with GltfWriter(path, assets=list(record["assets"]), symbols=list(record["symbols"]), meta=record["meta"],
                    tile_size=10.0, max_bytes=3000) as writer:
        writer.write(TerminalChunk(asset=record["asset"], xform=record["xform"], lot=record["lot"],
                                   symbol=record["symbol"], mesh=MeshChunk.empty(), color=record["color"]))
        parts = writer.close()["parts"]
    assert parts > 2
    index = json.loads(path.with_name("small.glb.json").read_text())
    assert index["parts"] == [p.name for p in part_paths(path, parts)] and index["parts"][0] == "small.glb"
    assert sum(index["instances"]) == sum(len(instances(p)[0]) for p in part_paths(path, parts)) == len(
        record["asset"])
    for part in part_paths(path, parts):
        gltf = pygltflib.GLTF2().load(str(part))
        assert gltf.buffers[0].byteLength <= 3000 + 2000  # the asset meshes a part needs come on top


def test_a_glb_asset_is_its_own_prototype(tmp_path):
    """The prototype of a GLB asset is its mesh (both nodes), not a box; its instances are the record's."""
    record, path, triangles = glb_city(tmp_path, "masts.glb")
    gltf = pygltflib.GLTF2().load(str(path))
    (mesh,) = [m for m in gltf.meshes if m.name == "mast.glb"]
    assert sum(gltf.accessors[p.indices].count for p in mesh.primitives) == 3 * triangles
    got, names = instances(path)
    assert names == ["mast.glb"] * 3
    np.testing.assert_allclose(got[np.argsort(got[:, 0, 3])], record["xform"], atol=1e-4)


def test_an_instanced_glb_embeds_its_textures(tmp_path):
    tree, _ = _read_part(textured_city(tmp_path, TEXTURED, ".glb"))
    assert tree["images"] == [{"bufferView": tree["images"][0]["bufferView"], "mimeType": "image/png"}]
    textured = [m for m in tree["materials"] if "baseColorTexture" in m["pbrMetallicRoughness"]]
    assert len(textured) == 1
    # the walls' mesh (an (asset, material) group) has the textured material
    used = {p["material"] for mesh in tree["meshes"] for p in mesh["primitives"]}
    assert tree["materials"].index(textured[0]) in used


def test_the_polygons_carry_the_records_texture_coordinates(tmp_path):
    """``TEXCOORD_0`` of each tile's polygon mesh: the record's, v turned down the image as glTF has it."""
    record = np.load(textured_city(tmp_path, TEXTURED_GROUND, ".npz"))
    path = textured_city(tmp_path, TEXTURED_GROUND, ".glb")
    assert isinstance(trimesh.load(path), trimesh.Scene)
    gltf = pygltflib.GLTF2().load(str(path))
    blob = gltf.binary_blob()
    checked = 0
    for tile in gltf.scenes[0].nodes:
        origin = np.array(gltf.nodes[tile].translation)
        for child in gltf.nodes[tile].children:
            mesh = gltf.meshes[gltf.nodes[child].mesh]
            if not mesh.name.endswith("_polygons"):
                continue
            attributes = mesh.primitives[0].attributes
            points = accessor(gltf, blob, attributes.POSITION) + origin
            uv = accessor(gltf, blob, attributes.TEXCOORD_0).astype(float)
            np.testing.assert_allclose(np.stack([uv[:, 0], 1 - uv[:, 1]], axis=1), nearest_uv(record, points),
                                       atol=1e-5)
            checked += len(points)
    assert checked >= 2 * 8 * 3  # two rings with a hole: eight triangles each


def test_a_city_of_one_part_replaces_one_of_many_without_leaving_its_index_or_parts(tmp_path):
    record, _, _ = city(tmp_path, "city.npz")
    path = tmp_path / "small.glb"
    for max_bytes in (3000, MAX_BYTES):
        with GltfWriter(path, assets=list(record["assets"]), symbols=list(record["symbols"]), meta=record["meta"],
                        tile_size=10.0, max_bytes=max_bytes) as writer:
            writer.write(TerminalChunk(asset=record["asset"], xform=record["xform"], lot=record["lot"],
                                       symbol=record["symbol"], mesh=MeshChunk.empty(), color=record["color"]))
            parts = writer.close()["parts"]
    assert parts == 1 and sorted(p.name for p in tmp_path.glob("small*")) == ["small.glb"]
    assert written_parts(path) == [path] and len(instances(path)[0]) == len(record["asset"])
