"""backend/operations/simplify.py in derivations: reduceGeometry on polygons, prisms, boxes and roofs."""

from __future__ import annotations

import numpy as np
from derivations import mesh_faces, rect, run, totals


def _circle(n=40, radius=10.0):
    angle = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return [np.c_[radius * np.cos(angle) + 20, radius * np.sin(angle) + 20]]


def test_reduce_geometry_removes_its_share_of_a_lots_vertices(write):
    """The reference's example in small: a 40-gon reduced by 0.8 keeps 8 vertices; its prism keeps the
    same outline; a rectangle lot stays a rectangle."""
    face = mesh_faces(run(write, "Lot --> reduceGeometry(0.8) L.\n", [_circle()]))
    assert [len(f[0]) for f in face] == [8]
    t = totals(run(write, 'Lot --> reduceGeometry(0.8) extrude(3) report("n", geometry.nVertices) L.\n',
                   [_circle()]))
    assert t["n_sum"] == 16
    kept = run(write, "Lot --> reduceGeometry(0.5) L.\n", [rect(12, 8)])
    same = run(write, "Lot --> L.\n", [rect(12, 8)])
    assert np.array_equal(kept["xform"], same["xform"]) and len(kept["mesh"].lot) == len(same["mesh"].lot)


def test_reduce_geometry_of_a_roof_is_refused(write):
    records = run(write, "Lot --> roofHip(30) reduceGeometry(0.5) R.\n", [rect(12, 8)])
    (bad,) = records["bad"]
    assert bad.reason.startswith("`reduceGeometry` of a roof is not supported yet")
