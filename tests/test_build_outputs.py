"""``grammarc build`` options for outputs: --select, --bake, --lod, --reports, --max-triangles."""

import csv
import json

import numpy as np
import pytest
import trimesh

from grammarc.cli import main
from grammarc.io.npz import read_instances

GRAMMAR = """
Lot --> report("floor_area", geometry.area()) extrude(6) comp(f){ side : Facade | top : Roof. }
Facade --> split(x){ ~3 : Tile }*
Tile --> i("props/bench.obj")
"""
BENCH = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nv 0 0 1\nv 2 0 1\nv 2 1 1\nv 0 1 1\nf 1 2 3 4\nf 5 6 7 8\n"


@pytest.fixture
def city(tmp_path):
    (tmp_path / "props").mkdir()
    (tmp_path / "props" / "bench.obj").write_text(BENCH)
    (tmp_path / "g.cga").write_text(GRAMMAR)
    features = [{"type": "Feature", "id": f"L{k}", "properties": {}, "geometry": {"type": "Polygon",
                 "coordinates": [[[30 * k, 0], [30 * k + 12, 0], [30 * k + 12, 9], [30 * k, 9], [30 * k, 0]]]}}
                for k in range(4)]
    (tmp_path / "lots.geojson").write_text(json.dumps({"type": "FeatureCollection", "features": features}))
    return tmp_path


def build(city, out, *args):
    return main(["build", str(city / "g.cga"), "--lots", str(city / "lots.geojson"), "--emit", str(city / out),
                 "--quiet", *args])


def test_select_derives_the_named_lots_only(city, capsys):
    assert build(city, "all.npz") == 0 and build(city, "two.npz", "--select", "L1,L3") == 0
    every, two = read_instances(city / "all.npz"), read_instances(city / "two.npz")
    assert sorted(set(two["lot"].tolist())) == [1, 3]
    np.testing.assert_array_equal(two["xform"], every["xform"][np.isin(every["lot"], [1, 3])])
    assert build(city, "none.npz", "--select", "L9") == 2
    assert "no lot has the id 'L9'" in capsys.readouterr().err


def test_bake_a_glb_and_obj(city):
    assert build(city, "one.glb", "--bake", "--select", "L0") == 0
    mesh = trimesh.load(city / "one.glb", force="mesh")
    assert len(mesh.faces) == 14 * 4 + 2  # 14 tiles of ~3 m around the 12 x 9 m lot, 2 quads each; the roof
    assert build(city, "one.obj", "--select", "L0") == 0  # .obj is always baked
    assert build(city, "one.npz", "--bake") == 2


def test_max_triangles_refuses_a_large_bake(city, capsys):
    assert build(city, "big.obj", "--max-triangles", "10") == 2
    err = capsys.readouterr().err
    assert "passes 10 triangles" in err and "--max-triangles" in err and not (city / "big.obj").exists()


def test_lod_picks_the_substitute_beside_the_asset(city):
    (city / "props" / "bench.low.obj").write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n")
    assert build(city, "high.obj", "--select", "L0") == 0 and build(city, "low.obj", "--select", "L0",
                                                                        "--lod", "low") == 0
    high, low = (trimesh.load(city / f"{n}.obj", force="mesh") for n in ("high", "low"))
    tiles = 14  # 4 + 3 + 4 + 3 tiles of ~3 m on the 12 x 9 m lot
    assert len(high.faces) - len(low.faces) == tiles * (4 - 1)
    # a missing asset: an error, unless --lod builtin puts a cube in its place
    (city / "props" / "bench.obj").unlink()
    (city / "props" / "bench.low.obj").unlink()
    assert build(city, "gone.obj", "--select", "L0") == 1 and not (city / "gone.obj").exists()
    assert build(city, "cubes.obj", "--select", "L0", "--lod", "builtin") == 0
    assert len(trimesh.load(city / "cubes.obj", force="mesh").faces) == tiles * 12 + 2


def test_reports_as_csv(city):
    assert build(city, "c.npz", "--reports", str(city / "areas.csv")) == 0
    rows = list(csv.DictReader((city / "areas.csv").read_text().splitlines()))
    assert [r["id"] for r in rows] == ["L0", "L1", "L2", "L3", ""] and rows[-1]["lot"] == "total"
    assert float(rows[0]["floor_area_sum"]) == pytest.approx(108)
    assert float(rows[-1]["floor_area_sum"]) == pytest.approx(4 * 108)
    assert build(city, "d.npz") == 0
    data = json.loads((city / "d.reports.json").read_text())
    assert data["ids"] == {"0": "L0", "1": "L1", "2": "L2", "3": "L3"} and data["total"]["floor_area_n"] == 4
