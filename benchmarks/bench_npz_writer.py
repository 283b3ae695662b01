"""Benchmark: InstanceWriter streaming 60M terminal rows (3.6 GB) into instances.npz.

Run under ``/usr/bin/time`` for the peak RSS::

    /usr/bin/time -f "%e s %M KB" python benchmarks/bench_npz_writer.py            # the writer alone
    /usr/bin/time -f "%e s %M KB" python benchmarks/bench_npz_writer.py --derive-ms 70

``--derive-ms`` stands in for the derivation: before each write the caller spins for that much CPU time in the
interpreter (holding the GIL, as numba kernels do), so the output shows how much of the writing hides behind it.
70 ms per 300k-row chunk is the ~14 s the derivation takes for 60M rows on the 2-core reference machine.

The chunk is built once, outside the timed region, and written again and again: cheap, and the writer does not
modify or keep the arrays once they are written, so reusing them is safe.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

import numpy as np

from grammarc.io.npz import InstanceWriter
from grammarc.model.records import MeshChunk, TerminalChunk

ASSETS = ["builtin:cube", "builtin:quad", "facade/window.obj"]
SYMBOLS = ["Wall", "Window", "Roof", "Ledge"]


def make_chunk(rows: int, seed: int = 0) -> TerminalChunk:
    """``rows`` random-ish terminals and a few mesh faces, seeded."""
    rng = np.random.default_rng(seed)
    mesh = MeshChunk(
        vertices=rng.normal(size=(12, 3)).astype(np.float32),
        ring_offsets=np.array([0, 4, 8, 12], np.int64),
        face_offsets=np.array([0, 2, 3], np.int64),
        lot=np.array([0, 1], np.int32),
        symbol=np.array([0, 2], np.int32),
    )
    return TerminalChunk(
        asset=rng.integers(0, len(ASSETS), rows).astype(np.int32),
        xform=rng.normal(size=(rows, 3, 4)).astype(np.float32),
        lot=np.sort(rng.integers(0, 1 << 20, rows)).astype(np.int32),
        symbol=rng.integers(0, len(SYMBOLS), rows).astype(np.int32),
        mesh=mesh,
    )


def spin(seconds: float) -> None:
    """Burn ``seconds`` of this thread's CPU time in the interpreter."""
    end = time.thread_time() + seconds
    while time.thread_time() < end:  # a system call: not too often, or the spin is all system time
        for _ in range(10_000):
            pass


def bench_write_60M_rows(directory: str, rows: int, chunk_rows: int, derive_ms: float) -> dict:
    chunk = make_chunk(chunk_rows)
    n_chunks = rows // chunk_rows
    path = os.path.join(directory, "instances.npz")
    t0 = time.perf_counter()
    in_write = in_derive = 0.0
    out = InstanceWriter(path, assets=ASSETS, symbols=SYMBOLS, meta={"seed": 0, "bench": "npz_writer"})
    for _ in range(n_chunks):
        t = time.perf_counter()
        spin(derive_ms / 1000)
        in_derive += time.perf_counter() - t
        t = time.perf_counter()
        out.write(chunk)
        in_write += time.perf_counter() - t
    t = time.perf_counter()
    counts = out.close()
    in_close = time.perf_counter() - t
    total = time.perf_counter() - t0
    return {
        "rows": counts["instances"],
        "GB": os.path.getsize(path) / 1e9,
        "derive_s": in_derive,
        "write_s": in_write,
        "close_s": in_close,
        "total_s": total,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=60_000_000)
    parser.add_argument("--chunk-rows", type=int, default=300_000)
    parser.add_argument("--derive-ms", type=float, default=0.0, help="caller CPU time per chunk")
    parser.add_argument("--dir", default=None, help="where to write (default: a temporary directory here)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(dir=args.dir or os.getcwd(), prefix="bench_npz_") as directory:
        result = bench_write_60M_rows(directory, args.rows, args.chunk_rows, args.derive_ms)
    print(
        f"{result['rows']:,} rows, {result['GB']:.2f} GB: derive {result['derive_s']:.1f} s, "
        f"write() {result['write_s']:.1f} s, close() {result['close_s']:.1f} s, total {result['total_s']:.1f} s"
    )


if __name__ == "__main__":
    main()
