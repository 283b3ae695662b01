"""A one-lot build, start to end: in its own process, and in a fork of a warm server (``grammarc server``),
timed in turn in one run (own, served, own, served, ...), so that a noisy machine slows both alike.

The served build is the ``grammarc`` command as a user runs it once a server is up: Python starts, the
client hands the command to the server and waits for its status. The grammars: candler.rpk of the PRT
kit (skipped without the kit), and the example city's grammar, each on one 30 x 20 m lot; and the city's
grammar on a lot as a GIS user has it (GeoParquet in UTM, read through Arrow and PROJ) to npz, USD and a
baked OBJ, whose libraries a served build finds imported by its server.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import grid_lots

from grammarc.conform import kit_dir

ROOT = Path(__file__).resolve().parents[1]
ROUNDS = 7


def _timed(args: list[str], env: dict) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "grammarc.client", "build", *args], env=env, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


@pytest.mark.parametrize("grammar", ["candler", "city"])
def test_one_lot_build(benchmark, served_env, tmp_path, grammar):
    path = kit_dir() / "rpk" / "candler.rpk" if grammar == "candler" else ROOT / "examples/city/city.cga"
    if not path.exists():
        pytest.skip("needs the PRT kit (../shared/prt)")
    lots = grid_lots(tmp_path / "one.geojson", 1, 30.0, 20.0)
    _own_and_served(benchmark, served_env, [str(path), "--lots", str(lots), "--emit", str(tmp_path / "one.npz")])


@pytest.mark.parametrize("emit", ["npz", "usda", "obj"])
def test_one_lot_build_of_gis_lots(benchmark, served_env, tmp_path, emit):
    pytest.importorskip("pyarrow")
    pytest.importorskip("pyproj")
    if emit == "usda":
        pytest.importorskip("pxr")
    lots = grid_lots(tmp_path / "one.geojson", 1, 30.0, 20.0, crs="EPSG:32633", at=(500000.0, 6000000.0))
    subprocess.run([sys.executable, "-m", "grammarc.client", "lots", str(lots), "--to", str(tmp_path / "one.parquet")],
                   env={**served_env, "GRAMMARC_SERVER": "off"}, check=True, capture_output=True)
    _own_and_served(benchmark, served_env, [str(ROOT / "examples/city/city.cga"), "--lots",
                                            str(tmp_path / "one.parquet"), "--emit", str(tmp_path / f"one.{emit}")])


def _own_and_served(benchmark, served_env: dict, args: list[str]) -> None:
    """Time the build of ``args`` served, each run after one in its own process (whose times go in the extra
    info)."""
    args = [*args, "--quiet"]
    own_env = {**served_env, "GRAMMARC_SERVER": "off"}
    _timed(args, own_env)  # the numba cache filled, the files in the page cache
    own: list[float] = []
    benchmark.pedantic(lambda: _timed(args, served_env), setup=lambda: own.append(_timed(args, own_env)),
                       rounds=ROUNDS, iterations=1)
    served = statistics.median(benchmark.stats.stats.data)
    benchmark.extra_info.update(own_median_s=round(statistics.median(own), 3), served_median_s=round(served, 3),
                                own_over_served=round(statistics.median(own) / served, 2))
