"""Make assets/*.obj: the terminal objects of the Xkipche example, deterministically.

The Puuc paper (Mueller et al. 2006, section 4.2) inserts its stones as objects: `wall.obj`, `lintel.obj`,
`jamb.obj`, `apron.obj`, `reverse_apron.obj` and `cylinder.obj` (the colonette) are named in rules 6-19,
and the masks "are separately reconstructed ornaments of high geometrical complexity" that were modelled
with "traditional mesh modeling software" (Figure 10). We have neither their meshes nor their textures, so
this script makes small stand-ins of our own from boxes, lathed and extruded profiles: enough for the
grammar to place them and for a picture to read as a Puuc facade, not a reconstruction of the stones.

Conventions. Every file is written in the unit box [0, 1]^3 (grammarc fits an asset's bounding box to the
scope it is inserted in) with 4 decimals, so the same script always writes the same bytes. Facade pieces
use the paper's facade frame: x along the wall, y up, z *into* the wall, so the face seen from outside is
at z = 0 and relief stands out towards -z before the fit (xkipche.cga turns grammarc's outward facade
frame into this one at rule 2). The stairway is a lot piece: z runs from the platform (z = 0) out to the
front.

    python make_assets.py [--out assets]
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # examples/assetkit.py
import assetkit
from assetkit import Mesh, box, combine, extrude_x, lathe

# ------------------------------------------------------------------------------------------ primitives


def relief(x0, y0, x1, y1, out: float, back: float = 0.0) -> Mesh:
    """A block on a facade: the rectangle [x0, x1] x [y0, y1] standing ``out`` in front of the plane
    z = -back (the facade frame's z points into the wall, so "in front" is -z)."""
    return box(x0, y0, -back - out, x1, y1, -back)


def extrude_z(profile, z0: float, z1: float) -> Mesh:
    """A prism along z over ``profile``, (x, y) points counter-clockwise seen from -z (from outside)."""
    n = len(profile)
    points = [(x, y, z0) for x, y in profile] + [(x, y, z1) for x, y in profile]
    faces = [list(range(n)), list(reversed(range(n, 2 * n)))]
    faces += [[k, n + k, n + (k + 1) % n, (k + 1) % n] for k in range(n)]
    return Mesh().add(points, faces)


# -------------------------------------------------------------------------------- the paper's stones


def wall() -> Mesh:
    """Veneer wall block (rules 6, 14-17, 20): a box; the grammar gives it its size and projection."""
    return box(0.0, 0.0, 0.0, 1.0, 1.0, 1.0)


def lintel() -> Mesh:
    """Door lintel (rule 8): a stone beam with a slightly recessed soffit band along its lower edge."""
    return combine(box(0.0, 0.12, 0.0, 1.0, 1.0, 1.0), box(0.02, 0.0, 0.04, 0.98, 0.12, 1.0))


def jamb() -> Mesh:
    """Door jamb (rule 9): a dressed stone post with a small corbel at its top ([Car86], section 3.2),
    the corbel standing out of the post's face."""
    return combine(box(0.0, 0.0, 0.0, 1.0, 0.93, 1.0), box(0.0, 0.93, -0.06, 1.0, 1.0, 1.0))


def apron() -> Mesh:
    """Apron member of a molding (rule 14): the sloped stone in front of the wall, thickest at its foot
    (we read Pollock's apron as leaning back as it rises; the paper does not draw the slope's sense)."""
    return extrude_x([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.8, 1.0)])


def reverse_apron() -> Mesh:
    """Reverse apron member (rule 17): the apron upside down, thickest at its top."""
    return extrude_x([(0.8, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)])


def cylinder() -> Mesh:
    """Colonette (rule 19: "cylinder.obj"; section 3.2: "serrated cylinders"): a 10-sided drum bound
    at its ends and at mid-height, the binders standing proud of the waisted shaft."""
    profile = [(0.5, 0.0), (0.5, 0.07), (0.42, 0.09), (0.42, 0.44), (0.5, 0.46), (0.5, 0.54),
               (0.42, 0.56), (0.42, 0.91), (0.5, 0.93), (0.5, 1.0)]
    return lathe(profile, 10, 0.5, 0.5)


# ------------------------------------------------------------------------------- frieze ornaments


def chaac(width: float, height: float, nose: float) -> Mesh:
    """A long-nosed mask (the rain god Chaac of section 3.2) of ``width`` x ``height`` on its backing
    slab: brow band, two eyes with pupils, ear flares, a snout whose nose juts ``nose`` out and curls up,
    a mouth with four teeth and a chin band. Proportions are ours, after photographs of Puuc masks."""
    w, h = width, height
    parts = [relief(0.0, 0.0, w, h, 0.08),                                   # backing slab
             relief(0.05 * w, 0.80 * h, 0.95 * w, 0.95 * h, 0.10, 0.08),     # brow band
             relief(0.0, 0.40 * h, 0.12 * w, 0.75 * h, 0.14, 0.08),          # ear flares
             relief(0.88 * w, 0.40 * h, w, 0.75 * h, 0.14, 0.08),
             relief(0.36 * w, 0.16 * h, 0.64 * w, 0.32 * h, 0.10, 0.08),     # mouth
             relief(0.10 * w, 0.0, 0.90 * w, 0.12 * h, 0.06, 0.08)]          # chin band
    for x0 in (0.17, 0.60):                                                  # eyes and pupils
        parts.append(relief(x0 * w, 0.52 * h, (x0 + 0.23) * w, 0.76 * h, 0.10, 0.08))
        parts.append(relief((x0 + 0.07) * w, 0.58 * h, (x0 + 0.16) * w, 0.70 * h, 0.06, 0.18))
    for k in range(4):                                                       # teeth
        x0 = (0.39 + 0.06 * k) * w
        parts.append(relief(x0, 0.11 * h, x0 + 0.04 * w, 0.17 * h, 0.05, 0.08))
    # the snout, then the nose jutting out and curling up in two steps (the Puuc "trunk")
    parts.append(relief(0.42 * w, 0.34 * h, 0.58 * w, 0.60 * h, 0.16, 0.08))
    parts.append(relief(0.44 * w, 0.34 * h, 0.56 * w, 0.44 * h, nose, 0.24))
    parts.append(relief(0.45 * w, 0.44 * h, 0.55 * w, 0.56 * h, 0.12, 0.12 + nose))
    return combine(*parts)


