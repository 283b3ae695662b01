"""``grammarc render`` of the facade grammar on 1667 lots: 1,000,200 instances, 1600 x 1000 pixels.

Target (issue): a few seconds on the 2-core machine. The record is derived outside the timed region and
the numba cache is filled by a first render; "call" times ``load_record`` and ``render()`` in this process
(reading the record, framing, drawing, writing the PNG), "command" the whole ``grammarc render`` process,
start-up included.
"""

from __future__ import annotations

import subprocess
import sys

import pytest
from conftest import HERE, grid_lots, run_build

from grammarc.io.npz import load_record
from grammarc.render import render

LOTS = 1667
TERMINALS_PER_LOT = 600


@pytest.fixture(scope="module")
def record_1e6(lots_dir):
    lots = grid_lots(lots_dir / f"lots_{LOTS}.geojson", LOTS)
    out = lots_dir / "facade_1e6.npz"
    run_build([str(HERE / "facade.cga"), "--lots", str(lots), "--emit", str(out), "--quiet"])
    return out


@pytest.mark.parametrize("view", ["oblique", "top"])
@pytest.mark.parametrize("how", ["call", "command"])
def test_render_1e6(benchmark, record_1e6, tmp_path, view, how):
    out = tmp_path / "city.png"
    result = render(load_record(record_1e6), out, view=view)  # fills the numba cache
    assert result["instances"] == LOTS * TERMINALS_PER_LOT
    if how == "call":
        benchmark.pedantic(lambda: render(load_record(record_1e6), out, view=view), rounds=3, iterations=1)
    else:
        command = [sys.executable, "-m", "grammarc.cli", "render", str(record_1e6), "-o", str(out),
                   "--view", view]
        benchmark.pedantic(subprocess.run, args=(command,), kwargs={"check": True, "capture_output": True},
                           rounds=3, iterations=1)
    seconds = benchmark.stats.stats.min
    benchmark.extra_info.update(
        instances=result["instances"],
        splats=result["splats"],
        instances_per_s=round(result["instances"] / seconds),
    )
