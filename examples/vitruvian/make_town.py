"""Make lots.geojson: a Vitruvian town laid out as Noghani's thesis does it, deterministically.

"The procedural generation of Vitruvian architecture" (J. Noghani, Coventry, 2015; seed 002 in shared/)
turns De Architectura into a city generator. This script is its layout half (thesis section 3.2.1-3.2.4);
the buildings are grammar (vitruvian.cga). Step by step:

1. **Terrain** (3.2.1): the thesis draws a 256 x 256 Perlin heightmap at one pixel per 100 m^2 (10 m a
   side, a 2,560 m map) with a water line. We make a smooth synthetic one with the same scale: land
   rising from a sea in the south, three hills, and a river running down to the sea in a valley, plus an
   existing road (a via along the coast) for the road factor.
2. **Site** (3.2.1.3, Method 3): every pixel gets the weighted point value
   ``PV = Cd*Cw + Wd*Ww + Rd*Rw + (Gw*G)*(Hw*(MH - H))`` and the lowest PV wins (ties: the lowest Cd).
   Cd, Wd, Rd are the distances (m) to the map centre, the nearest water and the road, G the gradient
   (rise over run: 0 flat, 1 at 45 degrees, as the thesis asks), H the height and MH the map's highest
   point (m). A pixel is usable when the town's wall and its extramural temples would stand on land inside
   the map (the thesis rejects points in water or too close to the map's edge, 3.2.1.1 and 4.1).
3. **Wall** (3.2.2): a pentagon (the thesis's choice over Vitruvius's octagon) whose towers stand one
   bowshot apart: 600 Roman feet, "approximately 182 meters". We make each side exactly three bowshots
   (546 m), so the towers are 182 m apart and the perimeter (2.73 km) lies in the thesis's 1.869-3.744
   km. One side faces the nearest water (the harbour side). Gates open where the two main streets meet
   the wall.
4. **Streets** (3.2.3): a grid of square insulae of 73 m, streets 5 m wide (the thesis: 5-7 m with
   sidewalks, 4.5 m the legal minimum) and the two main ones (cardo and decumanus maximus, beside the
   forum) 7 m; a 10 m ring road inside the wall. Insulae wholly inside are building lots; the ragged
   ones at the wall become gardens.
5. **Buildings** (3.2.4): the insula nearest the centre is the forum; its neighbours the basilica, a
   temple (Mercury's, "in or alongside the forum") and two governmental buildings; the furthest insula
   holds the theatre, with Apollo's temple beside it, and the insula furthest from the centre and the
   theatre the amphitheatre; the highest insula the Capitolium; temples of Venus, Ceres, Vulcan and Mars
   outside the walls (Vitruvius I.7). The other insulae are residential, governmental or religious and
   commercial by the thesis's probability method (3.2.4.3; see ``assign_districts`` for how we read
   its formulas).

Every lot is a polygon whose first edge is its front (a street, the forum, the outside of the wall):
grammarc puts the front at the scope's +z. Each lot carries ``kind`` and the attributes its rules read
(``columns``, ``temple_w``, ``podium_h`` of a temple; ``deity`` and ``style`` are for the reader).

    python make_town.py [--out lots.geojson] [--seed 2015]

The same arguments always write the same bytes.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
import shapely
from shapely.geometry import LineString, Point, Polygon, box

# ------------------------------------------------------------------------------------------- terrain

#: Heightmap pixels a side and metres a pixel (the thesis: 256 x 256, one pixel = 100 m^2).
MAP_PX, PIXEL = 256, 10.0
#: Weights of the point value. The thesis leaves them to the user (3.2.1.3); ours, and why:
#: water first (Vitruvius I.4, I.7: water and a harbour); the road at half (an existing via helps trade
#: and building); the centre at a fifth (the thesis added Cd only to keep towns off the map's edge, which
#: the usable test already does); Gw * Hw = 12 so that a 5% slope 40 m below the top costs as much as
#: 24 m further from water: the product term favours flat or high ground, as the thesis intends.
WEIGHTS = {"Cw": 0.2, "Ww": 1.0, "Rw": 0.5, "Gw": 12.0, "Hw": 1.0}

# ------------------------------------------------------------------------------------------- the town

#: One bowshot (600 Roman feet as the thesis converts them, 3.2.2) between towers; three to a side.
BOWSHOT, SHOTS_PER_SIDE = 182.0, 3
SIDE = BOWSHOT * SHOTS_PER_SIDE
#: Circumradius of the pentagon with that side: 464.4 m.
RADIUS = SIDE / (2 * math.sin(math.pi / 5))
#: Wall thickness: "armed men meeting on top of it may pass one another" (I.5.3); the thesis gives no
#: number, so we take two men of a metre each with shields, and a parapet: 2.5 m.
WALL_T = 2.5
#: Round towers (I.5.5: "round or polygonal") 9 m across, projecting outwards (I.5.2); gates 8 m wide.
TOWER, GATE = 9.0, 8.0
#: The ring road inside the wall (the pomerium kept free of buildings), our width.
RING_ROAD = 10.0
#: Insula side (the thesis: "approximately 73 meters squared", read as 73 m a side) and street widths.
INSULA, STREET, MAIN_STREET = 73.0, 5.0, 7.0
#: Extramural temples stand this far beyond the wall's outer face, beside the road from their gate.
TEMPLE_OUT = 40.0
#: Land the town needs round its centre: the wall, then the extramural temples and their lots.
TOWN_REACH = RADIUS + TEMPLE_OUT + 90.0
#: The probability method's damping of governmental squares: each one assigned lowers the chance of
#: the next by this (our reading of the thesis's undefined ``GovernmentalN``, see assign_districts).
GOV_STEP = 0.12


def _heights(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Terrain height (m) at map points (m): a coastal plain rising inland from the sea in the south, three
    hills, a river valley cut from north to south, and a long ripple; negative is under water."""
    coast = 430.0 + 70.0 * np.sin(2 * np.pi * x / 1700.0 + 0.8) + 25.0 * np.sin(2 * np.pi * x / 610.0 + 2.0)
    h = 0.035 * (y - coast)
    for hx, hy, top, spread in ((820.0, 1450.0, 38.0, 330.0), (1900.0, 1900.0, 60.0, 420.0),
                                (1250.0, 2250.0, 45.0, 300.0)):
        h = h + top * np.exp(-((x - hx) ** 2 + (y - hy) ** 2) / (2 * spread**2))
    river = _river_x(y)
    h = h - 14.0 * np.exp(-(((x - river) / 160.0) ** 2)) * (y > coast)
    h = h + 3.0 * np.sin(2 * np.pi * (x + 0.6 * y) / 530.0)
    return h


