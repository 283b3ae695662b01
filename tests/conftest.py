"""Shared fixtures: strict invariant checks on, a zoo of small grammars and lots.

The zoo holds named inputs that tests parametrize over (shapely's ``tests/common.py`` habit): lots that are
square, concave, with a hole, a sliver, and grammars in the paper notation.
"""

from __future__ import annotations

import os

os.environ.setdefault("GRAMMARC_STRICT", "1")
# The tests' grammars make fused kernels and extracted packages of their own: they go to a cache of the tests
# (kept between runs, as the user's is), not into the user's, all of whose kernels a warm server loads.
from grammarc.frontend.user_cache import cache_home

os.environ["XDG_CACHE_HOME"] = os.path.join(cache_home(), "grammarc-tests")

import importlib.util
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

from grammarc.io.lots import lots_from_polygons
from grammarc.model.records import world_columns

#: ``pytest --hypothesis-profile long``: the property tests that do not fix their number of examples (the
#: fuzz of ``test_build_fuzz.py``) run for hours rather than a hundred examples each.
settings.register_profile("long", max_examples=20_000)
#: Without a profile, every run draws the same examples (CI's result is the code's, not the draw's); the
#: long profile draws new ones each run.
settings.register_profile("fixed", derandomize=True)
settings.load_profile("fixed")

PRT_KIT = Path(__file__).resolve().parents[1].parent / "shared" / "prt"
#: Tests of conformance with PRT: the kit's records, and PyPRT's side environment for the live harness.
needs_kit = pytest.mark.skipif(not (PRT_KIT / "reference.json").is_file(),
                               reason="PRT kit (../shared/prt) absent")
needs_scipy = pytest.mark.skipif(importlib.util.find_spec("scipy") is None, reason="scipy not installed")
needs_earcut = pytest.mark.skipif(importlib.util.find_spec("mapbox_earcut") is None,
                                  reason="mapbox-earcut not installed")


@pytest.fixture(scope="session")
def prt_reference():
    """The PRT kit's reference records (``grammarc.conform.load_reference``)."""
    from grammarc.conform import load_reference

    return load_reference(PRT_KIT)

#: Footprints in map coordinates (x east, y north), exterior counter-clockwise, holes clockwise.
LOT_ZOO = {
    "square": [np.array([[0, 0], [10, 0], [10, 10], [0, 10]], float)],
    "rect_12x8": [np.array([[0, 0], [12, 0], [12, 8], [0, 8]], float)],
    "concave_L": [np.array([[0, 0], [30, 0], [30, 10], [10, 10], [10, 20], [0, 20]], float)],
    "courtyard": [
        np.array([[0, 0], [40, 0], [40, 40], [0, 40]], float),
        np.array([[10, 10], [10, 30], [30, 30], [30, 10]], float),
    ],
    "sliver": [np.array([[0, 0], [50, 0], [50, 0.05], [0, 0.05]], float)],
}


def in_world(record: dict) -> dict:
    """``record`` (of ``build.derive`` or ``read_instances``) with its transforms and mesh vertices in world
    coordinates, float64 (``model.records.LotOrigins`` added): how the tests that place things on their
    lots read a record."""
    xform, vertices = world_columns(record)
    out = {key: value for key, value in record.items() if key != "lot_origin"}
    out["xform"] = xform
    if "mesh" in record:
        out["mesh"] = replace(record["mesh"], vertices=vertices)
    elif "mesh_vertices" in record:
        out["mesh_vertices"] = vertices
    return out


def make_lots(*names: str, attrs: dict | None = None):
    """Lots from the zoo by name, ids equal to the names."""
    return lots_from_polygons([LOT_ZOO[n] for n in names], ids=list(names), attrs=attrs)


def example_script(folder: Path, name: str):
    """Import one of an example's scripts (``examples/NAME`` is not a package)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location(f"{folder.name}_{name}", folder / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture
def write(tmp_path):
    """Write a text file under tmp_path and return its path: ``write("g.cga", text)``."""

    def _write(name: str, text: str) -> Path:
        path = tmp_path / name
        path.write_text(text, encoding="utf-8")
        return path

    return _write


@pytest.fixture
def georeferenced_lots(tmp_path) -> Path:
    """One 30 x 20 m lot in UTM 33N, as GeoParquet (``tmp_path/lots.parquet``): lots as a GIS user has them,
    read through Arrow and PROJ. Skipped without the ``parquet`` and ``gis`` extras."""
    import json

    from grammarc.cli import main

    pytest.importorskip("pyarrow")
    pytest.importorskip("pyproj")
    ring = [[500000, 6000000], [500030, 6000000], [500030, 6000020], [500000, 6000020], [500000, 6000000]]
    (tmp_path / "lots.geojson").write_text(json.dumps({
        "type": "FeatureCollection", "crs": {"type": "name", "properties": {"name": "EPSG:32633"}},
        "features": [{"type": "Feature", "properties": {"id": "a"},
                      "geometry": {"type": "Polygon", "coordinates": [ring]}}]}))
    assert main(["lots", str(tmp_path / "lots.geojson"), "--to", str(tmp_path / "lots.parquet")]) == 0
    return tmp_path / "lots.parquet"
