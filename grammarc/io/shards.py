"""The output of a cluster build (``grammarc.cluster``): a shard per partition of the lots, and a manifest.

``grammarc build city.cga --lots L --emit out/city.npz --dask ...`` writes

- ``out/city.shards/part-00000.npz`` (or ``.usdc`` with its tile folder), one per partition, each a
  complete output of its lots, written atomically by the usual writer;
- beside each shard, ``part-00000.json``: what it holds (its partition, its lots' first number, lots
  derived, bad lots, counts, bounding box) and the SHA-256 of each of its files, written after the shard
  and atomically, so a shard with a sidecar is complete;
- ``out/city.manifest.json``, last: the run (grammar, seed, lots), the shards in order with their
  sidecars' facts, the totals and the bounding box. ``grammarc info`` reads it, and for USD the root
  layer ``out/city.usdc`` references the shards it lists.

The shards in order hold the same records as a one-process build's output (the records do not depend on
how lots are chunked). A run carries a key (``run_key``) made of everything its records depend on; a
resumed run keeps a shard whose sidecar has the same key and whose files still have their checksums.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numba
import numpy as np

from grammarc.atomic import replacing

__all__ = ["is_manifest", "manifest_path", "read_manifest", "shard_outputs", "shards_folder"]

#: A manifest's name ends so.
MANIFEST_SUFFIX = ".manifest.json"


def shards_folder(output: Path) -> Path:
    """``out/city.npz`` -> ``out/city.shards``."""
    return output.with_name(output.stem + ".shards")


def manifest_path(output: Path) -> Path:
    """``out/city.npz`` -> ``out/city.manifest.json``."""
    return output.with_name(output.stem + MANIFEST_SUFFIX)


def shard_name(number: int, suffix: str) -> str:
    return f"part-{number:05d}{suffix}"


def sidecar_path(folder: Path, number: int) -> Path:
    return folder / shard_name(number, ".json")


def is_manifest(path: Path) -> bool:
    return path.name.endswith(MANIFEST_SUFFIX)


def read_manifest(path: Path) -> dict:
    with open(path, "rb") as file:
        manifest = json.load(file)
    if manifest.get("kind") != "grammarc-shards":
        raise ValueError(f"{path}: not a manifest of grammarc shards")
    return manifest


def shard_outputs(path: Path) -> list[Path]:
    """The shards a manifest lists, in order, as paths."""
    return [path.parent / shard["path"] for shard in read_manifest(path)["shards"]]


def run_key(facts: dict) -> str:
    """The key of a run: the SHA-256 of its facts as canonical JSON."""
    return hashlib.sha256(json.dumps(facts, sort_keys=True, default=str).encode()).hexdigest()


def file_digests(files: list[Path], root: Path) -> dict[str, str]:
    """``{path relative to root: sha256}`` of ``files``."""
    return {f.relative_to(root).as_posix(): _sha256(f) for f in sorted(files)}


def complete_shard(folder: Path, number: int, key: str) -> dict | None:
    """The sidecar of shard ``number`` if it is of run ``key`` and its files are there with their
    checksums; else None (the shard is derived again)."""
    try:
        with open(sidecar_path(folder, number), "rb") as file:
            sidecar = json.load(file)
    except (OSError, ValueError):
        return None
    if sidecar.get("run") != key or sidecar.get("partition") != number:
        return None
    for name, digest in sidecar.get("files", {}).items():
        path = folder / name
        if not path.is_file() or _sha256(path) != digest:
            return None
    return sidecar


def write_json(path: Path, value: dict) -> None:
    """Write JSON to ``path`` atomically (``grammarc.atomic.replacing``)."""
    with replacing(path) as tmp:
        tmp.write_text(json.dumps(value, indent=1))


@numba.njit(cache=True, nogil=True)
def instance_box(xform: np.ndarray, low: np.ndarray, high: np.ndarray) -> None:
    """Grow ``low``/``high`` (3,) float64 to the boxes of instances ``xform`` (n, 3, 4): the unit cube
    mapped by each affine transform, per world axis its translation plus the negative (or positive)
    entries of the linear map's row. One pass, without numpy's (n, 3, 3) temporaries."""
    for n in range(xform.shape[0]):
        for i in range(3):
            lo = hi = np.float64(xform[n, i, 3])
            for j in range(3):
                v = np.float64(xform[n, i, j])
                if v < 0:
                    lo += v
                else:
                    hi += v
            low[i] = min(low[i], lo)
            high[i] = max(high[i], hi)


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as file:
        while block := file.read(1 << 22):
            digest.update(block)
    return digest.hexdigest()
