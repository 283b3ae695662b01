"""``grammarc info OUT``: what a city's output holds, without opening another program.

OUT is an instance record (``.npz``), or instanced USD, glTF or 3D Tiles as ``build`` writes them (read back
by ``io.usd.read_usd``, ``io.gltf.read_glb`` and ``io.tiles3d.read_tileset``, its leaves): glTF keeps no
lots or symbols, so those lines are left out for it; the bytes are those of every file of the output (USD's
tile layers, glTF's parts, a tileset's tiles, the coarse ones too).

Counts per asset and per symbol, terminals per lot (min, median, max), the bounding box, and what the city
weighs once instanced assets are expanded: polygons and triangles as ``bake`` would make them (each asset
counted once from its mesh, times its instances; the mesh table's faces as they are), next to the
instanced count (a prototype's polygons once per asset, plus the mesh table). Asset files are looked up
as the writers do (the grammar's folder, then the record's ``--assets`` folders); an asset that cannot be
loaded is reported and left out of the polygon counts rather than failing the summary.
"""

from __future__ import annotations

import contextlib
import glob
import os
from collections import Counter
from pathlib import Path

import numpy as np

from grammarc.errors import AssetError
from grammarc.io.bake import count_triangles
from grammarc.io.npz import read_instances
from grammarc.io.rpk import record_asset_roots
from grammarc.io.shards import is_manifest, manifest_path, shard_outputs
from grammarc.model.assets import asset_library
from grammarc.model.records import world_columns

__all__ = ["READS", "format_summary", "summarize", "what_file"]

#: What ``summarize`` reads, for the message about a file it cannot.
READS = (".npz instance records, .usda/.usdc/.usd, .glb and .3dtiles outputs of build, a cluster build's "
         ".manifest.json")
#: A file's first bytes -> what it is, for a file ``summarize`` cannot read.
_MAGIC = {b"PK\x03\x04": "a zip archive that is not an instance record", b"\x93NUMPY": "a single numpy array (.npy)",
          b"glTF": "a glTF file that is not an output of build", b"#usda": "a USD layer that is not an output of build",
          b"PXR-USDC": "a USD layer that is not an output of build", b"ply": "a PLY mesh", b"\x89PNG": "a PNG picture",
          b"PAR1": "a Parquet file (lots? `grammarc lots` reads them)", b"SQLite": "a database (a GeoPackage?)"}
#: Suffixes of files build writes that are not records: what they are.
_MESHES = "a baked mesh, which build writes but info does not read (build --emit city.npz writes the record)"
_WRITTEN = {".obj": _MESHES, ".ply": _MESHES, ".stl": _MESHES, ".json": "JSON (CityJSON? reports?)",
            ".geojson": "GeoJSON (lots? `grammarc lots` reads them)", ".cga": "a grammar (`grammarc check` reads it)",
            ".rpk": "a rule package (`grammarc check` reads it)"}


def summarize(path: str | os.PathLike, asset_roots=None, lod: str | None = None) -> dict:
    """The facts ``grammarc info`` prints, as a JSON-ready dict (see the module docstring).

    ``path`` may be the manifest of a cluster build (``io.shards``): its shards are read one at a time and
    their counts added up, so a city larger than memory can be summarized.
    """
    path = Path(path)
    if (path.suffix.lower() in (".usd", ".usda", ".usdc") and manifest_path(path).is_file()
            and not any(path.parent.glob(f"{glob.escape(path.name)}.tiles*"))):
        path = manifest_path(path)  # the root layer of a cluster build's shards
    with contextlib.ExitStack() as package:
        tallies = []
        for part in shard_outputs(path) if is_manifest(path) else [path]:
            record, files = _read(part)
            if not tallies:  # a rule package's assets: opened again while the summary is made
                asset_roots = package.enter_context(record_asset_roots(record["meta"], asset_roots))
            tallies.append(_tally(record, files, asset_roots, lod))
        return _summary(path, tallies, asset_roots, lod)


