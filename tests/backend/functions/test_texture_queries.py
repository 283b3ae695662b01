"""backend/functions/texture.py: geometry.uMin, uMax, vMin, vMax, du and dv of a shape's texture
coordinates, on a facade projected in 2 m by 3 m tiles, on a lot's own coordinates and without any."""

from __future__ import annotations

import pytest
from backend.operations.derivations import per_lot, rect, run

#: A 12 x 8 lot extruded 6 high, its front face (12 wide, 6 high) projected with 2 x 3 m tiles from 1 m to
#: the right of its origin.
FACADE = ("Lot --> extrude(6) comp(f){ front : Front }\n"
          "Front --> setupProjection(0, scope.xy, 2, 3, 1, 0) projectUV(0) QUERY\n")


def reported(write, text, lots=None):
    """The reported sums of the one lot (a 12 x 8 rectangle unless ``lots`` says otherwise)."""
    r = run(write, text, lots or [rect(12, 8)])
    return {k[:-4]: float(v) for k, v in next(iter(per_lot(r).values())).items() if k.endswith("_sum")}


@pytest.mark.parametrize("query, want", [
    ("geometry.uMin", -0.5), ("geometry.uMax", 5.5), ("geometry.vMin(0)", 0), ("geometry.vMax", 2),
    ("geometry.du(0, uvSpace)", 6), ("geometry.dv(0, uvSpace)", 2),
    ("geometry.du(0, unitSpace)", 12), ("geometry.dv(0, unitSpace)", 6),
])
def test_texture_extent_of_a_projected_facade(write, query, want):
    assert reported(write, FACADE.replace("QUERY", f'report("q", {query})'))["q"] == pytest.approx(want)


def test_lot_coordinates_and_a_set_without_any(write):
    """The lot's own coordinates are metres along its x and z; set 1, never projected, answers 0."""
    got = reported(write, 'Lot --> report("du", geometry.du(0, unitSpace)) report("dv", geometry.dv(0, uvSpace)) '
                   'report("u1", geometry.uMax(1)) L.\n', [rect(30, 20)])
    assert got == {"du": pytest.approx(30), "dv": pytest.approx(20), "u1": 0}