def _river_x(y: np.ndarray) -> np.ndarray:
    """The river's centre line: x (m) as a function of y, meandering."""
    return 1700.0 + 130.0 * np.sin(2 * np.pi * y / 950.0) + 55.0 * np.sin(2 * np.pi * y / 370.0 + 1.0)


def terrain() -> dict:
    """The heightmap and its features: ``H`` (MAP_PX, MAP_PX) heights (row = y pixel, column = x pixel),
    ``x``/``y`` the pixel centres (m), ``water`` (sea and river, shapely), ``road`` (a LineString)."""
    centres = (np.arange(MAP_PX) + 0.5) * PIXEL
    x, y = np.meshgrid(centres, centres)
    height = _heights(x, y)
    size = MAP_PX * PIXEL
    # the sea: everything below the coast line (the zero contour along the bottom of the map), traced
    # every 10 m; the river: a 30 m band along its centre line from the sea to the map top
    xs = np.linspace(0.0, size, 257)
    coast = [(float(u), float(_coast_y(u))) for u in xs]
    sea = Polygon([(0.0, -10.0), *coast, (size, -10.0)])
    ys = np.linspace(0.0, size + 10.0, 257)
    river = LineString([(float(_river_x(v)), float(v)) for v in ys]).buffer(15.0)
    water = shapely.union(sea, river)
    # a via running east-west along the coast, a little inland, bending round the hills
    road = LineString([(0.0, 760.0), (600.0, 700.0), (1200.0, 820.0), (1800.0, 760.0), (size, 900.0)])
    return {"H": height, "x": x, "y": y, "water": water, "road": road}


