"""grammarc against Esri's PRT on the same rule packages and lots, timed side by side in one run.

Each round runs PRT (``prt_reference.py RPK rect_30x20.obj --batch N --processes 2``: PyPRT in its side
environment, N copies of the footprint on a grid, two processes as grammarc's two workers) and then
``grammarc build RPK`` on N such lots (``conftest.grid_lots``), both as whole processes, start-up included; the ratio is PRT's
median over grammarc's, so a noisy machine slows both alike. Skipped without the PRT kit
(``../shared/prt``) or its side environment: ``$GRAMMARC_PRT_PYTHON``, else ``.prt-venv/bin/python``
beside the repository (the kit's README says how to make it).
"""

from __future__ import annotations

import statistics
import subprocess
import time

import pytest
from conftest import grid_lots, run_build

from grammarc.conform import kit_dir, prt_python
from grammarc.io.npz import read_instances

ROUNDS = 3


@pytest.mark.parametrize("n_lots", [100, 500], ids=["100", "500"])
@pytest.mark.parametrize("package", ["candler", "massing"])
def test_against_prt(benchmark, lots_dir, tmp_path, package, n_lots):
    kit, python = kit_dir(), prt_python()
    if not kit.is_dir() or python is None:
        pytest.skip("needs the PRT kit (../shared/prt) and PyPRT's side environment (.prt-venv or "
                    "GRAMMARC_PRT_PYTHON)")
    rpk = kit / "rpk" / f"{package}.rpk"
    lots = lots_dir / f"rect_30x20_{n_lots}.geojson"
    if not lots.exists():
        grid_lots(lots, n_lots, 30.0, 20.0)
    out = tmp_path / "out.npz"
    args = [str(rpk), "--lots", str(lots), "--emit", str(out), "--quiet"]
    prt = [str(python), str(kit / "prt_reference.py"), str(rpk), str(kit / "footprints" / "rect_30x20.obj"),
           "--batch", str(n_lots), "--processes", "2"]
    run_build(args)  # the numba cache filled outside the timed rounds
    prt_seconds, result = [], {}

    def run_prt():
        start = time.perf_counter()
        subprocess.run(prt, check=True, capture_output=True)
        prt_seconds.append(time.perf_counter() - start)

    benchmark.pedantic(lambda: result.update(run_build(args)), setup=run_prt, rounds=ROUNDS, iterations=1)
    terminals = len(read_instances(out)["asset"])
    ours = statistics.median(benchmark.stats.stats.data)
    benchmark.extra_info.update(
        terminals=terminals,
        terminals_per_s=round(terminals / ours),
        peak_rss_mib=round(result["peak_rss_kib"] / 1024, 1),
        prt_median_s=round(statistics.median(prt_seconds), 3),
        prt_over_grammarc=round(statistics.median(prt_seconds) / ours, 2),
    )