def mask() -> Mesh:
    """Front mask over a doorway (the paper's "front mask"): a broad Chaac face."""
    return chaac(2.0, 1.7, 0.34)


def edge_mask() -> Mesh:
    """Edge mask (the paper's "edge mask"): a narrow Chaac face for the stacks at a building's corners,
    with a longer nose, as corner masks jut out further."""
    return chaac(1.0, 0.95, 0.42)


def frame(out: float) -> list[Mesh]:
    """The plain border of a unit mosaic panel, ``out`` in front of a recessed ground."""
    b = 0.07
    return [relief(0.0, 0.0, 1.0, 1.0, 0.02),
            relief(0.0, 0.0, 1.0, b, out, 0.02), relief(0.0, 1.0 - b, 1.0, 1.0, out, 0.02),
            relief(0.0, b, b, 1.0 - b, out, 0.02), relief(1.0 - b, b, 1.0, 1.0 - b, out, 0.02)]


def lattice() -> Mesh:
    """Lattice panel (section 3.2: "lattice work"): 4 x 4 diamonds standing out of the ground inside a
    border, the X-crossed stones of the Puuc celosia seen as their diamond faces."""
    parts = frame(0.10)
    cell = (1.0 - 2 * 0.07) / 4
    for i in range(4):
        for j in range(4):
            cx, cy, r = 0.07 + (i + 0.5) * cell, 0.07 + (j + 0.5) * cell, 0.44 * cell
            diamond = [(cx, cy - r), (cx + r, cy), (cx, cy + r), (cx - r, cy)]
            parts.append(extrude_z(diamond, -0.10, -0.02))
    return combine(*parts)


def fret() -> Mesh:
    """Stepped fret panel (section 3.2: "stepped frets", the greca escalonada): a stair of four steps
    rising from the lower left and a hook curling in from the upper right, inside a border."""
    parts = frame(0.10)
    for k in range(4):                       # the steps
        parts.append(relief(0.07, 0.07 + 0.12 * k, 0.07 + 0.5 - 0.12 * k, 0.07 + 0.12 * (k + 1), 0.10, 0.02))
    # the hook: down from the top border, along, and back up
    parts += [relief(0.80, 0.35, 0.93, 0.93, 0.10, 0.02), relief(0.45, 0.35, 0.80, 0.47, 0.10, 0.02),
              relief(0.45, 0.47, 0.57, 0.75, 0.10, 0.02), relief(0.57, 0.63, 0.68, 0.75, 0.10, 0.02)]
    return combine(*parts)


# -------------------------------------------------------------------------------- doors and platforms


def door_column() -> Mesh:
    """Door column (section 3.2: doors "framed by columns with simple, rectangular capitals" [Car86]):
    a square base, an 8-sided shaft and a square capital under its abacus."""
    base = box(-0.5, 0.0, -0.5, 0.5, 0.06, 0.5)
    shaft = lathe([(0.40, 0.06), (0.36, 0.88)], 8)
    capital = box(-0.45, 0.88, -0.45, 0.45, 0.94, 0.45)
    abacus = box(-0.5, 0.94, -0.5, 0.5, 1.0, 0.5)
    return combine(base, shaft, capital, abacus)


def stairway() -> Mesh:
    """Stairway up a platform (section 3.2: Puuc houses "were often built on a platform sub-structure";
    the paper does not say how it was climbed, we give it a flight of 8 steps): full height at z = 0
    (the platform), down to the ground at z = 1."""
    steps = 8
    profile = [(0.0, 0.0), (1.0, 0.0)]
    for k in range(steps):
        profile += [(1.0 - k / steps, (k + 1) / steps), (1.0 - (k + 1) / steps, (k + 1) / steps)]
    return extrude_x(profile)


ASSETS = {"wall": wall, "lintel": lintel, "jamb": jamb, "apron": apron, "reverse_apron": reverse_apron,
          "cylinder": cylinder, "mask": mask, "edge_mask": edge_mask, "lattice": lattice, "fret": fret,
          "door_column": door_column, "stairway": stairway}


NOTE = "made by make_assets.py (grammarc Xkipche example); unit box, y up, +z into the wall"


def obj_files() -> dict[str, tuple[str, int]]:
    """Each asset's file name, OBJ text and triangle count (``assetkit.obj_files``; the tests compare)."""
    return assetkit.obj_files(ASSETS, NOTE)


if __name__ == "__main__":
    assetkit.main(ASSETS, NOTE, Path(__file__).resolve().parent, __doc__.splitlines()[0])
