"""Checks of a 3D Tiles 1.1 tileset against its specifications, for the tests of ``io.tiles3d``.

The CesiumGS validator and the specification's JSON schemas are on no package registry this project
installs from, so the rules are written here from the specifications' text:

* ``TILESET``: the JSON schema of what a ``tileset.json`` (3D Tiles 1.1, "Tileset" and "Tile") may hold, with
  ``jsonschema``; and what a schema cannot say: each content's file exists, a child's geometric error is at
  most its parent's, a child's bounding box lies inside its parent's, the root says how it refines;
* ``check_content``: a GLB's ``EXT_mesh_gpu_instancing`` (TRANSLATION, ROTATION, SCALE and every other
  attribute of one count per node, ROTATION unit quaternions), ``EXT_instance_features`` and
  ``EXT_mesh_features`` (each feature ID set's attribute exists with one SCALAR per instance or vertex, not
  normalized, values in ``[0, featureCount)``, its property table exists with ``featureCount`` rows) and
  ``EXT_structural_metadata`` (the schema's id and classes, each table's class and properties, buffer views
  at multiples of 8 bytes, scalar columns of ``count`` values, string offsets rising from 0 to the bytes'
  length), and that every extension used is listed in ``extensionsUsed``.
"""

from __future__ import annotations

import json
from itertools import pairwise
from pathlib import Path

import jsonschema
import numpy as np

from grammarc.io.gltf import _read_part

_NUMBER = {"type": "number"}
_IDENTIFIER = {"type": "string", "pattern": "^[a-zA-Z_][a-zA-Z0-9_]*$"}
TILESET = {
    "$schema": "https://json-schema.org/draft/2020-12/schema",
    "type": "object",
    "required": ["asset", "geometricError", "root"],
    "properties": {
        "asset": {"type": "object", "required": ["version"],
                  "properties": {"version": {"const": "1.1"}, "tilesetVersion": {"type": "string"},
                                 "extras": {}, "extensions": {"type": "object"}}, "additionalProperties": False},
        "geometricError": {"type": "number", "minimum": 0},
        "root": {"$ref": "#/$defs/tile"},
        "extensionsUsed": {"type": "array", "items": {"type": "string"}, "minItems": 1, "uniqueItems": True},
        "extensionsRequired": {"type": "array", "items": {"type": "string"}, "minItems": 1, "uniqueItems": True},
        "extras": {}, "extensions": {"type": "object"},
    },
    "additionalProperties": False,
    "$defs": {
        "tile": {
            "type": "object",
            "required": ["boundingVolume", "geometricError"],
            "properties": {
                "boundingVolume": {"$ref": "#/$defs/boundingVolume"},
                "viewerRequestVolume": {"$ref": "#/$defs/boundingVolume"},
                "geometricError": {"type": "number", "minimum": 0},
                "refine": {"enum": ["ADD", "REPLACE"]},
                "transform": {"type": "array", "items": _NUMBER, "minItems": 16, "maxItems": 16},
                "content": {"$ref": "#/$defs/content"},
                "children": {"type": "array", "items": {"$ref": "#/$defs/tile"}, "minItems": 1, "uniqueItems": True},
                "extras": {}, "extensions": {"type": "object"},
            },
            "not": {"required": ["content", "contents"]},
            "additionalProperties": False,
        },
        "boundingVolume": {
            "type": "object",
            "properties": {"box": {"type": "array", "items": _NUMBER, "minItems": 12, "maxItems": 12},
                           "region": {"type": "array", "items": _NUMBER, "minItems": 6, "maxItems": 6},
                           "sphere": {"type": "array", "items": _NUMBER, "minItems": 4, "maxItems": 4},
                           "extras": {}, "extensions": {"type": "object"}},
            "anyOf": [{"required": ["box"]}, {"required": ["region"]}, {"required": ["sphere"]}],
            "additionalProperties": False,
        },
        "content": {
            "type": "object", "required": ["uri"],
            "properties": {"uri": {"type": "string"}, "boundingVolume": {"$ref": "#/$defs/boundingVolume"},
                           "group": {"type": "integer", "minimum": 0}, "extras": {}, "extensions": {"type": "object"}},
            "additionalProperties": False,
        },
    },
}
_COMPONENTS = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
_WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
_METADATA_SIZES = {"INT8": 1, "UINT8": 1, "INT16": 2, "UINT16": 2, "INT32": 4, "UINT32": 4, "INT64": 8, "UINT64": 8,
                   "FLOAT32": 4, "FLOAT64": 8}


