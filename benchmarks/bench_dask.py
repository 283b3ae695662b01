"""A build on a local Dask cluster against the one-machine build, at 10^6 lots (issue 9's benchmark).

The facade grammar with one floor (70 terminals a lot) on a grid of lots, as GeoParquet (made
beforehand, cached in ``--lots-dir``), built three ways, each as a whole command in a child process:

- ``grammarc build --workers 1``: one process;
- ``grammarc build``: the default, a worker process per core (two here);
- ``grammarc build --dask local:2``: a local cluster of two worker processes, shards and a manifest.

Reports wall seconds, terminals per second, the cluster's overhead against each, and the peak of the
summed RSS of the command's whole process tree (the cluster's workers are grandchildren), sampled every
0.2 s. Writes ``benchmarks/bench_dask.csv``::

    python benchmarks/bench_dask.py                 # 10^6 lots
    python benchmarks/bench_dask.py --lots 100000
"""

from __future__ import annotations

import argparse
import csv
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

from conftest import HERE, grid_lots

FACADE_ATTRS = ["--attr", "height=3", "--attr", "tile_w=6"]


def tree_rss_kib(root: int) -> int:
    """The summed RSS of ``root`` and its descendants, from /proc."""
    parents: dict[int, int] = {}
    rss: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as file:
                fields = file.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        parents[int(entry)] = int(fields[1])
        rss[int(entry)] = int(fields[21]) * os.sysconf("SC_PAGE_SIZE") // 1024
    tree, frontier = {root}, [root]
    while frontier:
        children = [p for p, parent in parents.items() if parent in frontier and p not in tree]
        tree.update(children)
        frontier = children
    return sum(rss.get(p, 0) for p in tree)


def run(args: list[str]) -> dict:
    """``grammarc build ARGS`` in a child: wall seconds, its report line, the peak RSS of its tree."""
    start = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "grammarc.cli", "build", *args], stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    peak = 0
    while proc.poll() is None:
        peak = max(peak, tree_rss_kib(proc.pid))
        time.sleep(0.2)
    seconds = time.perf_counter() - start
    stderr = proc.stderr.read()
    if proc.returncode != 0:
        raise RuntimeError(stderr)
    found = re.search(r"([\d,]+) instances, ([\d,]+) mesh faces", stderr)
    return {"seconds": seconds, "terminals": sum(int(g.replace(",", "")) for g in found.groups()),
            "peak_tree_mib": peak / 1024}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--lots", type=int, default=1_000_000)
    parser.add_argument("--lots-dir", type=Path, default=Path("/tmp/grammarc-dask-bench"))
    parser.add_argument("--out", type=Path, default=HERE / "bench_dask.csv")
    args = parser.parse_args()
    args.lots_dir.mkdir(parents=True, exist_ok=True)
    lots = args.lots_dir / f"grid_{args.lots}.parquet"
    if not lots.exists():
        geojson = grid_lots(args.lots_dir / f"grid_{args.lots}.geojson", args.lots)
        subprocess.run([sys.executable, "-m", "grammarc.cli", "lots", str(geojson), "--to", str(lots)], check=True,
                       stdout=subprocess.DEVNULL)
        geojson.unlink()
    out = args.lots_dir / "out"
    grammar = str(HERE / "facade.cga")
    ways = {
        "one process (--workers 1)": ["--workers", "1", "--emit", str(out / "one.npz")],
        "one machine (--workers 2)": ["--workers", "2", "--emit", str(out / "two.npz")],
        "dask local:2": ["--dask", "local:2", "--emit", str(out / "dask.npz")],
    }
    rows = []
    for name, extra in ways.items():
        shutil.rmtree(out, ignore_errors=True)
        out.mkdir()
        result = run([grammar, "--lots", str(lots), *FACADE_ATTRS, *extra])
        rows.append({"way": name, "lots": args.lots, "terminals": result["terminals"],
                     "seconds": round(result["seconds"], 2),
                     "terminals_per_s": round(result["terminals"] / result["seconds"]),
                     "peak_tree_mib": round(result["peak_tree_mib"])})
        print(rows[-1], flush=True)
    shutil.rmtree(out, ignore_errors=True)
    dask = rows[-1]["seconds"]
    for row in rows:
        row["dask_over_this"] = round(dask / row["seconds"], 3)
    with open(args.out, "w", newline="") as file:
        writer = csv.DictWriter(file, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