def _coast_y(x: float) -> float:
    """Where the land rises out of the sea at map x: the zero of ``_heights`` found by bisection in y."""
    lo, hi = -200.0, 1200.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if _heights(np.array(x), np.array(mid)) > 0:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def choose_site(t: dict) -> dict:
    """The thesis's Method 3 over every pixel: the usable pixel with the lowest point value."""
    x, y, height = t["x"], t["y"], t["H"]
    points = shapely.points(x.ravel(), y.ravel())
    w = WEIGHTS
    size = MAP_PX * PIXEL
    cd = np.hypot(x - size / 2, y - size / 2)
    wd = shapely.distance(points, t["water"]).reshape(x.shape)
    rd = shapely.distance(points, t["road"]).reshape(x.shape)
    gy, gx = np.gradient(height, PIXEL)
    g = np.hypot(gx, gy)
    mh = float(height.max())
    pv = cd * w["Cw"] + wd * w["Ww"] + rd * w["Rw"] + (w["Gw"] * g) * (w["Hw"] * (mh - height))
    inside = np.minimum.reduce([x, y, size - x, size - y])
    usable = (wd >= TOWN_REACH) & (inside >= TOWN_REACH)
    candidates = np.flatnonzero(usable.ravel())
    # lowest PV, ties broken by the lowest Cd (3.2.1.3)
    best = candidates[np.lexsort((cd.ravel()[candidates], pv.ravel()[candidates]))[0]]
    row, col = divmod(int(best), MAP_PX)
    nearest = shapely.shortest_line(t["water"], Point(x[row, col], y[row, col])).coords[0]
    return {"x": float(x[row, col]), "y": float(y[row, col]), "pixel": [col, row],
            "PV": round(float(pv[row, col]), 3), "Cd": round(float(cd[row, col]), 1),
            "Wd": round(float(wd[row, col]), 1), "Rd": round(float(rd[row, col]), 1),
            "G": round(float(g[row, col]), 4), "H": round(float(height[row, col]), 2), "MH": round(mh, 2),
            "water_towards": [round(nearest[0], 1), round(nearest[1], 1)], "weights": WEIGHTS}


# ------------------------------------------------------------------------------------------- the lots


