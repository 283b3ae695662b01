"""The lots of a build read in a thread: found beside the grammar, their error raised where they are taken,
steps taken meanwhile only while they are being read."""

from __future__ import annotations

import threading

import pytest

from grammarc.errors import LotsError
from grammarc.io import lots_reading
from grammarc.io.lots_reading import LotsReading, find_lots

SQUARE = ('{"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {}, "geometry": '
          '{"type": "Polygon", "coordinates": [[[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]]]}}]}')


def test_the_lots_beside_the_grammar_are_found(tmp_path):
    grammar = tmp_path / "town.cga"
    assert find_lots(grammar) is None
    (tmp_path / "lots.geojson").write_text(SQUARE)
    assert find_lots(grammar) == tmp_path / "lots.geojson"
    (tmp_path / "town.geojson").write_text(SQUARE)
    assert find_lots(grammar) == tmp_path / "town.geojson"


def test_the_lots_are_read_in_a_thread_and_their_error_raised_by_result(tmp_path):
    (tmp_path / "lots.geojson").write_text(SQUARE)
    assert len(LotsReading(tmp_path / "g.cga", None, None).result()) == 1
    with pytest.raises(LotsError):
        LotsReading(tmp_path / "g.cga", tmp_path / "missing.geojson", None).result()


def test_steps_are_taken_while_the_lots_are_read_and_none_once_they_are(tmp_path, monkeypatch):
    (tmp_path / "lots.geojson").write_text(SQUARE)
    go_on, load = threading.Event(), lots_reading.load_lots

    def held(*args):  # the reading ends once three steps were taken
        go_on.wait()
        return load(*args)

    monkeypatch.setattr(lots_reading, "load_lots", held)
    taken = []

    def steps():
        while True:
            taken.append(len(taken))
            if len(taken) == 3:
                go_on.set()
            yield

    reading = LotsReading(tmp_path / "g.cga", None, None)
    assert len(reading.result(meanwhile=steps())) == 1 and len(taken) >= 3
    taken.clear()
    assert len(reading.result(meanwhile=steps())) == 1 and taken == []  # read already: no step
