"""``grammarc info OUT``: what a city's output holds, without opening another program.

OUT is an instance record (``.npz``), or instanced USD or glTF as ``build`` writes them (read back by
``io.usd.read_usd`` and ``io.gltf.read_glb``): glTF keeps no lots or symbols, so those lines are left out
for it; the bytes are those of every file of the output (USD's tile layers, glTF's parts).

Counts per asset and per symbol, terminals per lot (min, median, max), the bounding box, and what the city
weighs once instanced assets are expanded: polygons and triangles as ``bake`` would make them (each asset
counted once from its mesh, times its instances; the mesh table's faces as they are), next to the
instanced count (a prototype's polygons once per asset, plus the mesh table). Asset files are looked up
as the writers do (the grammar's folder, then the record's ``--assets`` folders); an asset that cannot be
loaded is reported and left out of the polygon counts rather than failing the summary.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from grammarc.errors import AssetError
from grammarc.io.bake import asset_library, count_triangles
from grammarc.io.npz import read_instances

__all__ = ["format_summary", "summarize"]


def summarize(path: str | os.PathLike, asset_roots=None, lod: str | None = None) -> dict:
    """The facts ``grammarc info`` prints, as a JSON-ready dict (see the module docstring)."""
    record, files = _read(Path(path))
    names = [str(n) for n in record["assets"]]
    symbols = [str(n) for n in record.get("symbols", ())]
    asset = record["asset"].astype(np.int64)
    per_asset = np.bincount(asset, minlength=len(names))
    per_symbol = np.bincount(record["symbol"].astype(np.int64), minlength=len(symbols)) if "symbol" in record \
        else np.zeros(0, np.int64)
    per_lot = np.bincount(record["lot"].astype(np.int64)) if len(asset) and "lot" in record \
        else np.zeros(0, np.int64)
    per_lot = per_lot[per_lot > 0]
    xform = record["xform"].astype(np.float64)
    corners = _corners(xform)
    mesh_vertices = record["mesh_vertices"].astype(np.float64)
    points = np.concatenate([corners, mesh_vertices]) if len(mesh_vertices) else corners
    mesh_faces = len(record["mesh_face_offsets"]) - 1
    mesh_rings = len(record["mesh_ring_offsets"]) - 1

    library = asset_library(names, record, asset_roots, lod)
    assets, polygons, instanced, problems = {}, 0, mesh_rings, []
    for a in np.flatnonzero(per_asset):
        entry = {"instances": int(per_asset[a])}
        try:
            shape = library[int(a)]
        except AssetError as error:
            problems.append(str(error))
        else:
            entry.update(polygons=shape.n_polygons, triangles=shape.n_triangles)
            polygons += shape.n_polygons * int(per_asset[a])
            instanced += shape.n_polygons
        assets[names[a]] = entry
    return {
        "path": str(path),
        "bytes": sum(f.stat().st_size for f in files),
        "grammar": record["meta"].get("grammar"),
        "seed": record["meta"].get("seed"),
        "instances": len(asset),
        "mesh_faces": mesh_faces,
        "lots": len(per_lot),
        "per_lot": ({"min": int(per_lot.min()), "median": float(np.median(per_lot)), "max": int(per_lot.max())}
                    if len(per_lot) else None),
        "bbox": ({"min": points.min(axis=0).tolist(), "max": points.max(axis=0).tolist()}
                 if len(points) else None),
        "assets": assets,
        "symbols": {symbols[s]: int(per_symbol[s]) for s in np.flatnonzero(per_symbol)},
        # the mesh table counts a polygon per ring, as bake and PRT's encoder do
        "polygons": {"instanced": int(instanced), "baked": int(polygons + mesh_rings),
                     "baked_triangles": None if problems else count_triangles(record, asset_roots, lod)},
        "problems": problems,
    }


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
        lines.append(f"  bbox        {_xyz(low)} .. {_xyz(high)} (size {_xyz(high - low)})")
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