class Town:
    """Collects lots as GeoJSON features."""

    def __init__(self) -> None:
        self.features: list[dict] = []

    def lot(self, lot_id: str, ring, **props) -> None:
        """A lot from ``ring`` ((x, y) points, not closed), whose first edge is its front. The ring is
        made counter-clockwise as RFC 7946 asks, keeping its first edge first."""
        ring = [(float(px), float(py)) for px, py in ring]
        if _signed_area(ring) < 0:
            # reversed, the old first edge (p0 -> p1) runs p1 -> p0: start the ring at p1
            ring = [ring[1], ring[0], *reversed(ring[2:])]
        coords = [[round(px, 6), round(py, 6)] for px, py in ring]
        self.features.append({"type": "Feature", "id": lot_id, "properties": props,
                              "geometry": {"type": "Polygon", "coordinates": [coords + [coords[0]]]}})

    def rect(self, lot_id: str, x0: float, y0: float, x1: float, y1: float, front: str, **props) -> None:
        """An axis-aligned lot whose first edge is side ``front`` ("S", "E", "N", "W")."""
        corners = {"S": [(x0, y0), (x1, y0), (x1, y1), (x0, y1)],
                   "E": [(x1, y0), (x1, y1), (x0, y1), (x0, y0)],
                   "N": [(x1, y1), (x0, y1), (x0, y0), (x1, y0)],
                   "W": [(x0, y1), (x0, y0), (x1, y0), (x1, y1)]}[front]
        self.lot(lot_id, corners, **props)

    def oriented(self, lot_id: str, centre, along, length: float, depth: float, **props) -> None:
        """A rectangle ``length`` along the unit vector ``along`` and ``depth`` across, centred on
        ``centre``; its first edge is the side to the right of ``along`` (the outside, for the wall)."""
        ux, uy = along
        nx, ny = uy, -ux            # the right-hand normal: outwards for a counter-clockwise wall
        cx, cy = centre
        hl, hd = length / 2, depth / 2
        ring = [(cx - ux * hl + nx * hd, cy - uy * hl + ny * hd), (cx + ux * hl + nx * hd, cy + uy * hl + ny * hd),
                (cx + ux * hl - nx * hd, cy + uy * hl - ny * hd), (cx - ux * hl - nx * hd, cy - uy * hl - ny * hd)]
        self.lot(lot_id, ring, **props)

    def polygon(self, lot_id: str, geom: Polygon, **props) -> None:
        """A clipped polygon lot, its longest edge first (along the street, or the garden's side)."""
        ring = list(shapely.normalize(geom).exterior.coords)[:-1]
        lengths = [math.dist(ring[k], ring[(k + 1) % len(ring)]) for k in range(len(ring))]
        k = int(np.argmax(np.round(lengths, 6)))
        self.lot(lot_id, ring[k:] + ring[:k], **props)


def _signed_area(ring) -> float:
    return 0.5 * sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(ring, ring[1:] + ring[:1]))


def pentagon(centre, water) -> list[tuple[float, float]]:
    """The wall's corners, counter-clockwise, one side's outward normal pointing at the nearest water."""
    cx, cy = centre
    towards = math.atan2(water[1] - cy, water[0] - cx)
    start = towards - math.pi / 5      # the side between corners 0 and 1 has its normal at ``towards``
    return [(cx + RADIUS * math.cos(start + 2 * math.pi * k / 5), cy + RADIUS * math.sin(start + 2 * math.pi * k / 5))
            for k in range(5)]


def wall_lots(town: Town, corners, main_lines) -> list[dict]:
    """Towers every bowshot along the pentagon, curtains between them, a gate where a main street (one of
    ``main_lines``) crosses a side. Returns the gates (position, outward normal, direction, side)."""
    ring = Polygon(corners).exterior
    gates = []
    for line in main_lines:
        hits = ring.intersection(line)
        gates += [(p.x, p.y) for p in getattr(hits, "geoms", [hits])]
    out = []
    for side in range(5):
        a, b = np.array(corners[side]), np.array(corners[(side + 1) % 5])
        along = (b - a) / SIDE
        normal = np.array([along[1], -along[0]])
        # gates on this side, as distances along it, kept clear of the towers
        on_side = sorted(_clear_of_towers(float(np.dot(np.array(g) - a, along))) for g in gates
                         if abs(float(np.dot(np.array(g) - a, normal))) < 1e-6 * SIDE
                         and 0.0 <= float(np.dot(np.array(g) - a, along)) <= SIDE)
        for k in range(SHOTS_PER_SIDE):
            s = k * BOWSHOT
            # corner towers stand square to the bisector, the others square to their side; each projects
            # outwards so that its inner face is the wall's
            direction = along if k else _unit(along + _unit(a - np.array(corners[side - 1])))
            outward = np.array([direction[1], -direction[0]])
            centre = a + along * s + outward * (TOWER / 2 - WALL_T / 2)
            town.oriented(f"tower-{side}-{k}", centre, direction, TOWER, TOWER, kind="tower")
            # the curtain to the next tower, cut by the gates on it
            cuts = [s + TOWER / 2] + [c for g in on_side if s < g < s + BOWSHOT
                                      for c in (g - GATE / 2, g + GATE / 2)] + [s + BOWSHOT - TOWER / 2]
            for j, (u0, u1) in enumerate(zip(cuts[::2], cuts[1::2])):
                town.oriented(f"wall-{side}-{k}-{j}", a + along * (u0 + u1) / 2, along, u1 - u0, WALL_T,
                              kind="wall")
            for j, g in enumerate(x for x in on_side if s < x < s + BOWSHOT):
                town.oriented(f"gate-{side}-{k}-{j}", a + along * g, along, GATE, WALL_T + 2.0, kind="gate")
                out.append({"at": a + along * g, "normal": normal, "along": along, "side": side})
    return out


