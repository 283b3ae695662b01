"""Tests of grammarc.io.cityjson: a Building per lot, valid CityJSON 2.0, its surfaces the baked city's.

The structure is checked with a JSON schema of the parts of CityJSON 2.0 that grammarc writes, written here
from the specification (https://www.cityjson.org/specs/2.0.1/: the root object, transform, CityObjects of
type Building, MultiSurface geometry with semantics), and what a schema cannot say by code: vertex indices in
range, one semantic value per surface, every value naming a surface.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh
from writers_city import GRAMMAR

from grammarc.build import BuildOptions, build
from grammarc.io.cityjson import SURFACES

jsonschema = pytest.importorskip("jsonschema")

INDEX = {"type": "integer", "minimum": 0}
SCHEMA = {
    "type": "object",
    "required": ["type", "version", "transform", "CityObjects", "vertices"],
    "properties": {
        "type": {"const": "CityJSON"},
        "version": {"const": "2.0"},
        "transform": {"type": "object", "required": ["scale", "translate"], "properties": {
            "scale": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3},
            "translate": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}}},
        "metadata": {"type": "object", "properties": {"referenceSystem": {"type": "string",
                                                                          "pattern": "^https://www.opengis.net/def/crs/"}}},
        "CityObjects": {"type": "object", "additionalProperties": {
            "type": "object", "required": ["type", "geometry"],
            "properties": {
                "type": {"const": "Building"},
                "attributes": {"type": "object"},
                "geometry": {"type": "array", "items": {
                    "type": "object", "required": ["type", "lod", "boundaries"],
                    "properties": {
                        "type": {"const": "MultiSurface"},
                        "lod": {"type": "string", "pattern": r"^\d(\.\d)?$"},
                        "boundaries": {"type": "array", "items": {  # surfaces: rings: vertex indices
                            "type": "array", "minItems": 1, "items": {"type": "array", "minItems": 3, "items": INDEX}}},
                        "semantics": {"type": "object", "required": ["surfaces", "values"], "properties": {
                            "surfaces": {"type": "array", "items": {"type": "object", "required": ["type"]}},
                            "values": {"type": "array", "items": {"type": ["integer", "null"]}}}},
                    }}},
            }}},
        "vertices": {"type": "array", "items": {"type": "array", "items": {"type": "integer"},
                                                 "minItems": 3, "maxItems": 3}},
    },
}


def city(tmp_path, name: str = "city.city.json", **options):
    lots = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "id": f"lot{k}", "properties": {"use": "house", "storeys": 3 + k},
         "geometry": {"type": "Polygon", "coordinates": [[[x, y], [x + w, y], [x + w, y + 12], [x, y + 12], [x, y]]]}}
        for k, (x, y, w) in enumerate([(2_600_000, 1_200_000, 14), (2_600_020, 1_200_000, 10),
                                       (2_600_700, 1_200_010, 20)])],
        "crs": {"type": "name", "properties": {"name": "EPSG:2056"}}}
    (tmp_path / "lots.geojson").write_text(json.dumps(lots))
    (tmp_path / "g.cga").write_text(GRAMMAR)
    build(tmp_path / "g.cga", tmp_path / name, lots_path=tmp_path / "lots.geojson", options=BuildOptions(**options))
    return tmp_path / name


def check(document: dict) -> None:
    """The schema above, and what it cannot say."""
    jsonschema.validate(document, SCHEMA)
    n = len(document["vertices"])
    for building in document["CityObjects"].values():
        for geometry in building["geometry"]:
            indices = np.concatenate([np.ravel(ring) for surface in geometry["boundaries"] for ring in surface])
            assert indices.min() >= 0 and indices.max() < n
            semantics = geometry["semantics"]
            assert len(semantics["values"]) == len(geometry["boundaries"])
            assert {s["type"] for s in semantics["surfaces"]} <= set(SURFACES)
            assert all(v is None or 0 <= v < len(semantics["surfaces"]) for v in semantics["values"])


def test_a_building_per_lot_with_its_attributes_and_surfaces(tmp_path):
    document = json.loads(city(tmp_path).read_text())
    check(document)
    assert list(document["CityObjects"]) == ["lot0", "lot1", "lot2"]
    assert document["CityObjects"]["lot1"]["attributes"] == {"use": "house", "storeys": 4.0}
    assert document["metadata"]["referenceSystem"] == "https://www.opengis.net/def/crs/EPSG/0/2056"
    kinds = {s["type"] for b in document["CityObjects"].values() for g in b["geometry"]
             for s in g["semantics"]["surfaces"]}
    assert kinds == {"RoofSurface", "WallSurface", "GroundSurface"}


def test_the_surfaces_are_the_baked_city_to_the_millimetre(tmp_path):
    document = json.loads(city(tmp_path).read_text())
    transform = document["transform"]
    vertices = np.array(document["vertices"]) * transform["scale"] + transform["translate"]
    baked = trimesh.load(city(tmp_path, "city.obj"), force="mesh", process=False).vertices
    # world x east, y up, z south; CityJSON easting, northing, height
    expected = np.column_stack([baked[:, 0], -baked[:, 2], baked[:, 1]])
    np.testing.assert_allclose(vertices.min(axis=0), expected.min(axis=0), atol=1e-3)
    np.testing.assert_allclose(vertices.max(axis=0), expected.max(axis=0), atol=1e-3)
    assert 2_600_000 <= vertices[:, 0].min() < 2_600_001 and vertices[:, 2].max() > 8


def test_the_file_does_not_depend_on_the_chunking(tmp_path):
    one = city(tmp_path, "a.city.json").read_bytes()
    assert city(tmp_path, "b.city.json", chunk_size=1).read_bytes() == one


#: cjio's command, installed beside the Python that runs the tests (the `dev` extra).
CJIO = Path(sys.executable).parent / "cjio"


@pytest.mark.skipif(not CJIO.is_file(), reason="cjio not installed")
def test_cjio_reads_it(tmp_path):
    done = subprocess.run([str(CJIO), str(city(tmp_path)), "info", "--long"], capture_output=True, text=True,
                          check=True)
    assert "CityJSON version = 2.0" in done.stdout and "EPSG = 2056" in done.stdout
    assert "Building (3)" in done.stdout and "attributes = ['storeys', 'use']" in done.stdout
    assert "semantics surfaces = ['GroundSurface', 'RoofSurface', 'WallSurface']" in done.stdout