def what_file(path: str | os.PathLike) -> str:
    """What a file that ``summarize`` cannot read seems to be: by its first bytes, else its suffix, else
    text or not."""
    path = Path(path)
    with open(path, "rb") as file:
        head = file.read(64)
    found = next((what for magic, what in _MAGIC.items() if head.startswith(magic)), None)
    if found is None and path.suffix.lower() in _WRITTEN:
        found = _WRITTEN[path.suffix.lower()]
    if found is None:
        try:
            head.decode()
        except UnicodeDecodeError:
            return "a binary file of another kind"
        return "a text file" if head else "an empty file"
    return found


def _summary(path: Path, tallies: list[dict], asset_roots, lod: str | None) -> dict:
    """The summary of ``tallies``, the assets loaded from ``asset_roots`` (or the record's own)."""
    per_asset = sum((Counter(t["assets"]) for t in tallies), Counter())
    symbols = sum((Counter(t["symbols"]) for t in tallies), Counter())
    names = list(per_asset)
    per_lot = np.concatenate([t["per_lot"] for t in tallies])
    points = [t["bbox"] for t in tallies if t["bbox"] is not None]
    meta = tallies[0]["meta"] if tallies else {}
    mesh_rings = sum(t["mesh_rings"] for t in tallies)
    library = asset_library(names, {"meta": meta}, asset_roots, lod)
    assets, polygons, instanced, problems = {}, 0, mesh_rings, []
    for index, name in enumerate(names):
        entry = {"instances": per_asset[name]}
        try:
            shape = library[index]
        except AssetError as error:
            problems.append(str(error))
        else:
            entry.update(polygons=shape.n_polygons, triangles=shape.n_triangles)
            polygons += shape.n_polygons * per_asset[name]
            instanced += shape.n_polygons
        assets[name] = entry
    return {
        "path": str(path),
        "bytes": sum(t["bytes"] for t in tallies) + (path.stat().st_size if is_manifest(path) else 0),
        "grammar": meta.get("grammar"),
        "seed": meta.get("seed"),
        "crs": meta.get("crs"),
        "instances": sum(per_asset.values()),
        "mesh_faces": sum(t["mesh_faces"] for t in tallies),
        "lots": len(per_lot),
        "per_lot": ({"min": int(per_lot.min()), "median": float(np.median(per_lot)), "max": int(per_lot.max())}
                    if len(per_lot) else None),
        "bbox": ({"min": np.min([p[0] for p in points], axis=0).tolist(),
                  "max": np.max([p[1] for p in points], axis=0).tolist()} if points else None),
        "assets": assets,
        "symbols": dict(symbols),
        # the mesh table counts a polygon per ring, as bake and PRT's encoder do
        "polygons": {"instanced": int(instanced), "baked": int(polygons + mesh_rings),
                     "baked_triangles": None if problems or any(t["triangles"] is None for t in tallies)
                     else sum(t["triangles"] for t in tallies)},
        "problems": problems,
    }


def _tally(record: dict, files: list[Path], asset_roots, lod: str | None) -> dict:
    """What one output adds to a summary: counts by name, terminals per lot, its box, its bytes, its
    baked triangles (None when an asset does not load)."""
    names = [str(n) for n in record["assets"]]
    symbols = [str(n) for n in record.get("symbols", ())]
    asset = record["asset"].astype(np.int64)
    per_asset = np.bincount(asset, minlength=len(names))
    per_symbol = np.bincount(record["symbol"].astype(np.int64), minlength=len(symbols)) if "symbol" in record \
        else np.zeros(0, np.int64)
    per_lot = np.bincount(record["lot"].astype(np.int64)) if len(asset) and "lot" in record \
        else np.zeros(0, np.int64)
    xform, mesh_vertices = world_columns(record)
    corners = _corners(xform)
    points = np.concatenate([corners, mesh_vertices]) if len(mesh_vertices) else corners
    return {
        "meta": record["meta"],
        "assets": {names[a]: int(per_asset[a]) for a in np.flatnonzero(per_asset)},
        "symbols": {symbols[s]: int(per_symbol[s]) for s in np.flatnonzero(per_symbol)},
        "per_lot": per_lot[per_lot > 0],
        "bbox": (points.min(axis=0), points.max(axis=0)) if len(points) else None,
        "mesh_faces": len(record["mesh_face_offsets"]) - 1,
        "mesh_rings": len(record["mesh_ring_offsets"]) - 1,
        "bytes": sum(f.stat().st_size for f in files),
        "triangles": _triangles(record, asset_roots, lod),
    }