def _clear_of_towers(s: float) -> float:
    """A gate's distance along its side, moved off the nearest tower if it would touch it (the main
    street then meets the wall a few metres beside its gate)."""
    clear = TOWER / 2 + GATE / 2 + 3.0
    tower = BOWSHOT * round(s / BOWSHOT)
    if abs(s - tower) >= clear:
        return s
    return tower + clear if s >= tower and tower < SIDE else tower - clear


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def grid_lines(centre, count: int) -> tuple[dict, dict]:
    """Insula edges: x0 of column c and y0 of row r for c, r in [-count, count]; the forum insula
    (0, 0) is centred on the town's centre, the cardo maximus runs east of it, the decumanus maximus
    south of it."""
    cx, cy = centre

    def edges(c0: float, main_after: int) -> dict:
        start = {0: c0 - INSULA / 2}
        for k in range(1, count + 1):
            start[k] = start[k - 1] + INSULA + (MAIN_STREET if k - 1 == main_after else STREET)
            start[-k] = start[-k + 1] - INSULA - (MAIN_STREET if -k == main_after else STREET)
        return start

    # the street after column 0 is the cardo maximus; the one after row -1 (south of the forum) the
    # decumanus maximus
    return edges(cx, 0), edges(cy, -1)


def assign_districts(free: list, dfc: dict, rng: np.random.Generator) -> dict:
    """The thesis's Method 3 (3.2.4.3), square by square from the centre outwards:

        ResP = (DFC / CityRadius)^2
        GovP = ((CityRadius - DFC) / CityRadius - GovernmentalN
        R = random in [0, 1): governmental if R < GovP, else residential if R > ResP, else religious

    ``GovernmentalN`` is not defined (and a bracket is not closed): we read it as the number of
    governmental squares assigned so far times GOV_STEP, so the governmental quarter stays a few squares
    round the forum instead of filling the centre. The comparisons we take as written, although they
    make ResP the probability of a religious (not a residential) square: it rises towards the wall,
    where the thesis also flags temples ("on the outskirts, or completely outside the city walls"), and
    most squares are houses, as in a real town; reading ResP by its name instead (``R > 1 - ResP``)
    turned two thirds of the town into temples and shops. Religious squares also hold the commercial
    buildings (the thesis's third group)."""
    kinds, governmental = {}, 0
    for square in sorted(free, key=lambda s: (dfc[s], s)):
        res_p = (dfc[square] / RADIUS) ** 2
        gov_p = (RADIUS - dfc[square]) / RADIUS - governmental * GOV_STEP
        r = float(rng.random())
        if r < gov_p:
            kinds[square] = "governmental"
            governmental += 1
        elif r > res_p:
            kinds[square] = "residential"
        else:
            kinds[square] = "religious"
    return kinds


def temple_props(columns: int, width: float, deity: str, podium_h: float = 2.0) -> dict:
    style = {4: "tetrastyle", 6: "hexastyle", 8: "octastyle"}[columns]
    return {"kind": "temple", "columns": float(columns), "temple_w": width, "podium_h": podium_h,
            "style": style, "deity": deity}


