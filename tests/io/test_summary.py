"""``grammarc info``: counts, lots, bbox and polygon counts of a record."""

import json

import numpy as np
import pytest
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
    assert "missing.npz: No such file or directory" in capsys.readouterr().err


@pytest.mark.parametrize("output", ["city.usdc", "city.glb", "city.3dtiles"])
def test_info_of_instanced_outputs_counts_what_the_record_has(tmp_path, output):
    """USD, glTF and 3D Tiles read back (``read_usd``, ``read_glb``, ``read_tileset``): the same instances per
    asset, the same box; USD and 3D Tiles keep lots and symbols too."""
    if output.endswith(".usdc"):
        pytest.importorskip("pxr")
    city(tmp_path, output, tile_size=100.0)
    npz, other = summarize(tmp_path / "city.npz"), summarize(tmp_path / output)
    assert other["instances"] == npz["instances"] and other["assets"] == npz["assets"]
    np.testing.assert_allclose(other["bbox"]["min"], npz["bbox"]["min"], atol=2e-3)
    np.testing.assert_allclose(other["bbox"]["max"], npz["bbox"]["max"], atol=2e-3)
    assert other["polygons"]["baked_triangles"] == npz["polygons"]["baked_triangles"]
    if not output.endswith(".glb"):
        assert other["symbols"] == npz["symbols"] and other["per_lot"] == npz["per_lot"]
    else:
        assert other["symbols"] == {} and "symbols" not in format_summary(other)
    assert other["bytes"] > 0 and output in format_summary(other)
