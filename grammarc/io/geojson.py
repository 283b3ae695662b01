"""Lots of a GeoJSON document (``.geojson``, ``.json``), or of a PRT initial shape as JSON.

GeoJSON may be a FeatureCollection, a single Feature or a bare Polygon / MultiPolygon geometry. Its
coordinates are longitude and latitude (RFC 7946) where they are degrees, else metres of a local scene,
unless a legacy ``crs`` member names their coordinate system (``io.crs``). Features become lots as
``io.lot_builder.parse_features`` says (a MultiPolygon a lot per polygon, other geometries bad lots), and
their properties ``attrs`` columns, typed over all polygon lots of the file.

A ``.json`` file holding a PRT initial shape (``vertices``, ``face_indices``, ``face_counts``, ``holes``
in world coordinates, the arguments of ``pyprt.InitialShape``, as the PRT kit's
``courtyard_40x40.json``) is read too: one lot per face that is not a hole, ids ``"face<k>"``.

The document is read whole; a city too large for that is a GeoJSON sequence (``io.geojson_sequence``) or
GeoParquet (``io.geoparquet``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import orjson

from grammarc.errors import LotsError
from grammarc.io.crs import CRS84
from grammarc.io.lot_builder import LotBuilder, parse_features, property_columns
from grammarc.io.lot_format import NO_OPTIONS, LotsFormat, LotsOptions, read_text
from grammarc.model.lots import Lots

__all__ = ["FORMAT", "read_geojson"]


def read_geojson(path: Path, options: LotsOptions = NO_OPTIONS) -> Lots:
    """All lots of a GeoJSON document or a PRT initial shape as JSON (see the module docstring).

    Raises
    ------
    LotsError
      The file is unreadable, not valid JSON (with its line and column), not a PRT shape though it looks
      like one, or holds no polygon.
    """
    try:
        data = orjson.loads(read_text(path))  # about twice as fast as the stdlib on city-sized files
    except orjson.JSONDecodeError as error:
        raise LotsError(f"{path}:{error.lineno}:{error.colno}: not valid JSON: {error.msg}") from error
    if isinstance(data, dict) and "face_counts" in data and "type" not in data:
        return _prt_shape(data, path).finish_file({}, path, options)
    builder = parse_features(_features(data), 0, options.id_field)
    builder.declared, builder.implied = _declared_crs(data, path), CRS84
    return builder.finish_file(property_columns(builder.props), path, options)


def _declared_crs(data, path: Path) -> str | None:
    """The coordinate system a GeoJSON document names in its ``crs`` member (the 2008 specification's:
    ``{"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::2056"}}``), None without one."""
    member = data.get("crs") if isinstance(data, dict) else None
    if member is None:
        return None
    properties = member.get("properties") if isinstance(member, dict) else None
    if isinstance(properties, dict) and isinstance(properties.get("name"), str):
        return properties["name"]
    if isinstance(properties, dict) and member.get("type") == "EPSG" and "code" in properties:
        return f"EPSG:{properties['code']}"
    raise LotsError(f"{path}: its `crs` member names no coordinate system: {orjson.dumps(member).decode()[:80]}")


def _features(data) -> list:
    """The features of a FeatureCollection, a Feature or a bare geometry."""
    if isinstance(data, dict) and data.get("type") == "FeatureCollection":
        return data.get("features") or []
    if isinstance(data, dict) and data.get("type") == "Feature":
        return [data]
    if isinstance(data, dict):
        return [{"type": "Feature", "geometry": data}]
    return []


def _prt_shape(data: dict, path: Path) -> LotBuilder:
    """A PRT initial shape as JSON: the arguments of ``pyprt.InitialShape`` (vertices, indices, counts,
    holes), in world coordinates; a hole face is listed after its face in ``holes``."""
    try:
        vertices = np.asarray(data["vertices"], dtype=np.float64).reshape(-1, 3)
        indices = np.asarray(data["face_indices"], dtype=np.int64)
        faces = np.split(indices, np.cumsum(data["face_counts"])[:-1])
        holes = {int(group[0]): [int(h) for h in group[1:]] for group in data.get("holes") or []}
        is_hole = {h for group in holes.values() for h in group}
        builder = LotBuilder(world=True)
        lots = [k for k in range(len(faces)) if k not in is_hole]
        for index, k in enumerate(lots):
            builder.add(index, f"face{k}", [vertices[faces[f]] for f in [k, *holes.get(k, [])]], {})
    except (KeyError, TypeError, ValueError, IndexError) as error:
        raise LotsError(f"{path}: not a PRT initial shape ({error!r})") from error
    return builder


FORMAT = LotsFormat(kind="geojson", suffixes=(".geojson", ".json"), title=None, read=read_geojson)
