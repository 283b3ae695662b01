"""Issue 6's writer figures: instances per second, bytes per instance and peak memory of each writer.

A city of ``rows`` instances is streamed into a writer in chunks of 200k rows, the way ``grammarc build``
streams its chunks: the facade tiles (quads, every third a cube) of 12 x 15 m buildings in rows of 200,
20 m apart (4 km; 10^7 instances are 125 rows), each building turned a little and given one of a few
colours. Each format is written in a child process,
so its peak RSS is its own::

    python -m pytest benchmarks/bench_writers.py                   # npz, usdc, glb, 3dtiles at 10^6 instances
    /usr/bin/time -f "%e s %M KB" python benchmarks/bench_writers.py --format usdc --rows 10000000

The second form is how the 10^7-instance figure of the closing note was made (streaming: the memory is
bounded by a chunk and a tile, not by the city).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

from grammarc.io import writer_for
from grammarc.model.records import MeshChunk, TerminalChunk

CHUNK = 200_000
ASSETS = ["builtin:quad", "builtin:cube"]
COLOURS = np.array([[200, 190, 170, 255], [120, 60, 40, 255], [90, 110, 140, 255], [255, 255, 255, 255]],
                   np.uint8)
PER_BUILDING = 400  # instances per building: 4 facades of 10 x 10 tiles


def chunk(first: int, rows: int) -> TerminalChunk:
    """Rows ``first .. first + rows`` of the city (deterministic, independent of the chunking)."""
    at = np.arange(first, first + rows)
    building, k = np.divmod(at, PER_BUILDING)
    gx, gz = (building % 200) * 20.0, (building // 200) * 20.0
    face, tile = np.divmod(k, 100)
    u, v = tile % 10, tile // 10
    angle = face * (np.pi / 2) + (building % 7) * 0.1
    c, s = np.cos(angle), np.sin(angle)
    xform = np.zeros((rows, 3, 4), np.float32)
    xform[:, 0, 0], xform[:, 2, 0] = 1.2 * c, -1.2 * s       # tile width along the facade
    xform[:, 1, 1] = 1.5                                    # tile height
    xform[:, 0, 2], xform[:, 2, 2] = 0.3 * s, 0.3 * c       # a cube's depth (a quad ignores it)
    xform[:, 0, 3] = gx + 6 + 1.2 * (u - 5) * c
    xform[:, 1, 3] = v * 1.5
    xform[:, 2, 3] = -(gz + 6) - 1.2 * (u - 5) * s
    return TerminalChunk(asset=(tile % 3 == 0).astype(np.int32), xform=xform, lot=building.astype(np.int32),
                         symbol=(tile % 3 == 0).astype(np.int32), mesh=MeshChunk.empty(),
                         color=COLOURS[building % len(COLOURS)])


def write(path: Path, rows: int) -> dict:
    """Stream the city into ``path``'s writer; seconds spent in the writer (making the chunks is not
    counted, the import of the writer's module is), bytes on disk (tile folders included)."""
    start = time.perf_counter()
    writer = writer_for(path)(path, assets=ASSETS, symbols=["Wall", "Window"], meta={"grammar": "bench"})
    seconds = time.perf_counter() - start
    with writer:
        for first in range(0, rows, CHUNK):
            part = chunk(first, min(CHUNK, rows - first))
            start = time.perf_counter()
            writer.write(part)
            seconds += time.perf_counter() - start
        start = time.perf_counter()
        writer.close()
    seconds += time.perf_counter() - start
    size = sum(f.stat().st_size for f in path.parent.rglob("*") if f.is_file())
    return {"seconds": seconds, "bytes": size}


def run_child(fmt: str, rows: int, directory: Path) -> dict:
    """``write`` in a child process: its result, with the peak RSS (KiB) it measured of itself."""
    proc = subprocess.run([sys.executable, __file__, "--format", fmt, "--rows", str(rows), "--dir",
                           str(directory)], capture_output=True, text=True, check=False)
    if proc.returncode:
        raise RuntimeError(proc.stderr)
    return json.loads(proc.stdout)


@pytest.mark.parametrize("fmt", ["npz", "usdc", "glb", "3dtiles"])
def test_writer_speed(benchmark, tmp_path, fmt):
    if fmt == "usdc":
        pytest.importorskip("pxr")
    rows = 1_000_000
    result = {}

    def once():
        directory = Path(tempfile.mkdtemp(dir=tmp_path))
        result.update(run_child(fmt, rows, directory))

    benchmark.pedantic(once, rounds=1, iterations=1)
    benchmark.extra_info.update(
        instances_per_second=round(rows / result["seconds"]), bytes_per_instance=round(result["bytes"] / rows, 1),
        peak_rss_mib=round(result["peak_rss_kib"] / 1024, 1), seconds=round(result["seconds"], 2))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--format", choices=("npz", "usdc", "usda", "glb", "3dtiles"), default="usdc")
    parser.add_argument("--rows", type=int, default=1_000_000)
    parser.add_argument("--dir", type=Path)
    args = parser.parse_args()
    directory = args.dir or Path(tempfile.mkdtemp())
    result = write(directory / f"city.{args.format}", args.rows)
    import resource

    result["peak_rss_kib"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    print(json.dumps(result))


if __name__ == "__main__":
    main()
