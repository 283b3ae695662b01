"""A small city for the instanced writers' tests: built with ``grammarc build`` into an npz record and
into the format under test, from lots far from the origin (x 12 km), with flat faces (quads), a mirrored
split, colours and a polygon of the mesh table."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from grammarc.build import build
from grammarc.io import OutputOptions
from grammarc.io.npz import read_instances

GRAMMAR = """
Lot --> extrude(9) comp(f){ side : Facade | top : Roof }
Facade --> split(y){ 3 : Floor }*
Floor --> split(x){ ~2 : Tile }*
Tile --> case split.index % 2 == 0 : color("#c04020") Window. else : mirror(true, false, false) Wall
Wall --> i("builtin:cube")
Roof --> roofHip(25)
"""


def city(tmp_path: Path, output: str, **options) -> tuple[dict, Path, dict]:
    """(the npz record, the output path, the writer's counts) of the city written as ``output``."""
    lots = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "id": f"lot{k}", "properties": {},
         "geometry": {"type": "Polygon", "coordinates": [[[x, y], [x + w, y], [x + w, y + 12], [x, y + 12],
                                                          [x, y]]]}}
        for k, (x, y, w) in enumerate([(12_000, 300, 14), (12_020, 300, 10), (12_700, 310, 20)])]}
    (tmp_path / "lots.geojson").write_text(json.dumps(lots))
    (tmp_path / "g.cga").write_text(GRAMMAR)
    build(tmp_path / "g.cga", tmp_path / "city.npz", lots_path=tmp_path / "lots.geojson")
    result = build(tmp_path / "g.cga", tmp_path / output, lots_path=tmp_path / "lots.geojson",
                   output_options=OutputOptions(**options))
    return read_instances(tmp_path / "city.npz"), tmp_path / output, result.counts


def world(position, orientation_xyzw, scale) -> np.ndarray:
    """(n, 3, 4) affine maps of translation, rotation and scale, the record's convention."""
    from scipy.spatial.transform import Rotation

    rotation = Rotation.from_quat(np.asarray(orientation_xyzw, float)).as_matrix()
    linear = rotation * np.asarray(scale, float)[:, None, :]
    return np.concatenate([linear, np.asarray(position, float)[:, :, None]], axis=2)
