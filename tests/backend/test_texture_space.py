"""backend/texture_space.py and the chunk's TextureMaps: texture coordinates as affine maps of world points."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.backend.chunk import TextureMaps
from grammarc.backend.texture_space import metres_per_unit, planar_map


def test_texture_maps_start_with_none_and_grow():
    table = TextureMaps(capacity=2)
    assert np.isnan(table[np.zeros(3, np.int32)]).all()  # map 0: no coordinates
    maps = np.arange(5 * 8, dtype=float).reshape(5, 2, 4)
    ids = table.add(maps)
    assert list(ids) == [1, 2, 3, 4, 5] and ids.dtype == np.int32
    np.testing.assert_array_equal(table[ids[::-1]], maps[::-1])


def test_planar_map_measures_metres_from_the_origin():
    origin = np.array([[1.0, 2.0, 3.0]])
    m = planar_map(origin, np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 1.0, 0.0]]))
    point = np.array([4.0, 7.0, 11.0])
    np.testing.assert_allclose(m[0, :, :3] @ point + m[0, :, 3], [8, 5])


def test_metres_per_unit_within_the_surface():
    """u = x / 2 on a surface: 2 m per unit; on a surface whose normal is x, u does not change (NaN)."""
    maps = np.zeros((2, 2, 4))
    maps[:, 0, 0], maps[:, 1, 2] = 0.5, 4
    assert metres_per_unit(maps)[0] == pytest.approx([2, 0.25])
    across = metres_per_unit(maps, np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]))
    assert across[0] == pytest.approx([2, 0.25]) and np.isnan(across[1, 0]) and across[1, 1] == 0.25
