"""backend/operations/cuts.py: ``Cut`` divides footprints, rectangles and earlier pieces alike."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from conftest import in_world
from derivations import paper, rect

from grammarc.build import derive
from grammarc.compiler import compile_grammar
from grammarc.errors import GrammarError
from grammarc.io.lots import read_lots

EXAMPLES = Path(__file__).resolve().parents[3] / "examples" / "gramatica"


def _faces(r):
    """Each mesh face's vertices (x, z) and its symbol's name."""
    rings = r["mesh"].ring_offsets
    return [(r["mesh"].vertices[rings[i]:rings[i + 1]][:, [0, 2]].round(6).tolist(), str(r["symbols"][s]))
            for i, s in enumerate(r["mesh"].symbol)]


def test_a_rectangle_and_then_its_piece_are_cut(write):
    r = paper(write, 'lot ~> Cut(0, 0.6, 1, 0.4){ tri | rest }\nrest ~> Cut(1, 0.5, 3, 0.5){ quad | pent }',
              [rect(4, 6)])
    faces = _faces(r)
    assert [(len(v), name) for v, name in faces] == [(3, "tri"), (4, "quad"), (5, "pent")]
    assert faces[0][0] == [[2.4, 0], [4, 0], [4, -2.4]]  # a map's y is the world's -z
    assert faces[1][0] == [[2, -6], [0, -6], [0, 0], [1.2, 0]]  # the rest's edges start where the cut began


def test_pieces_are_their_bounding_boxes_and_answer_geometry_queries(write):
    text = ('lot ~> Cut(0, 0.5, 1, 0.5){ a | b }\n'
            'a ~> S(1r, 2, 1r) I("cube")\n'  # the piece's scope is its box: 2 x 3
            'b : geometry.nVertices() == 5 && geometry.area() == 24 - 3 ~> I("cube")')
    r = paper(write, text, [rect(4, 6)])
    sizes = np.linalg.norm(r["xform"][:, :, :3], axis=1).round(6).tolist()
    assert sizes == [[2.0, 2.0, 3.0], [4.0, 0.0, 6.0]]


def test_a_cut_that_makes_no_two_pieces_fails_its_lot(write):
    r = paper(write, "lot ~> Cut(1, 0.2, 1, 0.7){ a | b }", [rect(4, 6), rect(3, 3)])
    assert len(r["bad"]) == 2 and "`Cut` between one edge and itself" in r["bad"][0].reason


def test_cut_takes_two_parts(write):
    with pytest.raises(GrammarError, match="`Cut` makes two pieces: its body has two parts"):
        compile_grammar(write("g.cga", "lot ~> Cut(0, 0.5, 2, 0.5){ a | b | c }"))


def test_the_fixed_ice_ray_derivation_of_figure_6():
    grammar = compile_grammar(EXAMPLES / "iceray_figure6.cga")
    r = in_world(derive(grammar, read_lots(EXAMPLES / "figure1.geojson")))
    faces = _faces(r)
    assert [len(v) for v, _ in faces] == [3, 5, 3, 5, 4, 4]  # rules 3, 2, 4, 3, 4 on a rectangle

    def area(ring):
        x, z = np.asarray(ring).T
        return abs(x @ np.roll(z, -1) - z @ np.roll(x, -1)) / 2

    assert sum(area(v) for v, _ in faces) == pytest.approx(24)
