"""``grammarc info``: counts, lots, bbox and polygon counts of a record."""

import json

import numpy as np
from writers_city import city

from grammarc.cli import main
from grammarc.io.summary import format_summary, summarize


def test_summary_counts_the_record(tmp_path):
    record, _, _ = city(tmp_path, "city.npz")
    info = summarize(tmp_path / "city.npz")
    assert info["instances"] == len(record["asset"]) and info["lots"] == 3
    assert sum(a["instances"] for a in info["assets"].values()) == info["instances"]
    assert sum(info["symbols"].values()) == info["instances"]
    assert info["symbols"]["Window"] + info["symbols"]["Wall"] == info["instances"]
    # every tile is a quad (a cube inserted in a flat scope is one), the roof polygons counted once each
    rings = len(record["mesh_ring_offsets"]) - 1
    assert list(info["assets"]) == ["builtin:quad"] and rings > 0
    assert info["polygons"]["baked"] == info["instances"] + rings
    assert info["polygons"]["instanced"] == 1 + rings
    fans = int((np.diff(record["mesh_ring_offsets"]) - 2).sum())  # the roof faces have no holes
    assert info["polygons"]["baked_triangles"] == 2 * info["instances"] + fans
    low, high = info["bbox"]["min"], info["bbox"]["max"]
    assert 11_999 < low[0] < 12_001 and 12_719 < high[0] < 12_721 and high[1] > 9  # x east, the roofs
    assert info["per_lot"]["min"] <= info["per_lot"]["median"] <= info["per_lot"]["max"]
    assert "builtin:quad" in format_summary(info)


def test_info_command(tmp_path, capsys):
    city(tmp_path, "city.npz")
    assert main(["info", str(tmp_path / "city.npz"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["lots"] == 3
    assert main(["info", str(tmp_path / "missing.npz")]) == 2
    assert "not an instance record" in capsys.readouterr().err
