"""Issue 4's polygons per second on 10^4 and 10^5 random concave footprints (8-40 vertices, every fifth
with a courtyard), for two grammars: ``footprints.cga`` extrudes, splits the prism into faces and every
side face into floors and tiles (the work per lot grows with its vertex count); ``roofs.cga`` puts a hip
roof with an overhang on each footprint (a straight skeleton per lot). "polygons" counts the lots'
footprints per second.
"""

from __future__ import annotations

import pytest
from conftest import HERE, concave_lots, run_build

from grammarc.io.npz import read_instances


@pytest.mark.parametrize("grammar", ["footprints.cga", "roofs.cga"], ids=["extrude_split", "roof_hip"])
@pytest.mark.parametrize("n_lots", [10_000, 100_000], ids=["1e4", "1e5"])
def test_concave_footprints_build(benchmark, lots_dir, tmp_path, n_lots, grammar):
    lots = lots_dir / f"concave_{n_lots}.geojson"
    if not lots.exists():
        concave_lots(lots, n_lots)
    out = tmp_path / "out.npz"
    args = [str(HERE / grammar), "--lots", str(lots), "--emit", str(out), "--quiet"]
    run_build(args)  # fill the numba cache outside the timed region
    result = {}
    benchmark.pedantic(lambda: result.update(run_build(args)), rounds=1 if n_lots >= 100_000 else 3,
                       iterations=1)
    records = read_instances(out)
    assert len(set(records["mesh_lot"].tolist())) == n_lots  # every lot has its roof
    seconds = benchmark.stats.stats.min
    terminals = len(records["asset"]) + len(records["mesh_lot"])  # facade tiles and roof faces
    benchmark.extra_info.update(
        polygons_per_s=round(n_lots / seconds),
        terminals=terminals,
        terminals_per_s=round(terminals / seconds),
        peak_rss_mib=round(result["peak_rss_kib"] / 1024, 1),
    )
