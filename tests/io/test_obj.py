"""The OBJ writer: what ``obj_bytes`` writes, ``read_obj`` reads back."""

import numpy as np
import pytest

from grammarc.io.obj import obj_bytes
from grammarc.model.obj import read_obj


def test_obj_bytes_writes_what_read_obj_reads():
    rng = np.random.default_rng(3)
    vertices = rng.uniform(-2e4, 2e4, (500, 3))
    vertices[:3] = [[0.0, -0.0, 4e-7], [-0.5, 12.25, 3.0], [1e6, -1e6, 0.000001]]
    faces = rng.integers(0, 500, (900, 3))
    text = obj_bytes(vertices, faces, "grammarc bake").decode()
    assert text.startswith("# grammarc bake\nv 0 0 0\nv -0.5 12.25 3\nv 1000000 -1000000 0.000001\n")
    points, read = read_obj(text)
    np.testing.assert_allclose(points, vertices, atol=5e-7, rtol=0)
    np.testing.assert_array_equal(np.array(read), faces)
    with pytest.raises(ValueError, match="finite"):
        obj_bytes(np.array([[np.nan, 0, 0]]), faces[:0])


def test_obj_bytes_writes_texture_coordinates_after_each_vertex():
    """A ``vt`` after each ``v``; each face corner names both, the vt index ``uv_shift`` lower (vertices
    written before without one)."""
    vertices = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.0]])
    text = obj_bytes(vertices + 0, np.array([[4, 5, 6]]) - 4, uv=vertices[:, :2] / 4).decode()
    assert text.splitlines()[:2] == ["v 0 0 0", "vt 0 0"] and text.splitlines()[-1] == "f 1/1 2/2 3/3"
    shifted = obj_bytes(vertices, np.array([[4, 5, 6]]), uv=vertices[:, :2], uv_shift=4).decode()
    assert shifted.splitlines()[-1] == "f 5/1 6/2 7/3"
    points, read = read_obj(shifted.replace("f 5/1 6/2 7/3", "f 1/1 2/2 3/3"))
    np.testing.assert_allclose(points, vertices)
    np.testing.assert_array_equal(np.array(read), [[0, 1, 2]])  # the reader takes each corner's v
    with pytest.raises(ValueError, match="finite"):
        obj_bytes(vertices, np.zeros((0, 3), int), uv=np.full((3, 2), np.nan))
