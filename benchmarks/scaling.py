"""Time and memory of ``grammarc build`` from 10^3 to 10^6 lots, on a log-log plot (issue 7's scaling figure).

Each size is built in a child process (``conftest.run_build``: wall time of the whole command and the
child's own peak RSS), the lots made beforehand (``conftest.grid_lots``, cached in ``--lots-dir``)::

    pip install matplotlib
    python benchmarks/scaling.py                       # the facade grammar, one floor of 6 m tiles
    python benchmarks/scaling.py --grammar examples/pompeii/pompeii.cga --sizes 1000,10000,100000

writes ``benchmarks/scaling.csv`` and ``benchmarks/scaling.png``: seconds and MiB against lots, with a line
of slope 1 through the largest size (linear growth lies along it; the small sizes sit above it, where the
start-up of about 1.5 s and the fixed memory dominate). ``--replot`` draws the png again from the csv.
"""

from __future__ import annotations

import argparse
import csv
import re
import time
from pathlib import Path

from conftest import HERE, grid_lots, run_build

#: The facade grammar with one 3 m floor of 6 m tiles: 70 terminals a lot, so 10^6 lots are 7 * 10^7
#: records (4.2 GB), which this machine's disk and memory take.
FACADE_ATTRS = ["--attr", "height=3", "--attr", "tile_w=6"]


def measure(grammar: Path, sizes: list[int], lots_dir: Path, out: Path, attrs: list[str]) -> list[dict]:
    rows = []
    for n in sizes:
        lots = lots_dir / f"grid_{n}.geojson"
        if not lots.exists():
            grid_lots(lots, n)
        args = [str(grammar), "--lots", str(lots), "--emit", str(out), *attrs]
        run_build([*args, "--quiet"])  # the numba cache, and the lots file in the page cache
        start = time.perf_counter()
        result = run_build(args)
        seconds = time.perf_counter() - start
        found = re.search(r"([\d,]+) instances, ([\d,]+) mesh faces", result["stderr"])
        terminals = sum(int(g.replace(",", "")) for g in found.groups())
        rows.append({"lots": n, "terminals": terminals, "seconds": round(seconds, 3),
                     "peak_rss_mib": round(result["peak_rss_kib"] / 1024, 1)})
        print(rows[-1], flush=True)
        out.unlink(missing_ok=True)
    return rows


def plot(rows: list[dict], path: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lots = [r["lots"] for r in rows]
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, key, label in ((axes[0], "seconds", "wall seconds (whole command)"),
                           (axes[1], "peak_rss_mib", "peak RSS (MiB)")):
        values = [r[key] for r in rows]
        ax.loglog(lots, values, "o-", label="grammarc build")
        ax.loglog(lots, [values[-1] * n / lots[-1] for n in lots], "--", color="grey", label="slope 1 (linear)")
        ax.set_xlabel("lots")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--grammar", type=Path, default=HERE / "facade.cga")
    parser.add_argument("--sizes", default="1000,10000,100000,1000000")
    parser.add_argument("--lots-dir", type=Path, default=Path("/tmp/grammarc-scaling"))
    parser.add_argument("--out", type=Path, default=HERE / "scaling")
    parser.add_argument("--replot", action="store_true", help="only draw the png from the csv")
    args = parser.parse_args()
    attrs = FACADE_ATTRS if args.grammar.resolve() == (HERE / "facade.cga").resolve() else []
    if args.replot:
        with open(args.out.with_suffix(".csv"), newline="") as table:
            rows = [{k: float(v) for k, v in row.items()} for row in csv.DictReader(table)]
    else:
        args.lots_dir.mkdir(parents=True, exist_ok=True)
        rows = measure(args.grammar, [int(s) for s in args.sizes.split(",")], args.lots_dir,
                       args.lots_dir / "out.npz", attrs)
        with open(args.out.with_suffix(".csv"), "w", newline="") as table:
            writer = csv.DictWriter(table, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
    plot(rows, args.out.with_suffix(".png"), f"grammarc build {args.grammar.name}, {' '.join(attrs)}")


if __name__ == "__main__":
    main()
