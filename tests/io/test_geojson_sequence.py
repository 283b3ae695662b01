"""Tests of grammarc.io.geojson_sequence: a Feature per line, read whole or cut at line ends."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest
from lot_features import FEATURES, lot_files

from grammarc.errors import LotsError
from grammarc.io import geojson_sequence
from grammarc.io.lots import count_lots, partition_lots, read_lots


def test_a_sequence_reads_as_its_feature_collection(tmp_path):
    whole, sequence, _ = lot_files(tmp_path)
    a, b = read_lots(whole), read_lots(sequence)
    assert a.ids.tolist() == b.ids.tolist() and a.index.tolist() == b.index.tolist() and a.bad == b.bad
    np.testing.assert_array_equal(a.vertices, b.vertices)


def test_a_bad_line_of_a_sequence_is_named(tmp_path):
    path = tmp_path / "lots.geojsonl"
    path.write_text(json.dumps(FEATURES[0]) + "\n{not json\n")
    with pytest.raises(LotsError, match=r"lots.geojsonl:2: not valid JSON"):
        read_lots(path)
    parts = partition_lots(path, 1)
    assert count_lots(parts[0]) == 1
    with pytest.raises(LotsError, match=r"lots.geojsonl:2:"):
        count_lots(parts[1])


def test_a_sequence_is_cut_at_line_ends_without_reading_it_whole(tmp_path, monkeypatch):
    """Partitions of a sequence are byte ranges found by scanning for line ends, in blocks."""
    _, sequence, _ = lot_files(tmp_path)
    monkeypatch.setattr(geojson_sequence, "_SCAN_BLOCK", 7)  # line ends across block boundaries
    parts = partition_lots(sequence, 4)
    data = sequence.read_bytes()
    assert {p.kind for p in parts} == {"sequence"} and [p.number for p in parts] == list(range(len(parts)))
    assert parts[0].offset == 0 and parts[-1].end == len(data)
    assert all(a.end == b.offset and data[b.offset - 1:b.offset] == b"\n" for a, b in itertools.pairwise(parts))
