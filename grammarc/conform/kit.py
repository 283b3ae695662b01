"""The PRT conformance kit: where it is, its reference records, its footprints and PyPRT's side environment.

The kit (``../shared/prt`` from the repository root, see its README) holds rule packages, footprints and
``reference.json``: one record per (rule package, footprint, attributes, seed) as PRT made it, with the
fields described in the file's ``meta.fields``. A record is found by those four keys (``rpk`` and
``footprint`` are names without folder or extension, ``attrs`` the attributes that were set, ``seed`` the
shape's seed, 0 in every record).
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from pathlib import Path, PurePath

from grammarc.errors import UsageError

__all__ = ["find_record", "footprint_geojson", "footprint_path", "kit_dir", "load_reference", "prt_python"]


def kit_dir() -> Path:
    """The PRT conformance kit: ``$GRAMMARC_PRT_KIT``, else ``shared/prt`` beside the repository.

    The folder need not exist; callers check (tests skip when it is absent).
    """
    override = os.environ.get("GRAMMARC_PRT_KIT")
    if override:
        return Path(override)
    return Path(__file__).resolve().parents[2].parent / "shared" / "prt"


def load_reference(path: str | os.PathLike | None = None) -> dict:
    """Load PRT's reference records.

    Parameters
    ----------
    path : path-like, optional
        ``reference.json``, or the kit folder holding it; ``kit_dir()`` by default.

    Returns
    -------
    dict
        ``{"meta": ..., "rpks": {name: ...}, "records": [record, ...]}`` as stored.

    Raises
    ------
    UsageError
        If the file does not exist.
    """
    path = Path(path) if path is not None else kit_dir()
    if path.is_dir():
        path = path / "reference.json"
    if not path.is_file():
        raise UsageError(f"PRT reference records `{path}` not found (the PRT kit is ../shared/prt from "
                         "the repository root; set GRAMMARC_PRT_KIT to use another)")
    with open(path, encoding="utf-8") as file:
        return json.load(file)


def find_record(
    reference: Mapping,
    rpk_name: str,
    footprint_name: str,
    attrs: Mapping | None = None,
    *,
    seed: int = 0,
) -> dict | None:
    """The reference record of a rule package on a footprint with attributes, or None.

    Parameters
    ----------
    reference : mapping
        As returned by ``load_reference``.
    rpk_name : str
        ``"candler"``; a file name or path (``"rpk/candler.rpk"``) is reduced to its stem.
    footprint_name : str
        ``"rect_30x20"``; likewise reduced to its stem.
    attrs : mapping, optional
        The attributes set. Numbers compare as floats (``40`` matches ``40.0``). A record with exactly
        these attributes is preferred; else a record whose attributes, with the defaults PRT used
        (``attributes_used``), give the same values (``{"BuildingHeight": 62.0}`` finds candler's
        default record, whose ``BuildingHeight`` is 62).
    seed : int
        The shape's seed; 0 in every record of the kit.

    Examples
    --------
    >>> reference = load_reference()                                              # doctest: +SKIP
    >>> find_record(reference, "extrude_color", "rect_30x20")["surface_area"]     # doctest: +SKIP
    1700.0
    """
    rpk = PurePath(rpk_name).stem if rpk_name.endswith(".rpk") else PurePath(rpk_name).name
    footprint = PurePath(footprint_name).name
    if PurePath(footprint).suffix in (".obj", ".json", ".geojson"):
        footprint = PurePath(footprint).stem
    wanted = _values(attrs or {})
    candidates = [
        r for r in reference.get("records", ())
        if r.get("rpk") == rpk and r.get("footprint") == footprint and r.get("seed", 0) == seed
    ]  # fmt: skip
    for record in candidates:
        if _values(record.get("attrs", {})) == wanted:
            return record
    for record in sorted(candidates, key=lambda r: len(r.get("attrs", {}))):
        used = _values(record.get("attributes_used", {}))
        if {**used, **_values(record.get("attrs", {}))} == {**used, **wanted}:
            return record
    return None


def _values(attrs: Mapping) -> dict:
    """Attributes with numbers as floats (bools kept), so that 40 and 40.0 compare equal."""
    return {
        str(k): float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else v
        for k, v in attrs.items()
    }



def footprint_geojson(name: str, kit: str | os.PathLike | None = None) -> dict:
    """A kit footprint as a GeoJSON FeatureCollection of one feature, from ``footprints/all.geojson``.

    Write it to a file to build with ``--lots``: grammarc maps it to PRT's world as the kit does
    (world x = x, world z = -y). ``name`` is a ``properties.name``, e.g. ``"courtyard_40x40"``.

    Raises
    ------
    UsageError
        If the kit or the footprint is missing.
    """
    path = Path(kit) if kit is not None else kit_dir()
    path = path / "footprints" / "all.geojson"
    if not path.is_file():
        raise UsageError(f"PRT kit footprints `{path}` not found")
    with open(path, encoding="utf-8") as file:
        collection = json.load(file)
    features = [f for f in collection["features"] if f.get("properties", {}).get("name") == name]
    if not features:
        names = ", ".join(f.get("properties", {}).get("name", "?") for f in collection["features"])
        raise UsageError(f"no footprint `{name}` in {path} (footprints: {names})")
    return {"type": "FeatureCollection", "features": features}



def footprint_path(name: str, kit: Path | None = None) -> Path:
    """A kit footprint by name (``rect_30x20``; the courtyard is its PRT JSON), or a path as given."""
    path = Path(name)
    if path.suffix:
        return path
    folder = (kit or kit_dir()) / "footprints"
    for suffix in (".obj", ".json"):
        candidate = folder / f"{name}{suffix}"
        if candidate.is_file():
            return candidate
    raise UsageError(f"no footprint `{name}` in {folder}")



def prt_python() -> Path | None:
    """PyPRT's side environment: ``$GRAMMARC_PRT_PYTHON``, else ``.prt-venv/bin/python`` beside the package.

    None when neither exists (the kit's README says how to make it).
    """
    configured = os.environ.get("GRAMMARC_PRT_PYTHON")
    python = Path(configured) if configured else Path(__file__).resolve().parents[2] / ".prt-venv" / "bin" / "python"
    return python if python.is_file() else None
