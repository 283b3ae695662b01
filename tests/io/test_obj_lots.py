"""Tests of grammarc.io.obj_lots: a lot per OBJ face, walls and bad indices as bad lots."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from lot_features import PRT_AREAS, PRT_FOOTPRINTS, lot_area, normal_y, prt, rings

from grammarc.errors import LotsError
from grammarc.io.lots import read_lots
from grammarc.model.lots import BadLot


def write_obj(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "lots.obj"
    path.write_text(text)
    return path


def test_obj_faces_with_negative_and_slashed_indices(tmp_path):
    text = """# two footprints
o lots
v 0 1 0
v 0 1 20
v 30 1 20
v 30 1 0
vt 0 0
vn 0 1 0
f 1/1/1 2//1 3/1 4
v 50 0 0
v 60 0 0
v 60 0 -10
f -3 -1 -2
"""
    lots = read_lots(write_obj(tmp_path, text))
    assert lots.ids.tolist() == ["face0", "face1"] and lots.index.tolist() == [0, 1]
    first, second = rings(lots, 0)[0], rings(lots, 1)[0]
    np.testing.assert_array_equal(first, [[0, 1, 0], [0, 1, 20], [30, 1, 20], [30, 1, 0]])  # y kept
    # -3 -1 -2 is clockwise from above: reversed keeping (50, 0, 0) first
    np.testing.assert_array_equal(second, [[50, 0, 0], [60, 0, 0], [60, 0, -10]])
    assert normal_y(first) > 0 and normal_y(second) > 0


def test_obj_wall_face_and_bad_index_are_reported(tmp_path):
    text = "v 0 0 0\nv 10 0 0\nv 10 3 0\nv 0 3 0\nv 0 0 -10\nf 1 2 3 4\nf 1 2 5\nf 1 2 9\n"
    lots = read_lots(write_obj(tmp_path, text))
    assert lots.ids.tolist() == ["face1"]
    assert lots.bad == (
        BadLot(0, "face0", "not a footprint: face normal is not vertical"),
        BadLot(2, "face2", "vertex index out of range"),
    )


def test_obj_malformed_line_raises_with_line_number(tmp_path):
    with pytest.raises(LotsError, match=r"lots.obj:2: bad 'v' line"):
        read_lots(write_obj(tmp_path, "v 0 0 0\nv 1 zero 0\n"))
    with pytest.raises(LotsError, match="no polygon"):
        read_lots(write_obj(tmp_path, "v 0 0 0\n"))


@prt
@pytest.mark.parametrize("name", [n for n in PRT_AREAS if n != "courtyard_40x40"])
def test_prt_obj_footprints_load_unchanged(name):
    path = PRT_FOOTPRINTS / f"{name}.obj"
    lots = read_lots(path)
    assert len(lots) == 1 and lots.bad == ()
    assert lot_area(lots, 0) == pytest.approx(PRT_AREAS[name], abs=0.01)
    # already +Y: the vertex order of the file is kept
    file_vertices = [line.split()[1:] for line in path.read_text().splitlines() if line.startswith("v ")]
    np.testing.assert_allclose(lots.vertices, np.array(file_vertices, dtype=float))