def cut(length: float, widths: tuple[float, float], rng: np.random.Generator) -> list[tuple[float, float]]:
    """Cut [0, length] into pieces of widths..widths[1], the last taking the rest."""
    out, u = [], 0.0
    while length - u > 0.5:
        w = float(rng.uniform(*widths))
        if length - u - w < widths[0]:
            w = length - u
        out.append((round(u, 3), round(u + w, 3)))
        u += w
    return out


def insula_lots(town: Town, name: str, x0: float, y0: float, kind: str, rng: np.random.Generator,
                facing: str) -> None:
    """An insula of a district, cut into lots: two halves back to back, each facing its street (north and
    south). Residential halves are a row of villas (18-30 m frontage: atrium, peristyle, triclinium) and
    houses (8-18 m); governmental halves two buildings each; religious and commercial insulae a small
    tetrastyle temple on the half facing the centre and a row of shops (5-8 m) on the other."""
    x1, y1, ym = x0 + INSULA, y0 + INSULA, y0 + INSULA / 2
    for side, (v0, v1) in {"S": (y0, ym), "N": (ym, y1)}.items():
        if kind == "residential":
            _row(town, f"{name}-{side}", x0, v0, v1, side, (8.0, 30.0), "villa", 18.0, "house", rng)
        elif kind == "governmental":
            # two public buildings to a half, each on a square quarter facing its street
            xm = x0 + INSULA / 2
            for k, (u0, u1) in enumerate(((x0, xm), (xm, x1))):
                town.rect(f"{name}-{side}{k}", u0, v0, u1, v1, side, kind="government")
        elif side == facing:
            town.rect(f"{name}-{side}", x0, v0, x1, v1, side,
                      **temple_props(4, round(float(rng.uniform(11.0, 14.0)), 2), "lares"))
        else:
            _row(town, f"{name}-{side}", x0, v0, v1, side, (5.0, 8.0), "shop", 0.0, "shop", rng)


def _row(town: Town, name: str, x0: float, v0: float, v1: float, side: str, widths: tuple[float, float],
         wide: str, at_least: float, narrow: str, rng: np.random.Generator) -> None:
    """Half an insula (between y = v0 and v1) cut along its street into lots of ``widths``: kind ``wide``
    from ``at_least`` metres of frontage, else ``narrow``; numbered from the street's west end on the
    south side and from its east end on the north side, each lot's front on the street."""
    for k, (a, b) in enumerate(cut(INSULA, widths, rng)):
        props = {"kind": wide if b - a >= at_least else narrow}
        if side == "S":
            town.rect(f"{name}{k}", x0 + a, v0, x0 + b, v1, "S", **props)
        else:
            town.rect(f"{name}{k}", x0 + INSULA - b, v0, x0 + INSULA - a, v1, "N", **props)