def _triangles(record: dict, asset_roots, lod: str | None) -> int | None:
    try:
        return count_triangles(record, asset_roots, lod)
    except AssetError:
        return None


def _read(path: Path) -> tuple[dict, list[Path]]:
    """The record of an output, and the files it is made of."""
    suffix = path.suffix.lower()
    if suffix in (".usd", ".usda", ".usdc"):
        from grammarc.io.usd import read_usd, tiles_folder

        return read_usd(path), [path, *(f for f in tiles_folder(path).glob("*") if f.is_file())]
    if suffix == ".glb":
        from grammarc.io.gltf import index_path, read_glb, written_parts

        index = index_path(path)
        return read_glb(path), written_parts(path) + ([index] if index.exists() else [])
    if suffix == ".3dtiles":
        from grammarc.io.tiles3d import read_tileset

        return read_tileset(path), [f for f in path.rglob("*") if f.is_file()]
    return read_instances(path), [path]


def _corners(xform: np.ndarray) -> np.ndarray:
    """(8n, 3) corners of the instances' boxes."""
    unit = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], np.float64)
    return (np.einsum("nij,cj->nci", xform[:, :, :3], unit) + xform[:, None, :, 3]).reshape(-1, 3)


def format_summary(info: dict) -> str:
    """The summary as text, a table per section."""
    lines = [f"{info['path']}: {info['bytes'] / 1e6:,.1f} MB, grammar {info['grammar']}, seed {info['seed']}",
             (f"  instances   {info['instances']:,} ({info['bytes'] / max(info['instances'], 1):,.1f} bytes "
              f"each), mesh faces {info['mesh_faces']:,}")]
    if info["per_lot"]:
        p = info["per_lot"]
        lines.append(f"  lots        {info['lots']:,}, terminals per lot min {p['min']:,} median "
                     f"{p['median']:,.1f} max {p['max']:,}")
    if info["bbox"]:
        low, high = (np.array(info["bbox"][k]) for k in ("min", "max"))
        lines.append(f"  bbox        {_xyz(low)} .. {_xyz(high)} (size {_xyz(high - low)}, world: x east, "
                     "y up, z south)")
    crs = info.get("crs")
    lines.append(f"  crs         {crs if crs is None or len(crs) < 100 else crs[:97] + '...'}"
                 if crs else "  crs         none (metres of a local scene)")
    poly = info["polygons"]
    triangles = "" if poly["baked_triangles"] is None else f" ({poly['baked_triangles']:,} triangles)"
    lines.append(f"  polygons    {poly['instanced']:,} instanced, {poly['baked']:,} baked{triangles}")
    lines.append("  assets")
    width = max((len(n) for n in info["assets"]), default=0)
    for name, entry in sorted(info["assets"].items(), key=lambda kv: -kv[1]["instances"]):
        extra = f"  x {entry['polygons']:,} polygons" if "polygons" in entry else "  (not loaded)"
        lines.append(f"    {name:<{width}}  {entry['instances']:>12,}{extra}")
    if info["symbols"]:
        lines.append("  symbols")
    width = max((len(n) for n in info["symbols"]), default=0)
    for name, count in sorted(info["symbols"].items(), key=lambda kv: -kv[1]):
        lines.append(f"    {name:<{width}}  {count:>12,}")
    lines += [f"  problem: {p}" for p in info["problems"]]
    return "\n".join(lines)


def _xyz(v: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:,.1f}" for x in v) + ")"
