"""Issue 24's states per second: ``grammarc search`` breadth-first on ``strips.cga`` (a rectangle 30 m
long divided into strips 1, 2 and 3 m high) until ``--max-states``, in one process and in two; the peak
RSS of 10^5 and 10^6 states shows what ``--max-states`` bounds. Times are wall-clock for the whole
command, start-up included.
"""

from __future__ import annotations

import json

import pytest
from conftest import HERE, run_command


@pytest.mark.parametrize("workers", [1, 2], ids=["workers1", "workers2"])
@pytest.mark.parametrize("states", [100_000, 1_000_000], ids=["1e5", "1e6"])
def test_search_states(benchmark, tmp_path, states, workers):
    lot = tmp_path / "lot.geojson"
    ring = [[0, 0], [4, 0], [4, 30], [0, 30], [0, 0]]
    lot.write_text(json.dumps({"type": "FeatureCollection", "features": [
        {"type": "Feature", "id": "strip", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [ring]}}]}))
    args = [str(HERE / "strips.cga"), "--lots", str(lot), "--max-states", str(states), "--workers", str(workers),
            "--quiet"]
    run_command("search", args)  # fill the numba cache outside the timed region
    result = {}
    benchmark.pedantic(lambda: result.update(run_command("search", args)), rounds=1, iterations=1)
    assert f"({states:,} states derived" in result["stderr"]
    benchmark.extra_info.update(states_per_s=round(states / benchmark.stats.stats.min),
                                peak_rss_mib=round(result["peak_rss_kib"] / 1024, 1))