def lots(seed: int = 2015) -> dict:
    """The town as a GeoJSON FeatureCollection; ``site`` (a foreign member) records how it was sited."""
    rng = np.random.default_rng(seed)
    t = terrain()
    site = choose_site(t)
    centre = (site["x"], site["y"])
    corners = pentagon(centre, site["water_towards"])
    wall = Polygon(corners)
    # building land: inside the wall's inner face and the ring road
    inner = wall.buffer(-(WALL_T / 2 + RING_ROAD), join_style="mitre")
    count = int(RADIUS // (INSULA + STREET)) + 2
    xs, ys = grid_lines(centre, count)
    town = Town()

    # insulae: whole (building land) or partial (gardens at the wall)
    whole, partial = [], {}
    for c in range(-count, count):
        for r in range(-count, count):
            square = box(xs[c], ys[r], xs[c] + INSULA, ys[r] + INSULA)
            if inner.contains(square):
                whole.append((c, r))
            elif inner.intersects(square):
                piece = inner.intersection(square)
                if piece.area > 0.12 * INSULA**2:
                    partial[c, r] = piece

    def insula_centre(s):
        return xs[s[0]] + INSULA / 2, ys[s[1]] + INSULA / 2

    dfc = {s: math.dist(insula_centre(s), centre) for s in whole}
    heights = {s: float(_heights(np.array(insula_centre(s)[0]), np.array(insula_centre(s)[1]))) for s in whole}

    def front_towards(s, target) -> str:
        """The side of insula ``s`` that faces ``target`` most."""
        dx, dy = target[0] - insula_centre(s)[0], target[1] - insula_centre(s)[1]
        return ("E" if dx > 0 else "W") if abs(dx) > abs(dy) else ("N" if dy > 0 else "S")

    # the public buildings (3.2.4): forum, its neighbours, theatre, amphitheatre, Capitolium
    special = {(0, 0): ("forum", {"kind": "forum"}, "S"),
               (1, 0): ("basilica", {"kind": "basilica"}, "W"),
               (0, 1): ("temple-mercury", temple_props(6, 24.0, "mercury"), "S"),
               (-1, 0): ("curia", {"kind": "governmental"}, "E"),
               (0, -1): ("tabularium", {"kind": "governmental"}, "N")}
    theatre = max((s for s in whole if s not in special), key=lambda s: (dfc[s], s))
    special[theatre] = ("theatre", {"kind": "theatre"}, front_towards(theatre, centre))
    beside = [s for s in ((theatre[0] + 1, theatre[1]), (theatre[0] - 1, theatre[1]), (theatre[0], theatre[1] + 1),
                          (theatre[0], theatre[1] - 1)) if s in dfc and s not in special]
    apollo = min(beside, key=lambda s: (dfc[s], s))
    special[apollo] = ("temple-apollo", temple_props(6, 22.0, "apollo"), front_towards(apollo, centre))
    amphi = max((s for s in whole if s not in special),
                key=lambda s: (min(dfc[s], math.dist(insula_centre(s), insula_centre(theatre))), s))
    special[amphi] = ("amphitheatre", {"kind": "amphitheatre"}, front_towards(amphi, centre))
    capitol = max((s for s in whole if s not in special), key=lambda s: (heights[s], s))
    special[capitol] = ("temple-capitolium", temple_props(8, 30.0, "jupiter", podium_h=3.0),
                        front_towards(capitol, centre))
    for s, (name, props, front) in special.items():
        if props["kind"] == "governmental":     # the local government: a governmental insula
            insula_lots(town, name, xs[s[0]], ys[s[1]], "governmental", rng, front)
        else:
            town.rect(name, xs[s[0]], ys[s[1]], xs[s[0]] + INSULA, ys[s[1]] + INSULA, front, **props)

    districts = assign_districts([s for s in whole if s not in special], dfc, rng)
    for s, kind in sorted(districts.items()):
        facing = "N" if centre[1] > insula_centre(s)[1] else "S"
        insula_lots(town, f"i{s[0]}_{s[1]}", xs[s[0]], ys[s[1]], kind, rng, facing)
    for s, piece in sorted(partial.items()):
        town.polygon(f"garden{s[0]}_{s[1]}", piece, kind="garden")

    # streets between the insulae, clipped to the building land plus the ring road, and their crossings
    street_land = wall.buffer(-WALL_T / 2, join_style="mitre")
    cells = set(whole) | set(partial)

    def v_street(c, r):
        return box(xs[c] + INSULA, ys[r], xs[c + 1], ys[r] + INSULA)      # east of insula (c, r)

    def h_street(c, r):
        return box(xs[c], ys[r] + INSULA, xs[c] + INSULA, ys[r + 1])      # north of insula (c, r)

    def crossing(c, r):
        return box(xs[c] + INSULA, ys[r] + INSULA, xs[c + 1], ys[r + 1])  # north-east of insula (c, r)

    pieces = {}
    for c, r in sorted(cells):
        for dc in (-1, 0):
            pieces[f"sv{c + dc}_{r}"] = v_street(c + dc, r)
            pieces[f"sh{c}_{r + dc}"] = h_street(c, r + dc)
            for dr in (-1, 0):
                pieces[f"x{c + dc}_{r + dr}"] = crossing(c + dc, r + dr)
    for name, piece in sorted(pieces.items()):
        clipped = street_land.intersection(piece)
        if clipped.area > 4.0 and clipped.geom_type == "Polygon":
            kind = "crossing" if name.startswith("x") else "street"
            if clipped.equals_exact(piece, 1e-9) or piece.equals(clipped):
                w, h = piece.bounds[2] - piece.bounds[0], piece.bounds[3] - piece.bounds[1]
                front = "S" if w >= h else "W"
                x0, y0, x1, y1 = piece.bounds
                town.rect(name, x0, y0, x1, y1, front, kind=kind)
            else:
                town.polygon(name, clipped, kind=kind)
    # the ring road: a trapezoid along each side between the wall's inner face and the building land,
    # from each corner of the one to the nearest corner of the other (they stand on the corner's bisector)
    outer_corners = list(street_land.exterior.coords)[:-1]
    inner_corners = list(inner.exterior.coords)[:-1]
    for k, corner in enumerate(outer_corners):
        after = outer_corners[(k + 1) % len(outer_corners)]
        near = [min(inner_corners, key=lambda p, q=q: math.dist(p, q)) for q in (corner, after)]
        town.polygon(f"ring{k}", Polygon([corner, after, near[1], near[0]]), kind="street")
    # the wall, with gates where the main streets leave the town
    cardo_x = xs[0] + INSULA + MAIN_STREET / 2
    decumanus_y = ys[0] - MAIN_STREET / 2
    far = 4 * RADIUS
    main_lines = [LineString([(cardo_x, centre[1] - far), (cardo_x, centre[1] + far)]),
                  LineString([(centre[0] - far, decumanus_y), (centre[0] + far, decumanus_y)])]
    gates = wall_lots(town, corners, main_lines)

    # temples outside the walls (Vitruvius I.7.1): Venus by the harbour gate, the others at the rest,
    # each beside the road from its gate, facing it
    harbour = np.array(site["water_towards"]) - np.array(centre)
    gates.sort(key=lambda g: -float(np.dot(g["normal"], harbour / np.linalg.norm(harbour))))
    for g, (deity, columns, width) in zip(gates, (("venus", 6, 18.0), ("ceres", 4, 15.0), ("vulcan", 4, 14.0),
                                                  ("mars", 6, 17.0))):
        depth, length = 2 * width + 14.0, width + 10.0
        at = g["at"] + g["normal"] * (WALL_T / 2 + TEMPLE_OUT + depth / 2) + g["along"] * (GATE / 2 + 6.0 + length / 2)
        # the first edge faces the wall: walking along -along, the right-hand side is towards the town
        town.oriented(f"temple-{deity}", at, -g["along"], length, depth,
                      **temple_props(columns, width, deity))
    return {"type": "FeatureCollection", "site": site, "features": town.features}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "lots.geojson")
    parser.add_argument("--seed", type=int, default=2015)
    args = parser.parse_args()
    town = lots(args.seed)
    args.out.write_text(json.dumps(town, separators=(",", ":")) + "\n")
    kinds: dict[str, int] = {}
    for f in town["features"]:
        kinds[f["properties"]["kind"]] = kinds.get(f["properties"]["kind"], 0) + 1
    print(f"{args.out}: {len(town['features'])} lots {dict(sorted(kinds.items()))}")
    print(f"site: {town['site']}")


if __name__ == "__main__":
    main()
