"""Positions, orientations and scales of the record's transforms; tiles that do not depend on chunking."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from writers_city import world

from grammarc.io.instancing import INSTANCE, TileSpool, decompose
from grammarc.model.records import MeshChunk, TerminalChunk


def transforms(n: int, seed: int = 1) -> np.ndarray:
    """Random rotations and sizes, with flat axes (one, two, three) and mirrors among them."""
    rng = np.random.default_rng(seed)
    scale = rng.uniform(0.1, 5, (n, 3))
    scale[::5, 1] = 0
    scale[1::7, 2] = 0
    scale[2::11, [0, 2]] = 0
    scale[3::13] = 0
    scale[4::3, 0] *= -1
    linear = Rotation.random(n, random_state=seed).as_matrix() * scale[:, None, :]
    return np.concatenate([linear, rng.uniform(-1e4, 1e4, (n, 3, 1))], axis=2).astype(np.float32)


def test_decompose_gives_back_the_transform():
    xform = transforms(3000)
    position, orientation, scale = decompose(xform)
    np.testing.assert_allclose(np.linalg.norm(orientation, axis=1), 1, atol=1e-6)
    assert (orientation[:, 3] >= 0).all()  # one sign of the two
    np.testing.assert_allclose(world(position, orientation, scale), xform, atol=2e-6 * 5, rtol=1e-5)


@pytest.mark.parametrize("linear, expected", [
    (np.diag([2.0, 3.0, 4.0]), [2, 3, 4]),
    (np.diag([-2.0, 3.0, 4.0]), [-2, 3, 4]),             # a mirror: x scale negative
    (np.diag([2.0, 0.0, 4.0]), [2, 0, 4]),               # a flat face
    (np.zeros((3, 3)), [0, 0, 0]),                       # a point
])
def test_flat_and_mirrored_axes(linear, expected):
    xform = np.concatenate([linear, np.ones((3, 1))], axis=1)[None].astype(np.float32)
    position, orientation, scale = decompose(xform)
    np.testing.assert_allclose(scale[0], expected)
    np.testing.assert_allclose(orientation[0], [0, 0, 0, 1], atol=1e-7)
    np.testing.assert_allclose(position[0], [1, 1, 1])


def chunk(xform: np.ndarray, first: int) -> TerminalChunk:
    n = len(xform)
    return TerminalChunk(asset=np.arange(first, first + n, dtype=np.int32) % 3, xform=xform,
                         lot=np.arange(first, first + n, dtype=np.int32), symbol=np.zeros(n, np.int32),
                         mesh=MeshChunk.empty())


def test_tiles_keep_the_record_order_whatever_the_chunking(tmp_path):
    xform = transforms(500)
    whole = TileSpool(tmp_path / "a", tile_size=2000)
    parts = TileSpool(tmp_path / "b", tile_size=2000)
    (tmp_path / "a").mkdir(), (tmp_path / "b").mkdir()
    whole.add(chunk(xform, 0))
    for first in range(0, 500, 37):
        parts.add(chunk(xform[first:first + 37], first))
    a, b = list(whole.tiles()), list(parts.tiles())
    assert [t.key for t in a] == [t.key for t in b] and len(a) > 4
    for x, y in zip(a, b):
        assert x.instances.tobytes() == y.instances.tobytes()
        assert (np.diff(x.instances["row"]) > 0).all()
        # transforms relative to the tile's corner: the boxes' centres lie in the tile
        centre = x.instances["xform"][:, :, 3] + 0.5 * x.instances["xform"][:, :, :3].sum(axis=2)
        assert ((centre[:, [0, 2]] >= -1e-3) & (centre[:, [0, 2]] < 2000)).all()
    assert sum(len(t.instances) for t in a) == 500 and a[0].instances.dtype == INSTANCE
