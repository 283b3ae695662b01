"""Issue 18's function figures: what a built-in costs per million shapes.

100 lots of 100 x 100 m, each split into 1 x 1 m cells (10^6 shapes), each cell a box that inserts an
asset. The cell's rule differs only in how it names the asset: a constant (the baseline), one drawn from
a folder by ``fileRandom``, one drawn from a string list by ``listRandom``, and a ``fileRandom`` pick
sized by ``assetInfo``. Each whole ``grammarc build`` is timed against the baseline in the same run (the
machine is noisy); ``extra_info`` has the seconds each function adds per million shapes.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
from conftest import grid_lots, run_build

SHAPES = 1_000_000
CELLS = {
    "constant": 'i("assets/trees/a.obj")',
    "fileRandom": 'i(fileRandom("assets/trees/*.obj"))',
    "listRandom": 'i(listRandom("assets/trees/a.obj;assets/trees/b.obj;assets/trees/c.obj;assets/trees/d.obj;"))',
    "assetInfo": 's(assetInfo(fileRandom("assets/trees/*.obj"), sx), 1, 1) i(fileRandom("assets/trees/*.obj"))',
}


def grammar(folder, cell: str):
    for k, name in enumerate("abcd"):  # four small boxes of different widths
        path = folder / "assets" / "trees" / f"{name}.obj"
        path.parent.mkdir(parents=True, exist_ok=True)
        w = 1 + k
        path.write_text("".join(f"v {x} {y} {z}\n" for x in (0, w) for y in (0, 2) for z in (0, 1))
                        + "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n")
    path = folder / f"{len(list(folder.glob('*.cga')))}.cga"
    path.write_text('version "2022.0"\n@StartRule\nLot --> split(x){ 1 : split(z){ 1 : Cell }* }*\n'
                    f"Cell --> s(1, 1, 1) {cell} X.\n")
    return path


def best_of(args: list[str], rounds: int) -> float:
    run_build(args)  # numba cache and file-system cache outside the timed region
    best = np.inf
    for _ in range(rounds):
        start = time.perf_counter()
        run_build(args)
        best = min(best, time.perf_counter() - start)
    return best


@pytest.mark.parametrize("function", ["fileRandom", "listRandom", "assetInfo"])
def test_function_cost_per_million_shapes(benchmark, lots_dir, tmp_path, function):
    lots = lots_dir / "squares_100.geojson"
    if not lots.exists():
        grid_lots(lots, 100, width=100.0, depth=100.0)
    out = tmp_path / "out.npz"

    def args(cell: str) -> list[str]:
        return [str(grammar(tmp_path, cell)), "--lots", str(lots), "--emit", str(out), "--quiet"]

    base = best_of(args(CELLS["constant"]), rounds=2)
    timed = best_of(args(CELLS[function]), rounds=2)
    benchmark.extra_info.update(constant_s=round(base, 3), function_s=round(timed, 3),
                                added_s_per_million=round((timed - base) * 1e6 / SHAPES, 3),
                                ratio=round(timed / base, 3))
    benchmark.pedantic(lambda: run_build(args(CELLS[function])), rounds=1, iterations=1)
