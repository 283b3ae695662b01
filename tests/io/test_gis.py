"""Tests of grammarc.io.gis: a GeoPackage read through GDAL gives its GeoJSON's lots."""

from __future__ import annotations

import numpy as np
import pytest
from lot_features import gis_file, lot_files

from grammarc.errors import LotsError
from grammarc.io.lots import read_lots


def test_a_gis_file_reads_as_its_features(tmp_path):
    """GeoPackage through GDAL: the lots, ids, MultiPolygon parts, street edges and bad lots of the
    GeoJSON (`streetWidth` is JSON text in a GeoPackage field, which has no lists)."""
    whole = read_lots(lot_files(tmp_path)[0])
    gis = read_lots(gis_file(tmp_path))
    assert gis.ids.tolist()[:3] == ["a", "m:0", "m:1"] and gis.index.tolist() == whole.index.tolist()
    assert gis.bad == whole.bad and [b.id for b in gis.bad] == ["line", "bad-width"]
    np.testing.assert_allclose(gis.vertices, whole.vertices)
    np.testing.assert_array_equal(gis.street, whole.street)
    np.testing.assert_array_equal(gis.attrs["h"].astype(float), whole.attrs["h"].astype(float))


def test_a_broken_gis_file_raises(tmp_path):
    pytest.importorskip("pyogrio")
    path = tmp_path / "lots.shp"
    path.write_bytes(b"\0")
    with pytest.raises(LotsError, match="cannot read lots file .*lots.shp"):
        read_lots(path)

