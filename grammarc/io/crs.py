"""Coordinate systems of lots: what a file declares, and lots in longitude/latitude brought to metres.

A grammar measures in metres, so lots must be in a projected (metric) coordinate system. Files say theirs
in their own ways, which the format modules read into a ``LotBuilder`` (``declared``): GeoJSON's legacy
``crs`` member, GeoParquet's ``crs`` (PROJJSON), a GIS layer's through GDAL. Where a format has a default
that the file leaves implicit (GeoJSON, RFC 7946, and GeoParquet without ``crs``: OGC:CRS84, longitude
and latitude), it is taken where the coordinates are degrees, and otherwise the file is what grammarc's and
CityEngine's local scenes have always been: metres with no coordinate system (``crs`` None).

``georeference`` then decides, over all lots of a file at once, before they are cleaned (an edge of 0.8 mm
is nothing in degrees):

- geographic lots (longitude/latitude) are reprojected with pyproj to ``--crs``, else to WGS 84's UTM
  zone of their centre (north or south), and the lots say so (``Lots.crs``, ``Lots.crs_note``);
- projected lots stay in theirs (or go to ``--crs`` where one is asked for);
- lots without a coordinate system whose coordinates look like degrees are an error that says how to
  declare one (``--lots-crs``), never a city of zero-area lots.

Coordinates "look like degrees" when they lie within longitude and latitude ranges and the lots' median
extent is under ``DEGREE_EXTENT``: a building is 1e-4 degrees wide, and no lot in metres is 1 cm wide.
"""

from __future__ import annotations

import json

import numpy as np

from grammarc.errors import LotsError, UsageError
from grammarc.io.lot_format import LotsOptions

__all__ = ["CRS84", "georeference", "looks_like_degrees", "projjson"]

#: Longitude and latitude on WGS 84, in that order: GeoJSON's and GeoParquet's default.
CRS84 = "OGC:CRS84"
#: Median lot extent (in the file's units) below which coordinates within lon/lat ranges are degrees.
DEGREE_EXTENT = 0.01


def looks_like_degrees(xy: np.ndarray, counts: np.ndarray) -> bool:
    """Whether map coordinates ``xy`` (V, 2) of lots of ``counts`` (L,) vertices each (exterior rings and
    holes together) look like longitude and latitude (see the module docstring)."""
    if not len(xy):
        return False
    if np.abs(xy[:, 0]).max() > 180 or np.abs(xy[:, 1]).max() > 90:
        return False
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)[counts > 0]  # a lot may have none
    extent = np.maximum.reduceat(xy, starts) - np.minimum.reduceat(xy, starts)
    return float(np.median(extent.max(axis=1))) < DEGREE_EXTENT


