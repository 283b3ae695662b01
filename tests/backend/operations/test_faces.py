"""backend/operations/faces.py in derivations: deleteHoles (convexify and cleanupGeometry: test_mesh_shapes.py)."""

from __future__ import annotations

import pytest
from conftest import LOT_ZOO
from derivations import (
    face_area,
    mesh_faces,
    rect,
    run,
    same_records,
    totals,
)


def test_delete_holes_leaves_each_face_its_outer_ring(write):
    """A courtyard lot's face, the border faces of its offset, and a hip roof's bottom face (a mesh) lose
    their holes and keep their scopes; a rectangle has none to lose."""
    area = 'report("a", geometry.area()) X.'
    for body, before, after in [("", 1200.0, 1600.0), ("roofHip(30) ", None, None),
                                ("offset(-2) comp(f){ border : B } ", None, None)]:
        kept = run(write, f"Lot --> {body}{area}\nB --> {area}\n", [LOT_ZOO["courtyard"]])
        gone = run(write, f"Lot --> {body}deleteHoles() {area}\nB --> deleteHoles() {area}\n",
                   [LOT_ZOO["courtyard"]])
        faces = mesh_faces(gone)
        assert any(len(rings) > 1 for rings in mesh_faces(kept)) and all(len(rings) == 1 for rings in faces)
        assert [face_area(rings[:1]) for rings in mesh_faces(kept)] == pytest.approx(
            [face_area(rings) for rings in faces])
        if before is not None:
            assert (totals(kept)["a_sum"], totals(gone)["a_sum"]) == pytest.approx((before, after))
    text = "Lot --> {}extrude(3) comp(f){{ side : S | top : T }}\n"
    same_records(run(write, text.format(""), [rect(12, 8)]), run(write, text.format("deleteHoles() "), [rect(12, 8)]))


def test_delete_holes_of_a_solid_with_holes_fails_its_lot(write):
    records = run(write, "Lot --> extrude(4) deleteHoles() X.\n", [LOT_ZOO["courtyard"], rect(12, 8)])
    (bad,) = records["bad"]
    assert bad.index == 0 and bad.reason.startswith("`deleteHoles` of a solid with holes is not supported yet")
    assert set(records["lot"]) == {1}
