"""Make assets/*.obj: the few terminal objects of the Vitruvian town, deterministically.

The thesis builds everything from boxes except the column, which it models once (3.2.5.2: a shaft of 8
sides, 76 polygons in all) and places many times. We do the same for the parts a box cannot stand for:
the Ionic column's base, tapering shaft and capital with its volutes, the archway of the theatre's and
the amphitheatre's outer walls and of the gates, a statue, and two trees. The grammar gives each its size;
the asset gives the form.

Conventions, those of a scope (grammarc fits an asset's bounding box to the scope it is inserted in): x
along the wall, y up, z out of the building (+z is the front). Files are written in the unit box [0, 1]^3
with 4 decimals, so the same script always writes the same bytes.

    python make_assets.py [--out assets]
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # examples/assetkit.py
import assetkit
from assetkit import Mesh, box, combine, lathe

#: The shaft's top diameter over its foot's (III.2.12, as the thesis has it): the test reads it back.
SHAFT_TOP = 0.75


def ionic_base() -> Mesh:
    """The Ionic base (III.5.2): a square plinth under a torus, a scotia and a torus, 1 3/8 diameters
    across and half a diameter high (the grammar gives those sizes: the asset is drawn in them)."""
    plinth = box(-0.6875, 0.0, -0.6875, 0.6875, 0.17, 0.6875)
    mouldings = lathe([(0.64, 0.17), (0.66, 0.23), (0.62, 0.29), (0.55, 0.33), (0.56, 0.40),
                       (0.60, 0.44), (0.56, 0.50), (0.5, 0.5)], 16)
    return combine(plinth, mouldings)


def ionic_shaft() -> Mesh:
    """The shaft: a frustum of 16 sides (for the thesis's 8, whose fluting a texture draws) whose top is
    three quarters of its foot, with the slight swelling (entasis, III.3.13) at a third of its height."""
    return lathe([(0.5, 0.0), (0.5, 0.05), (0.49, 0.33), (SHAFT_TOP * 0.5, 1.0)], 16)


def ionic_capital() -> Mesh:
    """The capital: an echinus, the cushion whose ends roll into the two volutes seen from the front,
    and the thin square abacus on top (III.5.5-7)."""
    echinus = lathe([(0.40, 0.0), (0.46, 0.25), (0.40, 0.45)], 16)
    cushion = box(-0.44, 0.30, -0.36, 0.44, 0.78, 0.36)
    volutes = [lathe([(0.2, -0.38), (0.2, 0.38)], 12, axis="z") for _ in range(2)]
    for side, volute in zip((-1, 1), volutes):
        volute.vertices = [(x + side * 0.4, y + 0.52, z) for x, y, z in volute.vertices]
    abacus = box(-0.53, 0.78, -0.53, 0.53, 1.0, 0.53)
    return combine(echinus, cushion, *volutes, abacus)


def prism(outline, z0: float, z1: float) -> Mesh:
    """A prism along z over a convex ``outline`` of (x, y) points, counter-clockwise seen from +z."""
    n = len(outline)
    points = [(x, y, z0) for x, y in outline] + [(x, y, z1) for x, y in outline]
    faces = [list(reversed(range(n))), list(range(n, 2 * n))]
    faces += [[k, (k + 1) % n, n + (k + 1) % n, n + k] for k in range(n)]
    return Mesh().add(points, faces)


def archway() -> Mesh:
    """A bay of an arcaded wall, through its thickness (z): two piers to the springing at half height and
    a semicircular arch over an opening 0.6 of the bay wide; the spandrels are quads between the arch and
    the bay's outline along rays from the arch's centre (every 15 degrees, so the rays meet the corners)."""
    half, spring, steps = 0.3, 0.5, 12
    parts = [prism([(-0.5, 0.0), (-half, 0.0), (-half, spring), (-0.5, spring)], 0.0, 1.0),
             prism([(half, 0.0), (0.5, 0.0), (0.5, spring), (half, spring)], 0.0, 1.0)]

    def on_outline(angle: float) -> tuple[float, float]:
        """Where the ray from the arch's centre at ``angle`` leaves the bay above the springing."""
        dx, dy = math.cos(angle), math.sin(angle)
        t = min(0.5 / abs(dx) if abs(dx) > 1e-12 else math.inf, (1.0 - spring) / dy if dy > 1e-12 else math.inf)
        return round(dx * t, 12), round(spring + dy * t, 12)

    for k in range(steps):
        a0, a1 = math.pi * k / steps, math.pi * (k + 1) / steps
        inner0 = (half * math.cos(a0), spring + half * math.sin(a0))
        inner1 = (half * math.cos(a1), spring + half * math.sin(a1))
        parts.append(prism([inner0, on_outline(a0), on_outline(a1), inner1][::-1], 0.0, 1.0))
    return combine(*parts)


def statue() -> Mesh:
    """A standing figure: legs and draped body, arms, head (the cult statue and the forum's honours)."""
    body = lathe([(0.24, 0.0), (0.26, 0.45), (0.2, 0.78), (0.0, 0.84)], 8)
    head = lathe([(0.0, 0.83), (0.09, 0.87), (0.09, 0.95), (0.0, 1.0)], 8)
    arms = box(-0.34, 0.6, -0.06, 0.34, 0.7, 0.06)
    return combine(body, head, arms)


def tree_cypress() -> Mesh:
    """A cypress: a slender spindle on a short trunk."""
    return combine(lathe([(0.06, 0.0), (0.06, 0.12)], 6), lathe([(0.35, 0.1), (0.5, 0.35), (0.3, 0.75), (0.0, 1.0)], 8))


def tree_pine() -> Mesh:
    """An umbrella pine: a tall trunk under a flat, wide crown."""
    return combine(lathe([(0.05, 0.0), (0.04, 0.66)], 6), lathe([(0.3, 0.62), (0.5, 0.75), (0.42, 0.9), (0.0, 1.0)], 10))


ASSETS = {"ionic_base": ionic_base, "ionic_shaft": ionic_shaft, "ionic_capital": ionic_capital,
          "archway": archway, "statue": statue, "tree_cypress": tree_cypress, "tree_pine": tree_pine}


NOTE = "made by make_assets.py (grammarc Vitruvian example); unit box, y up, +z front"


def obj_files() -> dict[str, tuple[str, int]]:
    """Each asset's file name, OBJ text and triangle count (``assetkit.obj_files``; the tests compare)."""
    return assetkit.obj_files(ASSETS, NOTE)


if __name__ == "__main__":
    assetkit.main(ASSETS, NOTE, Path(__file__).resolve().parent, __doc__.splitlines()[0])