def georeference(xy: np.ndarray, counts: np.ndarray, declared: str | None, implied: str | None,
                 options: LotsOptions, source: str) -> tuple[np.ndarray, str | None, str | None]:
    """Lots' map coordinates in metres, their coordinate system, and what was done (see the module docstring).

    Parameters
    ----------
    xy : (V, 2) float64
        Map coordinates (x, y: easting and northing, or longitude and latitude) of every vertex.
    counts : (L,) int64
        Vertices per lot, in order.
    declared : str or None
        The coordinate system the file names.
    implied : str or None
        The format's default where the file names none (``CRS84``), taken where the coordinates are degrees.
    options : LotsOptions
        The user's ``--lots-crs`` (overrides ``declared``) and ``--crs``.
    source : str
        The file, for messages.

    Returns
    -------
    xy : (V, 2) float64
        In the lots' coordinate system (reprojected where they were geographic).
    crs : str or None
        That coordinate system (as the file gave it, or ``EPSG:<code>`` of the one reprojected to); None:
        metres with no coordinate system.
    note : str or None
        What was read and done, for the build to say: ``"EPSG:4326 (longitude/latitude), reprojected to
        EPSG:32632 (WGS 84 / UTM zone 32N)"``; None where nothing was.

    Raises
    ------
    LotsError
        The lots name no coordinate system and look like degrees, or their coordinate system is unknown.
    UsageError
        pyproj is needed (a coordinate system to interpret or reproject) and not installed.
    """
    crs = options.lots_crs or declared
    degrees = looks_like_degrees(xy, counts)
    if crs is None and implied is not None and degrees:
        crs = implied
    if crs is None:
        if degrees:
            raise LotsError(f"{source}: the lots look like longitude/latitude degrees but the file names no "
                            "coordinate system: declare it with --lots-crs (e.g. --lots-crs EPSG:4326), and "
                            "grammarc reprojects them to metres")
        if options.crs is not None:
            raise LotsError(f"{source}: --crs {options.crs} asks to reproject lots that name no coordinate "
                            "system: declare theirs with --lots-crs")
        return xy, None, None
    if not degrees and options.crs is None and not _has_pyproj():
        return xy, crs, None  # projected, as its coordinates say: nothing to do, nothing to check it with
    pyproj = _pyproj(f"lots in {_short(crs)}")
    try:
        given = pyproj.CRS.from_user_input(crs)
    except pyproj.exceptions.CRSError as error:
        raise LotsError(f"{source}: unknown coordinate system {_short(crs)}: {error}") from error
    if not given.is_geographic and options.crs is None:
        return xy, crs, None
    if given.is_geographic and not degrees:
        raise LotsError(f"{source}: the lots name {_name(given)} (longitude/latitude) but their coordinates are "
                        "not degrees: declare their coordinate system with --lots-crs")
    target = pyproj.CRS.from_user_input(options.crs) if options.crs is not None else _utm(pyproj, xy)
    if target.is_geographic:
        raise UsageError(f"--crs {options.crs}: {_name(target)} is not in metres; give a projected one "
                         "(e.g. a UTM zone or a national grid)")
    transformer = pyproj.Transformer.from_crs(given, target, always_xy=True)
    x, y = transformer.transform(xy[:, 0], xy[:, 1])
    out = np.column_stack([x, y])
    if not np.isfinite(out).all():
        raise LotsError(f"{source}: some lots cannot be reprojected from {_name(given)} to {_name(target)}")
    kind = " (longitude/latitude)" if given.is_geographic else ""
    return out, _code(target), f"{_name(given)}{kind}, reprojected to {_name(target, full=True)}"


def projjson(crs: str | None) -> dict | None:
    """The PROJJSON of a coordinate system (what GeoParquet's ``crs`` holds), None for None."""
    if crs is None:
        return None
    try:
        return json.loads(crs) if crs.lstrip().startswith("{") else \
            _pyproj(f"writing the coordinate system {_short(crs)}").CRS.from_user_input(crs).to_json_dict()
    except ValueError as error:
        raise LotsError(f"unknown coordinate system {_short(crs)}: {error}") from error


def _utm(pyproj, xy: np.ndarray):
    """WGS 84's UTM zone of the middle of longitudes and latitudes ``xy`` (V, 2): EPSG 326zz north of the
    equator, 327zz south of it."""
    lon, lat = (xy.min(axis=0) + xy.max(axis=0)) / 2
    zone = int((lon + 180) // 6) % 60 + 1
    return pyproj.CRS.from_epsg((32600 if lat >= 0 else 32700) + zone)


def _code(crs) -> str:
    """``AUTHORITY:CODE`` of a coordinate system where it has one, else its WKT."""
    found = crs.to_authority()
    return f"{found[0]}:{found[1]}" if found else crs.to_wkt()


def _name(crs, full: bool = False) -> str:
    code = crs.to_authority()
    label = f"{code[0]}:{code[1]}" if code else crs.name
    return f"{label} ({crs.name})" if full and code else label


def _short(crs: str) -> str:
    return f"`{crs}`" if len(crs) < 60 else f"`{crs[:57]}...`"


def _has_pyproj() -> bool:
    import importlib.util

    return importlib.util.find_spec("pyproj") is not None


def _pyproj(what: str):
    try:
        import pyproj
    except ImportError:
        raise UsageError(f"{what} need pyproj for their coordinate system: pip install 'grammarc[gis]'") from None
    return pyproj