def tiles(tile: dict, parent: dict | None = None):
    """(tile, parent) of every tile under ``tile``, depth first."""
    yield tile, parent
    for child in tile.get("children", []):
        yield from tiles(child, tile)


def box_bounds(box: list[float]) -> tuple[np.ndarray, np.ndarray]:
    """The low and high corners of an axis-aligned ``box`` (centre, half axes)."""
    centre, half = np.array(box[:3]), np.abs(np.array(box[3:]).reshape(3, 3)).sum(axis=0)
    return centre - half, centre + half


def check_tileset(folder: Path) -> dict:
    """``folder/tileset.json`` checked (module docstring); returns it."""
    tileset = json.loads((folder / "tileset.json").read_text())
    jsonschema.validate(tileset, TILESET, cls=jsonschema.Draft202012Validator)
    assert "refine" in tileset["root"], "the root tile must say how it refines"
    for tile, parent in tiles(tileset["root"]):
        if "content" in tile:
            assert (folder / tile["content"]["uri"]).is_file(), tile["content"]["uri"]
        if parent is not None:
            assert tile["geometricError"] <= parent["geometricError"]
            low, high = box_bounds(tile["boundingVolume"]["box"])
            outer_low, outer_high = box_bounds(parent["boundingVolume"]["box"])
            assert (low >= outer_low - 1e-6).all() and (high <= outer_high + 1e-6).all()
    return tileset


def read_accessor(tree: dict, blob: bytes, index: int) -> np.ndarray:
    accessor = tree["accessors"][index]
    view = tree["bufferViews"][accessor["bufferView"]]
    width = _WIDTHS[accessor["type"]]
    offset = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    values = np.frombuffer(blob, _COMPONENTS[accessor["componentType"]], accessor["count"] * width, offset)
    return values.reshape(-1, width) if width > 1 else values


def view_bytes(tree: dict, blob: bytes, index: int) -> bytes:
    view = tree["bufferViews"][index]
    return blob[view.get("byteOffset", 0):view.get("byteOffset", 0) + view["byteLength"]]


def property_tables(tree: dict, blob: bytes) -> list[dict[str, list]]:
    """The rows of each property table of a GLB, as {property: values}."""
    metadata = tree.get("extensions", {}).get("EXT_structural_metadata")
    if metadata is None:
        return []
    out = []
    for table in metadata["propertyTables"]:
        kinds = metadata["schema"]["classes"][table["class"]]["properties"]
        columns = {}
        for key, column in table["properties"].items():
            data = view_bytes(tree, blob, column["values"])
            if kinds[key]["type"] == "STRING":
                offsets = np.frombuffer(view_bytes(tree, blob, column["stringOffsets"]), np.uint32)
                columns[key] = [data[a:b].decode() for a, b in pairwise(offsets)]
            else:
                columns[key] = np.frombuffer(data, np.dtype(kinds[key]["componentType"].lower())).tolist()
        out.append(columns)
    return out


