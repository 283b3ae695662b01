"""Make assets/*.obj: the terminal objects of the Pompeii example, deterministically.

The paper's Pompeii (section 7.2, Figure 18) is "a rule-based composition of 36 terminal objects (plus 4
tree types)", modelled in Maya because small curved details (capitals, roof bricks, grilles) are where a
split grammar is inefficient (section 8). This script plays Maya's part with a few primitives (boxes,
lathed profiles, extruded profiles, crossed quads), so that the assets are ours, reproducible and small
(8 to 400 triangles each): the grammar places them, it does not model them. We make 36 in all, the 4
trees among them.

Conventions, those of a scope (grammarc fits an asset's bounding box to the scope it is inserted in):
x along the wall or street, y up, z out of the building towards the viewer (+z is the front). Files are
written in the unit box [0, 1]^3 with 4 decimals, so the same script always writes the same bytes.

    python make_assets.py [--out assets]
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # examples/assetkit.py
import assetkit
from assetkit import Mesh, box, combine, extrude_x, lathe

# ------------------------------------------------------------------------------------------ primitives


def extrude_z(profile, z0: float, z1: float) -> Mesh:
    """A prism along z over ``profile``: (x, y) points, counter-clockwise seen from +z. Pediments, door
    frames: everything drawn on a facade."""
    n = len(profile)
    points = [(x, y, z0) for x, y in profile] + [(x, y, z1) for x, y in profile]
    faces = [list(reversed(range(n))), list(range(n, 2 * n))]
    faces += [[k, (k + 1) % n, n + (k + 1) % n, n + k] for k in range(n)]
    return Mesh().add(points, faces)


def two_sided_quad(p0, p1, p2, p3) -> Mesh:
    """A quad with a face on each side: the leaves of a crossed-quad tree are seen from everywhere."""
    return Mesh().add([p0, p1, p2, p3], [[0, 1, 2, 3], [3, 2, 1, 0]])


# -------------------------------------------------------------------------------- columns and orders


def column_doric() -> Mesh:
    """Greek Doric as the Pompeians built it (Triangular Forum, Basilica's lower order): no base, a
    tapering shaft, a cushion-like echinus and a square abacus. 12 sides stand in for 20 flutes."""
    shaft = lathe([(0.50, 0.0), (0.42, 8.6)], 12)
    echinus = lathe([(0.42, 8.6), (0.58, 9.1), (0.58, 9.2)], 12, caps=False)
    return combine(shaft, echinus, box(-0.62, 9.2, -0.62, 0.62, 9.6, 0.62))


def column_tuscan() -> Mesh:
    """Tuscan (the plain order of brick-and-stucco peristyles): a torus base, a plain shaft, a small
    capital; 8 sides, it is the most repeated column of the town."""
    base = box(-0.55, 0.0, -0.55, 0.55, 0.22, 0.55)
    torus = lathe([(0.50, 0.22), (0.52, 0.32), (0.44, 0.42)], 8, caps=False)
    shaft = lathe([(0.44, 0.42), (0.38, 8.2)], 8)
    cap = lathe([(0.38, 8.2), (0.50, 8.5)], 8)
    return combine(base, torus, shaft, cap, box(-0.55, 8.5, -0.55, 0.55, 8.8, 0.55))


def column_ionic() -> Mesh:
    """Ionic (the Forum's upper order, the Basilica, the Temple of Apollo's portico): an Attic base, a
    slender shaft and a capital whose two volutes are short cylinders along z on either side."""
    plinth = box(-0.6, 0.0, -0.6, 0.6, 0.18, 0.6)
    base = lathe([(0.55, 0.18), (0.55, 0.30), (0.46, 0.36), (0.52, 0.44), (0.42, 0.52)], 12, caps=False)
    shaft = lathe([(0.42, 0.52), (0.36, 8.6)], 12)
    echinus = lathe([(0.36, 8.6), (0.46, 8.8)], 12)
    pad = box(-0.62, 8.72, -0.40, 0.62, 8.98, 0.40)
    volutes = []
    for side in (-1, 1):
        ring = lathe([(0.0, 0.0), (0.22, 0.0), (0.22, 0.80), (0.0, 0.80)], 8)
        # turn the lathe's vertical axis into z: (x, y, z) -> (x, -z, y) about the volute's centre
        ring.vertices = [(side * 0.62 + x, 8.85 - z, -0.40 + y) for x, y, z in ring.vertices]
        volutes.append(ring)
    return combine(plinth, base, shaft, echinus, pad, *volutes, box(-0.58, 8.98, -0.58, 0.58, 9.1, 0.58))


def column_corinthian() -> Mesh:
    """Corinthian (the Temple of Jupiter, later temples): base, a 16-sided shaft and a bell capital with
    two rows of eight leaves (small wedges) under a concave abacus, simplified to a square one."""
    base = lathe([(0.58, 0.0), (0.58, 0.20), (0.48, 0.28), (0.54, 0.38), (0.42, 0.48)], 12, caps=True)
    shaft = lathe([(0.42, 0.48), (0.36, 8.4)], 16)
    bell = lathe([(0.36, 8.4), (0.48, 9.3)], 16)
    leaves = []
    for row, (y0, y1, r) in enumerate(((8.4, 8.85, 0.40), (8.7, 9.15, 0.45))):
        for k in range(8):
            a = 2 * math.pi * (k + 0.5 * row) / 8
            c, s = math.cos(a), math.sin(a)
            leaf = extrude_z([(-0.1, y0), (0.1, y0), (0.0, y1)], 0.0, 0.12)
            # the leaf stands on the bell at angle a, facing out: its z becomes the radial direction
            leaf.vertices = [(c * (r + z) - s * x, y, -s * (r + z) - c * x) for x, y, z in leaf.vertices]
            leaves.append(leaf)
    abacus = box(-0.62, 9.3, -0.62, 0.62, 9.55, 0.62)
    return combine(base, shaft, bell, *leaves, abacus)


def pilaster() -> Mesh:
    """A flat pilaster for the piers of shop fronts and house doorways (the tufa pilasters with
    capitals of the Samnite houses): base, shaft standing 0.3 out of the wall, capital."""
    return combine(box(-0.55, 0.0, 0.0, 0.55, 0.3, 0.40), box(-0.45, 0.3, 0.0, 0.45, 5.4, 0.30),
                   box(-0.50, 5.4, 0.0, 0.50, 5.6, 0.36), box(-0.58, 5.6, 0.0, 0.58, 5.8, 0.42))


def entablature() -> Mesh:
    """Architrave, frieze and cornice in section, along x: it caps every colonnade."""
    profile = [(0.0, 0.0), (0.55, 0.0), (0.55, 0.35), (0.60, 0.40), (0.50, 0.45), (0.50, 0.80),
               (0.70, 0.85), (0.85, 0.95), (0.85, 1.05), (0.0, 1.05)]
    return extrude_x(profile, 0.0, 4.0)


def cornice() -> Mesh:
    """The small moulded coping that tops plastered house walls and shop fronts."""
    return extrude_x([(0.0, 0.0), (0.25, 0.0), (0.30, 0.08), (0.42, 0.14), (0.42, 0.22), (0.0, 0.22)], 0.0, 2.0)


def pediment() -> Mesh:
    """A temple's gable front: a recessed tympanum framed by horizontal and raking cornices, drawn in
    x-y (apex at x = 0.5) and thin along z; slope 1:4 as Vitruvius gives it (IV.7)."""
    w, h = 12.0, 3.0
    frame = extrude_z([(0.0, 0.0), (w, 0.0), (w / 2, h)], 0.0, 0.3)
    tympanum = extrude_z([(0.9, 0.35), (w - 0.9, 0.35), (w / 2, h - 0.45)], 0.3, 0.45)
    cornice_z = extrude_z([(-0.2, -0.2), (w + 0.2, -0.2), (w + 0.2, 0.0), (-0.2, 0.0)], 0.0, 0.7)
    return combine(frame, tympanum, cornice_z)


def podium() -> Mesh:
    """The high podium of a Roman temple (Vitruvius' Tuscan temple, the Capitolium): a base moulding,
    the die, a crowning moulding."""
    return combine(box(0.0, 0.0, 0.0, 10.0, 0.4, 20.0), box(0.2, 0.4, 0.2, 9.8, 2.6, 19.8),
                   box(0.05, 2.6, 0.05, 9.95, 3.0, 19.95))


def steps() -> Mesh:
    """A flight of seven steps rising towards the back (-z): temple fronts, podia, thresholds."""
    n = 7
    profile = [(0.0, 0.0), (float(n), 0.0)]
    for k in range(n):
        profile += [(float(n - k), float(k + 1)), (float(n - k - 1), float(k + 1))]
    return extrude_x(profile, 0.0, 8.0)


# ------------------------------------------------------------------------------------------------ roofs


def roof_gable() -> Mesh:
    """A gable roof's body: a triangular prism, ridge along x; Pompeian pitches are low (about 20 deg)."""
    return extrude_x([(0.0, 0.0), (1.0, 0.0), (0.5, 0.36)], 0.0, 1.0)


def roof_shed() -> Mesh:
    """A lean-to roof's body, high at the back (z = 0), its eave at the front (z = 1): the roofs of
    shops, porticoes and the compluviate roofs that slope into an atrium."""
    return extrude_x([(0.0, 0.0), (1.0, 0.0), (0.0, 0.36)], 0.0, 1.0)


def tile_row() -> Mesh:
    """One row of the Roman tiled roof on a slope falling towards +z: two flat tegulae side by side and
    the imbrices over their joints (triangular ridges here), so rows side by side read as the ribbed roof."""
    slope = [(0.0, 1.0), (1.0, 0.0), (1.0, 0.03), (0.0, 1.03)]
    plate = Mesh().add([(x, y, z) for x in (0.0, 1.0) for z, y in slope],
                       [[0, 1, 2, 3][::-1], [4, 5, 6, 7], [0, 4, 7, 3][::-1], [1, 5, 6, 2],
                        [0, 1, 5, 4], [3, 7, 6, 2][::-1]])
    ribs = []
    for xc in (0.0, 0.5, 1.0):
        # an imbrex: a triangular ridge along the slope, 0.12 wide
        section = [(xc - 0.06, 0.0), (xc + 0.06, 0.0), (xc, 0.07)]
        rib = Mesh()
        for t in (0.0, 1.0):
            z, y = t, 1.03 - t
            rib.vertices += [(x, y + dy, z) for x, dy in section]
        rib.faces = [[0, 1, 2], [5, 4, 3], [0, 3, 4, 1], [1, 4, 5, 2], [2, 5, 3, 0]]
        ribs.append(rib)
    mesh = combine(plate, *ribs)
    mesh.vertices = [(min(max(x, 0.0), 1.0), y, z) for x, y, z in mesh.vertices]
    return mesh


def ridge_tile() -> Mesh:
    """The half-round ridge cover along x that closes a gable roof."""
    section = [(0.5 + 0.5 * math.cos(math.pi * k / 6), 0.5 * math.sin(math.pi * k / 6)) for k in range(7)]
    return extrude_x(section, 0.0, 4.0)


def vault() -> Mesh:
    """A barrel vault, solid, its axis along z: the halls of the baths (tepidarium, caldarium)."""
    k = 10
    outer = [(0.5 + 0.5 * math.cos(math.pi * i / k), 0.5 * math.sin(math.pi * i / k) + 0.1) for i in range(k + 1)]
    profile = [(1.0, 0.0)] + outer + [(0.0, 0.0)]
    return extrude_z(profile, 0.0, 1.0)


def dome() -> Mesh:
    """A low dome on a drum: the round frigidarium of the Stabian and Forum baths, the macellum's tholos."""
    profile = [(0.5, 0.0), (0.5, 0.25)] + [(0.5 * math.cos(a), 0.25 + 0.45 * math.sin(a))
                                           for a in np.linspace(0.2, 1.35, 5)] + [(0.0, 0.72)]
    return lathe(profile, 12)


# --------------------------------------------------------------------------------- openings and shops


def door() -> Mesh:
    """A double door of wooden leaves with raised panels, in its frame (x-y, thin along z)."""
    frame = extrude_z([(0.0, 0.0), (1.6, 0.0), (1.6, 3.0), (0.0, 3.0)], 0.0, 0.08)
    panels = []
    for x0 in (0.12, 0.84):
        for y0, y1 in ((0.2, 1.3), (1.5, 2.8)):
            panels.append(box(x0, y0, 0.08, x0 + 0.64, y1, 0.14))
    return combine(frame, *panels)


def shutter() -> Mesh:
    """One bay of a shop's shutter: vertical boards slid into the grooved threshold (the plaster casts
    of Pompeii's shop fronts), with the rail along their top."""
    boards = [box(0.02 + 0.25 * k, 0.0, 0.0, 0.25 * (k + 1) - 0.02, 2.9, 0.06) for k in range(4)]
    return combine(*boards, box(0.0, 2.9, -0.02, 1.0, 3.1, 0.08), box(0.0, 0.0, -0.02, 1.0, 0.08, 0.10))


def window_grille() -> Mesh:
    """A small, high window with an iron grille: Pompeian street walls were nearly blind."""
    frame = combine(box(0.0, 0.0, 0.0, 0.8, 0.08, 0.2), box(0.0, 0.52, 0.0, 0.8, 0.6, 0.2),
                    box(0.0, 0.08, 0.0, 0.08, 0.52, 0.2), box(0.72, 0.08, 0.0, 0.8, 0.52, 0.2))
    bars = [box(0.22 + 0.18 * k - 0.015, 0.08, 0.08, 0.22 + 0.18 * k + 0.015, 0.52, 0.11) for k in range(3)]
    return combine(frame, *bars)


def counter() -> Mesh:
    """A thermopolium counter: an L of masonry with three dolia (storage jars) sunk in its top."""
    body = combine(box(0.0, 0.0, 0.0, 3.0, 1.0, 0.7), box(2.3, 0.0, -1.4, 3.0, 1.0, 0.0))
    rims = [lathe([(0.22, 1.0), (0.22, 1.05), (0.16, 1.05), (0.16, 1.0)], 8, cx=0.5 + 0.8 * k, cz=0.35,
                  caps=False) for k in range(3)]
    return combine(body, *rims)


# ---------------------------------------------------------------------------------- things in rooms


def amphora() -> Mesh:
    """A transport amphora: a pointed toe, a long body, shoulders and a neck (8 sides)."""
    return lathe([(0.0, 0.0), (0.05, 0.12), (0.18, 0.35), (0.22, 0.6), (0.2, 0.8), (0.07, 0.9),
                  (0.06, 1.05), (0.08, 1.1), (0.0, 1.1)], 8)


def impluvium() -> Mesh:
    """The atrium's rain basin under the compluvium: a marble kerb round a sunken floor."""
    rim = 0.12
    return combine(box(0.0, 0.0, 0.0, 1.0, 0.04, 1.0), box(0.0, 0.0, 0.0, 1.0, 0.2, rim),
                   box(0.0, 0.0, 1.0 - rim, 1.0, 0.2, 1.0), box(0.0, 0.0, rim, rim, 0.2, 1.0 - rim),
                   box(1.0 - rim, 0.0, rim, 1.0, 0.2, 1.0 - rim))


def fountain() -> Mesh:
    """A street fountain at a crossing: a basin of four lava slabs and a pillar with a spout."""
    basin = impluvium()
    basin.vertices = [(x * 1.6, y * 4.0, z * 1.0) for x, y, z in basin.vertices]
    pillar = box(0.6, 0.0, -0.3, 1.0, 1.3, 0.0)
    return combine(basin, pillar, box(0.75, 1.0, 0.0, 0.85, 1.08, 0.25))


def labrum() -> Mesh:
    """The round basin on a foot of a bath's caldarium."""
    return lathe([(0.0, 0.0), (0.25, 0.0), (0.12, 0.1), (0.1, 0.7), (0.5, 0.9), (0.55, 1.0), (0.0, 1.0)], 12)


def puteal() -> Mesh:
    """A well-head or cistern mouth, a short stone drum with a moulded rim."""
    return lathe([(0.0, 0.0), (0.5, 0.0), (0.5, 0.1), (0.44, 0.15), (0.44, 0.85), (0.5, 0.9), (0.5, 1.0),
                  (0.0, 1.0)], 12)


def table() -> Mesh:
    """A cartibulum, the marble table at the atrium's impluvium: a slab on two carved supports."""
    return combine(box(0.0, 0.8, 0.0, 1.4, 0.9, 0.7), box(0.1, 0.0, 0.15, 0.25, 0.8, 0.55),
                   box(1.15, 0.0, 0.15, 1.3, 0.8, 0.55), box(0.05, 0.0, 0.1, 0.3, 0.1, 0.6),
                   box(1.1, 0.0, 0.1, 1.35, 0.1, 0.6))


def bench() -> Mesh:
    """A stone bench (schola) with a back: porticoes, gardens, the palaestra."""
    return combine(box(0.0, 0.42, 0.0, 2.0, 0.5, 0.5), box(0.1, 0.0, 0.1, 0.3, 0.42, 0.4),
                   box(1.7, 0.0, 0.1, 1.9, 0.42, 0.4), box(0.0, 0.5, 0.0, 2.0, 0.9, 0.08))


def altar() -> Mesh:
    """An altar: a plinth, a die, a cornice and the two bolsters (pulvini) on top."""
    die = combine(box(0.0, 0.0, 0.0, 1.4, 0.2, 1.0), box(0.1, 0.2, 0.1, 1.3, 1.0, 0.9),
                  box(0.0, 1.0, 0.0, 1.4, 1.15, 1.0))
    bolsters = []
    for x0 in (0.05, 1.2):
        b = lathe([(0.0, 0.0), (0.1, 0.0), (0.1, 1.0), (0.0, 1.0)], 6)
        b.vertices = [(x0 + 0.075 + x * 0.75, 1.25 - z * 0.75, y) for x, y, z in b.vertices]
        bolsters.append(b)
    return combine(die, *bolsters)


def statue() -> Mesh:
    """A statue on its base, the stand-in for the honorary statues lining the Forum: a moulded pedestal,
    a draped body (a lathed column of cloth) and a head."""
    pedestal = combine(box(-0.5, 0.0, -0.5, 0.5, 0.2, 0.5), box(-0.42, 0.2, -0.42, 0.42, 1.4, 0.42),
                       box(-0.5, 1.4, -0.5, 0.5, 1.55, 0.5))
    body = lathe([(0.3, 1.55), (0.26, 2.4), (0.2, 3.0), (0.08, 3.1)], 8)
    head = lathe([(0.0, 3.1), (0.1, 3.2), (0.09, 3.35), (0.0, 3.42)], 6)
    return combine(pedestal, body, head)


def lararium() -> Mesh:
    """The household shrine in the atrium or kitchen: a ledge, two pilasters, a niche and a pediment."""
    return combine(box(0.0, 0.0, 0.0, 1.2, 0.1, 0.45), box(0.0, 0.1, 0.0, 1.2, 1.0, 0.1),
                   box(0.0, 0.1, 0.1, 0.15, 1.0, 0.35), box(1.05, 0.1, 0.1, 1.2, 1.0, 0.35),
                   box(-0.05, 1.0, 0.0, 1.25, 1.1, 0.4),
                   extrude_z([(-0.05, 1.1), (1.25, 1.1), (0.6, 1.45)], 0.0, 0.4))


def oven() -> Mesh:
    """A bakery's bread oven: a masonry block with a domed top and a flue (the pistrinum of Modestus)."""
    block = box(0.0, 0.0, 0.0, 2.4, 1.2, 2.4)
    cupola = lathe([(1.1, 1.2), (1.0, 1.6), (0.7, 1.9), (0.3, 2.05), (0.0, 2.08)], 10, cx=1.2, cz=1.2)
    flue = box(1.0, 1.2, 2.0, 1.4, 2.8, 2.4)
    return combine(block, cupola, flue)


def millstone() -> Mesh:
    """A Pompeian donkey mill: the conical meta on a round base and the hourglass catillus over it."""
    base = lathe([(0.0, 0.0), (0.8, 0.0), (0.8, 0.4), (0.0, 0.4)], 10)
    catillus = lathe([(0.0, 0.4), (0.55, 0.4), (0.3, 1.0), (0.55, 1.6), (0.0, 1.6)], 10)
    arms = box(-0.75, 0.95, -0.06, 0.75, 1.05, 0.06)
    return combine(base, catillus, arms)


# -------------------------------------------------------------------------------------------- trees


def tree_cypress() -> Mesh:
    """Cypress: a trunk and a slim cone of foliage (the funerary and garden tree)."""
    return combine(lathe([(0.12, 0.0), (0.1, 1.0)], 6), lathe([(0.45, 1.0), (0.55, 2.5), (0.0, 8.0)], 8))


def tree_pine() -> Mesh:
    """Umbrella pine (Pinus pinea): a tall bare trunk under a flat, wide crown."""
    trunk = lathe([(0.25, 0.0), (0.16, 6.0)], 6)
    crown = lathe([(0.0, 5.6), (2.2, 6.0), (3.0, 6.8), (2.4, 7.6), (0.0, 8.0)], 10)
    return combine(trunk, crown)


def tree_olive() -> Mesh:
    """Olive or fig in a garden: a trunk and three crossed quads of foliage (billboards, cheap)."""
    trunk = lathe([(0.15, 0.0), (0.12, 1.6)], 5)
    quads = []
    for k in range(3):
        a = math.pi * k / 3
        dx, dz = 2.0 * math.cos(a), -2.0 * math.sin(a)
        quads.append(two_sided_quad((-dx, 1.2, -dz), (dx, 1.2, dz), (dx, 4.4, dz), (-dx, 4.4, -dz)))
    return combine(trunk, *quads)


def shrub() -> Mesh:
    """A shrub, vine or hedge plant: two crossed quads, the filler of gardens and vineyards."""
    return combine(two_sided_quad((-0.5, 0.0, 0.0), (0.5, 0.0, 0.0), (0.5, 1.0, 0.0), (-0.5, 1.0, 0.0)),
                   two_sided_quad((0.0, 0.0, 0.5), (0.0, 0.0, -0.5), (0.0, 1.0, -0.5), (0.0, 1.0, 0.5)))


ASSETS = {
    "column_doric": column_doric, "column_tuscan": column_tuscan, "column_ionic": column_ionic,
    "column_corinthian": column_corinthian, "pilaster": pilaster, "entablature": entablature,
    "cornice": cornice, "pediment": pediment, "podium": podium, "steps": steps,
    "roof_gable": roof_gable, "roof_shed": roof_shed, "tile_row": tile_row, "ridge_tile": ridge_tile,
    "vault": vault, "dome": dome,
    "door": door, "shutter": shutter, "window_grille": window_grille, "counter": counter,
    "amphora": amphora, "impluvium": impluvium, "fountain": fountain, "labrum": labrum, "puteal": puteal,
    "table": table, "bench": bench, "altar": altar, "statue": statue, "lararium": lararium,
    "oven": oven, "millstone": millstone,
    "tree_cypress": tree_cypress, "tree_pine": tree_pine, "tree_olive": tree_olive, "shrub": shrub,
}  # fmt: skip


NOTE = "made by make_assets.py (grammarc Pompeii example); unit box, y up, +z front"


def obj_files() -> dict[str, tuple[str, int]]:
    """Each asset's file name, OBJ text and triangle count (``assetkit.obj_files``; the tests compare)."""
    return assetkit.obj_files(ASSETS, NOTE)


if __name__ == "__main__":
    assetkit.main(ASSETS, NOTE, Path(__file__).resolve().parent, __doc__.splitlines()[0])
