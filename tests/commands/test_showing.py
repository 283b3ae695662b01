"""``grammarc info`` and ``grammarc lots`` (``commands/showing.py``): what they say of a file that is not what
they read, or is missing, and a conversion refused before the lots are read."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.cli import main


@pytest.mark.parametrize("name, content, seems", [
    ("x.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "a baked mesh"),
    ("x.npz", np.lib.format.magic(1, 0) + b"{'descr': '<f8'}", "a single numpy array"),
    ("notes.txt", b"hello\n", "a text file"),
])
def test_info_on_a_file_that_is_not_a_record_says_what_it_reads_and_what_the_file_seems(tmp_path, capsys, name,
                                                                                       content, seems):
    (tmp_path / name).write_bytes(content)
    assert main(["info", str(tmp_path / name)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and ".npz instance records" in err and f"): {seems}" in err
    assert "pickled" not in err


def test_info_on_a_missing_file_says_so(tmp_path, capsys):
    assert main(["info", str(tmp_path / "city.npz")]) == 2
    assert capsys.readouterr().err.strip().endswith("city.npz: No such file or directory")


def test_lots_to_a_path_that_cannot_be_written_is_refused_before_reading(tmp_path, capsys):
    lots = tmp_path / "lots.geojson"
    lots.write_text('{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {}, "geometry": '
                    '{"type": "Polygon", "coordinates": [[[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]]]}}]}')
    (tmp_path / "out.parquet").mkdir()
    assert main(["lots", str(lots), "--to", str(tmp_path / "out.parquet")]) == 2
    err = capsys.readouterr()
    assert err.out == "" and err.err.strip().endswith("out.parquet`: it is a folder")
