"""grammarc against Esri's PRT on the same rule packages and lots, timed side by side in one run.

Each round runs PRT (``prt_reference.py RPK rect_30x20.obj --batch N --processes 2``: PyPRT in its side
environment, N copies of the footprint on a grid, two processes as grammarc's two workers) and then
``grammarc build RPK`` on N such lots (``conftest.grid_lots``), both as whole processes, start-up included; the ratio is PRT's
median over grammarc's, so a noisy machine slows both alike. The same build is also timed as the ``grammarc``
command runs it with a warm server up (``grammarc server``): ``served_median_s``, ``prt_over_served``. Skipped without the PRT kit
(``../shared/prt``) or its side environment: ``$GRAMMARC_PRT_PYTHON``, else ``.prt-venv/bin/python``
beside the repository (the kit's README says how to make it).
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time

import pytest
from conftest import grid_lots, run_build

from grammarc.conform import kit_dir, prt_python
from grammarc.io.npz import read_instances

ROUNDS = 3


@pytest.mark.parametrize("n_lots", [100, 500], ids=["100", "500"])
@pytest.mark.parametrize("package", ["candler", "massing"])
def test_against_prt(benchmark, lots_dir, served_env, tmp_path, package, n_lots):
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
    served = [sys.executable, "-m", "grammarc.client", "build", *args]
    prt_seconds, served_seconds, result = [], [], {}

    def others():
        """PRT, then the same build as the ``grammarc`` command runs it when a server is up."""
        for command, env, seconds in ((prt, None, prt_seconds), (served, served_env, served_seconds)):
            start = time.perf_counter()
            subprocess.run(command, env=env, check=True, capture_output=True)
            seconds.append(time.perf_counter() - start)

    benchmark.pedantic(lambda: result.update(run_build(args)), setup=others, rounds=ROUNDS, iterations=1)
    terminals = len(read_instances(out)["asset"])
    ours = statistics.median(benchmark.stats.stats.data)
    prt_median, served_median = statistics.median(prt_seconds), statistics.median(served_seconds)
    benchmark.extra_info.update(
        terminals=terminals,
        terminals_per_s=round(terminals / ours),
        peak_rss_mib=round(result["peak_rss_kib"] / 1024, 1),
        prt_median_s=round(prt_median, 3),
        prt_over_grammarc=round(prt_median / ours, 2),
        served_median_s=round(served_median, 3),
        prt_over_served=round(prt_median / served_median, 2),
    )
