"""model/obj.py: the v and f lines of an OBJ file, as assets and OBJ lots read them."""

import pytest

from grammarc.model.obj import ObjError, read_obj


def test_read_obj_takes_vertex_tokens_and_negative_indices_and_names_a_bad_line():
    points, faces = read_obj("# c\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nf 1/1 2//3 -1/2/3\n")
    assert points.shape == (3, 3) and [f.tolist() for f in faces] == [[0, 1, 2]]
    with pytest.raises(ObjError, match="^lot.obj:2: bad 'v' line"):
        read_obj("v 0 0 0\nv 1 x 0\n", "lot.obj")