def check_content(path: Path) -> tuple[dict, bytes]:
    """A tile's GLB checked (module docstring); returns its JSON and binary chunk."""
    tree, blob = _read_part(path)
    used = set(tree.get("extensionsUsed", []))
    tables = _check_metadata(tree, blob, used)
    for node in tree.get("nodes", []):
        extensions = node.get("extensions", {})
        instancing = extensions.get("EXT_mesh_gpu_instancing")
        if instancing is not None:
            assert "EXT_mesh_gpu_instancing" in used
            counts = {read_accessor(tree, blob, a).shape[0] for a in instancing["attributes"].values()}
            assert len(counts) == 1, counts
            assert read_accessor(tree, blob, instancing["attributes"]["TRANSLATION"]).shape[1] == 3
            if "ROTATION" in instancing["attributes"]:
                rotation = read_accessor(tree, blob, instancing["attributes"]["ROTATION"])
                assert np.allclose(np.linalg.norm(rotation, axis=1), 1, atol=1e-5)
        if "EXT_instance_features" in extensions:
            assert instancing is not None, "EXT_instance_features needs EXT_mesh_gpu_instancing"
            assert "EXT_instance_features" in used
            _check_feature_ids(tree, blob, extensions["EXT_instance_features"], instancing["attributes"], tables)
    for mesh in tree.get("meshes", []):
        for primitive in mesh["primitives"]:
            features = primitive.get("extensions", {}).get("EXT_mesh_features")
            if features is not None:
                assert "EXT_mesh_features" in used
                _check_feature_ids(tree, blob, features, primitive["attributes"], tables)
    return tree, blob


def _check_feature_ids(tree: dict, blob: bytes, features: dict, attributes: dict, tables: list[dict]) -> None:
    count = read_accessor(tree, blob, next(iter(attributes.values()))).shape[0]
    assert features["featureIds"], "featureIds must not be empty"
    for feature_ids in features["featureIds"]:
        assert feature_ids["featureCount"] >= 1
        accessor = tree["accessors"][attributes[f"_FEATURE_ID_{feature_ids['attribute']}"]]
        assert accessor["type"] == "SCALAR" and not accessor.get("normalized", False)
        ids = read_accessor(tree, blob, attributes[f"_FEATURE_ID_{feature_ids['attribute']}"])
        assert ids.shape == (count,)
        assert (ids >= 0).all() and (ids < feature_ids["featureCount"]).all() and (ids == np.floor(ids)).all()
        if "propertyTable" in feature_ids:
            assert tables[feature_ids["propertyTable"]]["count"] == feature_ids["featureCount"]


def _check_metadata(tree: dict, blob: bytes, used: set[str]) -> list[dict]:
    metadata = tree.get("extensions", {}).get("EXT_structural_metadata")
    if metadata is None:
        return []
    assert "EXT_structural_metadata" in used
    schema = metadata["schema"]
    jsonschema.validate(schema["id"], _IDENTIFIER)
    for name, kind in schema["classes"].items():
        jsonschema.validate(name, _IDENTIFIER)
        for key, prop in kind["properties"].items():
            jsonschema.validate(key, _IDENTIFIER)
            assert prop["type"] in ("SCALAR", "STRING")
            assert prop["type"] == "STRING" or prop["componentType"] in _METADATA_SIZES
    for table in metadata["propertyTables"]:
        kinds = schema["classes"][table["class"]]["properties"]
        assert table["count"] >= 1 and set(table["properties"]) <= set(kinds)
        for key, column in table["properties"].items():
            views = [column["values"]] + ([column["stringOffsets"]] if "stringOffsets" in column else [])
            assert all(tree["bufferViews"][v].get("byteOffset", 0) % 8 == 0 for v in views)
            data = view_bytes(tree, blob, column["values"])
            if kinds[key]["type"] == "STRING":
                assert column.get("stringOffsetType", "UINT32") == "UINT32"
                offsets = np.frombuffer(view_bytes(tree, blob, column["stringOffsets"]), np.uint32)
                assert len(offsets) == table["count"] + 1 and offsets[0] == 0
                assert (np.diff(offsets.astype(np.int64)) >= 0).all() and offsets[-1] <= len(data)
            else:
                assert len(data) == table["count"] * _METADATA_SIZES[kinds[key]["componentType"]]
    return metadata["propertyTables"]
