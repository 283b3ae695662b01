"""backend/box_rings.py: a rectangle kept as its scope box keeps its ring's first vertex through
``rotateScope`` and ``alignScopeToAxes``, so its edges keep their numbers (``shapeL/U``, per-edge setbacks)
and a split's pieces start where PRT's do. The figures are PRT's (PyPRT on the kit's massing rule package,
``offset_absolute`` 0, ``lot_coverage`` 0.4, ``height_total`` 20, on the 30 x 10 m lot below): the area of
the tier's remainder, its roof at 20 m."""

from __future__ import annotations

import pytest
from operations.derivations import assets, mesh_faces, rect, run, totals

#: massing's orientation and tier rules, on one footprint rule (``{footprint}``) and its per-edge distances.
MASSING = """
Lot --> rotateScope(0, {orientation}, 0) alignScopeToAxes(y) {footprint}
Footprint --> extrude(12.2) comp(f){{ top : Top }}
Top --> setback(comp(fe){{ all : float(listItem("{distances}", comp.index)) }}) {{ all : T | remainder : R }}
R --> report("r", geometry.area)
"""
SHAPE_L = "shapeL(0.4 * scope.sz, 0.4 * scope.sx){ shape : Footprint | remainder : NIL }"
SHAPE_U = "shapeU(0.4 * scope.sz, 0.4 * scope.sx, 0.4 * scope.sx){ shape : Footprint | remainder : NIL }"
SPLIT = "split(z){ '0.4 : Footprint | ~1 : NIL }"


@pytest.mark.parametrize("footprint, distances, orientation, remainder", [
    (SHAPE_L, "4;4;0;0;0;0", 0, 72), (SHAPE_L, "4;4;0;0;0;0", 90, 48), (SHAPE_L, "4;4;0;0;0;0", 180, 48),
    (SHAPE_L, "4;4;0;0;0;0", 270, 48),
    (SHAPE_U, "4;4;3;3;0;0;4;3", 0, 33), (SHAPE_U, "4;4;3;3;0;0;4;3", 90, 39),
    (SHAPE_U, "4;4;3;3;0;0;4;3", 180, 39), (SHAPE_U, "4;4;3;3;0;0;4;3", 270, 12),
    (SPLIT, "4;0;4;4;0", 90, 16), (SPLIT, "4;0;4;4;0", 270, 16), (SPLIT, "4;0;4;4;0", 180, 0),
])
def test_a_turned_rectangle_keeps_its_edge_numbers(write, footprint, distances, orientation, remainder):
    """Before, the lot's rectangle restarted its ring at the turned scope's origin: shapeL left 120 m² at
    90 and 270 degrees and 72 at 180, shapeU 38 and 33, the split's piece 24."""
    text = MASSING.format(orientation=orientation, footprint=footprint, distances=distances)
    assert totals(run(write, text, [rect(30, 10)])).get("r_sum", 0.0) == pytest.approx(remainder)



def test_a_turned_rectangle_is_still_a_quad_record(write):
    """The rectangles stay their scope boxes, turned or cut: their records are built-in quads, not meshes."""
    text = ("Lot --> rotateScope(0, 270, 0) alignScopeToAxes(y) split(z){ '0.4 : A | ~1 : B }\n"
            "A --> setback(1){ front : C | remainder : D }\n")
    r = run(write, text, [rect(30, 10)])
    assert assets(r) == ["builtin:quad"] * 3 and mesh_faces(r) == []
