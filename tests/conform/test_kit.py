"""The PRT kit: its reference records, footprints and where it is found."""

import json

import pytest
from conftest import PRT_KIT as KIT
from conftest import needs_kit

from grammarc.conform import (
    find_record,
    footprint_geojson,
    kit_dir,
    load_reference,
)
from grammarc.errors import UsageError


@needs_kit
def test_find_record(prt_reference):
    record = find_record(prt_reference, "extrude_color", "rect_30x20", {})
    assert record["bbox_min"] == [0, 0, 0] and record["bbox_max"] == [30, 5, 20]
    assert record["surface_area"] == 1700
    assert find_record(prt_reference, "rpk/extrude_color.rpk", "footprints/rect_30x20.obj") is record
    # Integers match the stored floats; the attributes' order does not matter.
    variant = find_record(prt_reference, "candler", "rect_30x20",
                          {"TileWidth": 3, "FloorHeight": 3.2, "BuildingHeight": 40})
    assert variant["attrs"] == {"BuildingHeight": 40.0, "FloorHeight": 3.2, "TileWidth": 3.0}
    assert find_record(prt_reference, "candler", "rect_30x20", {"BuildingHeight": 40})["attrs"] == {
        "BuildingHeight": 40.0
    }
    # Attributes set to the defaults PRT used find the default record.
    default = find_record(prt_reference, "candler", "octagon", {"BuildingHeight": 62})
    assert default is find_record(prt_reference, "candler", "octagon", None) and default["attrs"] == {}
    assert find_record(prt_reference, "candler", "rect_30x20", {"BuildingHeight": 41}) is None
    assert find_record(prt_reference, "candler", "rect_30x20", seed=1) is None
    assert find_record(prt_reference, "nosuch", "rect_30x20") is None


@needs_kit
def test_footprints_and_kit(tmp_path, monkeypatch):
    collection = footprint_geojson("courtyard_40x40", KIT)
    (feature,) = collection["features"]
    assert feature["properties"]["name"] == "courtyard_40x40" and len(feature["geometry"]["coordinates"]) == 2
    json.dumps(collection)
    with pytest.raises(UsageError, match="no footprint `nope`.*rect_30x20"):
        footprint_geojson("nope", KIT)
    monkeypatch.setenv("GRAMMARC_PRT_KIT", str(tmp_path))
    assert kit_dir() == tmp_path
    with pytest.raises(UsageError, match="not found"):
        load_reference()
    monkeypatch.delenv("GRAMMARC_PRT_KIT")
    assert kit_dir().resolve() == KIT.resolve()


# --------------------------------------------------------------------- grammarc against PRT, end to end

