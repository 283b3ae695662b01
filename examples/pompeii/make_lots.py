"""Make lots.geojson: the footprints of a Roman town in the manner of Pompeii, deterministically.

The paper derived Pompeii from "real building footprints" (section 7.2). We have no such survey to ship,
so this script draws a town of the same make from what is known of Pompeii's plan: a grid of streets
(cardines north-south, decumani east-west, 6-8 m wide, with raised sidewalks and stepping stones),
insulae of unequal rectangles of roughly 40 x 70 to 60 x 100 m, each cut into deep narrow house lots back
to back along its long sides and rows of shops at its short ends; the forum in the centre-west with the
Capitolium at its north end, the basilica, the Temple of Apollo, the macellum and the municipal halls
round it; baths near the forum and at a main crossing, a few temples in the insulae, gardens and
vineyards in the east, and the town wall with towers and gates all round.

Every lot is a rectangle whose first edge is its front (the street, or the forum for the buildings that
face it): grammarc puts the front at the scope's +z, so a grammar can speak of front and back. Each lot
carries the control attributes its rules read (``kind``, ``storeys``, ``wealth``, ``order``,
``columns``, ``trade``), and with ``--street-width`` CityEngine's ``streetWidth`` (one number per edge,
> 0 where a street runs).

    python make_lots.py [--scale N] [--out lots.geojson] [--seed 7] [--street-width]

``--scale N`` tiles the town N times on a square grid (lot ids prefixed ``t<k>-``), the input of the
speed benchmark (``--scale 100``: 250,500 lots). The same arguments always write the same bytes.
"""

from __future__ import annotations

import argparse
import json
import math
from itertools import pairwise
from pathlib import Path

import numpy as np

#: Insula columns (west to east) and rows (south to north) of the grid.
COLUMNS, ROWS = 12, 7
#: The forum complex takes these 2 x 2 cells (west of centre, as in Pompeii) and the streets between.
FORUM_CELLS = (3, 2)
#: Street widths: the main cardo and decumanus (Via Stabiana, Via dell'Abbondanza) are wider.
STREET, MAIN_STREET = 6.5, 8.5
#: Thickness of the town wall and size of its towers.
WALL, TOWER = 5.0, 10.0


class Town:
    """Collects lots as GeoJSON features; the lot helpers below add them."""

    def __init__(self, rng: np.random.Generator, east_line: float) -> None:
        self.rng = rng
        self.east_line = east_line      # insulae east of it are in the garden quarter
        self.features: list[dict] = []

    def lot(self, lot_id: str, x0: float, y0: float, x1: float, y1: float, front: str, streets: dict,
            **props) -> None:
        """A rectangular lot whose first edge is side ``front`` ("S", "E", "N", "W"); ``streets`` maps
        the sides that face a street to its width. The ring is counter-clockwise, as RFC 7946 asks."""
        corners = {"S": [(x0, y0), (x1, y0), (x1, y1), (x0, y1)],
                   "E": [(x1, y0), (x1, y1), (x0, y1), (x0, y0)],
                   "N": [(x1, y1), (x0, y1), (x0, y0), (x1, y0)],
                   "W": [(x0, y1), (x0, y0), (x1, y0), (x1, y1)]}[front]
        sides = "SENW"
        order = [sides[(sides.index(front) + k) % 4] for k in range(4)]
        ring = [[round(x, 2), round(y, 2)] for x, y in corners]
        props = {"kind": props.pop("kind"), **props,
                 "streetWidth": [float(streets.get(side, 0.0)) for side in order]}
        self.features.append({"type": "Feature", "id": lot_id, "properties": props,
                              "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]}})

    # ------------------------------------------------------------------------------------- buildings

    def house_props(self, kind: str, east: bool) -> dict:
        """Control attributes of a house or shop lot: height in storeys, wealth (how grand the domus
        is: peristyle, order of its columns) and the trade of a shop."""
        rng = self.rng
        wealth = float(rng.beta(2.0, 3.0))
        props = {"kind": kind, "storeys": float(rng.choice([1, 2], p=[0.55, 0.45])),
                 "wealth": round(wealth, 3)}
        if kind == "domus":
            # richer houses, richer orders: Tuscan brick columns for most, Ionic or Corinthian for few
            props["order"] = str(rng.choice(["tuscan", "doric", "ionic", "corinthian"],
                                            p=[0.45, 0.25, 0.2, 0.1] if wealth < 0.5 else [0.1, 0.3, 0.35, 0.25]))
        if kind == "taberna":
            props["trade"] = str(rng.choice(["shop", "thermopolium", "bakery", "fullonica"],
                                            p=[0.5, 0.25, 0.15, 0.1]))
        if kind == "garden" and east:
            props["trade"] = "vineyard"
        return props

    def frontage_row(self, length: float, depth: float, place, east: bool) -> None:
        """Cut a strip ``length`` long along its street into lots of varied frontage: shops 4-7 m, small
        houses 7-10 m, atrium houses 10-18 m, a garden now and then (more in the east, as in Regio I-II);
        a shallow strip (an insula's short end) has shops and small houses only.
        ``place(a, b, props, k)`` adds lot ``k`` between distances a and b along the strip."""
        rng = self.rng
        kinds = ["taberna", "casa", "domus", "garden"]
        if depth < 14:
            p = [0.6, 0.4, 0.0, 0.0]
        else:
            p = [0.3, 0.18, 0.37, 0.15] if east else [0.34, 0.2, 0.42, 0.04]
        widths = {"taberna": (4.0, 7.0), "casa": (7.0, 10.0), "domus": (10.0, 18.0), "garden": (16.0, 28.0)}
        a, k = 0.0, 0
        while length - a > 0.5:
            kind = str(rng.choice(kinds, p=p))
            w = float(rng.uniform(*widths[kind]))
            if length - a - w < 4.0:      # the last lot takes the rest rather than leave a sliver
                w = length - a
            place(a, a + w, self.house_props(kind, east), k)
            a, k = a + w, k + 1

    def insula(self, name: str, x0: float, y0: float, x1: float, y1: float, streets: dict,
               special: str | None) -> None:
        """One insula, long side north-south: rows of shops and small houses along the short ends, deep
        lots back to back along the long sides (their backs meet on the insula's spine, off centre), or a
        whole-width building (a temple, baths, a great house) taking one end."""
        rng = self.rng
        width = x1 - x0
        east = (x0 + x1) / 2 > self.east_line
        end_s, end_n = float(rng.uniform(8, 12)), float(rng.uniform(8, 12))
        if special in ("temple", "baths", "bigdomus"):
            # a whole-width lot at the south end, facing the decumanus
            depth = {"temple": float(rng.uniform(38, 48)), "baths": float(rng.uniform(52, 62)),
                     "bigdomus": float(rng.uniform(40, 60))}[special]
            props = {"kind": special}
            if special == "temple":
                props = {"kind": "temple", "order": str(rng.choice(["doric", "ionic", "corinthian"])),
                         "columns": float(rng.choice([4, 6]))}
            if special == "bigdomus":
                props = {"kind": "domus", "storeys": 2.0, "wealth": 1.0, "order": "corinthian"}
            self.lot(f"{name}-{special}", x0, y0, x1, y0 + depth, "S",
                     {"S": streets["S"], "E": streets["E"], "W": streets["W"]}, **props)
            y0_core = y0 + depth
        else:
            y0_core = y0 + end_s
            self._end_row(f"{name}-s", x0, y0, x1, y0 + end_s, "S", streets, east)
        self._end_row(f"{name}-n", x0, y1 - end_n, x1, y1, "N", streets, east)
        core0, core1 = y0_core, y1 - end_n
        if core1 - core0 < 8:
            return
        spine = x0 + width * float(rng.uniform(0.42, 0.58))

        def west_lot(a, b, props, k):
            self.lot(f"{name}-w{k}", x0, core1 - b, spine, core1 - a, "W", {"W": streets["W"]}, **props)

        def east_lot(a, b, props, k):
            self.lot(f"{name}-e{k}", spine, core0 + a, x1, core0 + b, "E", {"E": streets["E"]}, **props)

        self.frontage_row(core1 - core0, spine - x0, west_lot, east)
        self.frontage_row(core1 - core0, x1 - spine, east_lot, east)

    def _end_row(self, name: str, x0: float, y0: float, x1: float, y1: float, side: str, streets: dict,
                 east: bool) -> None:
        """The short end of an insula: shops and small houses facing the decumanus (corner lots face
        the cardo too, which their streetWidth records)."""
        def place(a, b, props, k):
            if side == "S":
                near = {"S": streets["S"], **({"W": streets["W"]} if a == 0 else {}),
                        **({"E": streets["E"]} if b >= x1 - x0 - 1e-9 else {})}
                self.lot(f"{name}{k}", x0 + a, y0, x0 + b, y1, "S", near, **props)
            else:
                near = {"N": streets["N"], **({"E": streets["E"]} if a == 0 else {}),
                        **({"W": streets["W"]} if b >= x1 - x0 - 1e-9 else {})}
                self.lot(f"{name}{k}", x1 - b, y0, x1 - a, y1, "N", near, **props)

        self.frontage_row(x1 - x0, y1 - y0, place, east)

    def forum_complex(self, x0: float, y0: float, x1: float, y1: float, streets: dict) -> None:
        """The forum quarter (Pompeii's Regio VII 8-9 simplified): the paved forum with two-storey
        colonnades, the Capitolium closing its north end, the basilica and the Temple of Apollo to the
        west, the macellum, two temples and the Building of Eumachia to the east, three municipal
        halls to the south, the Forum Baths in the north-west; lots facing the forum have it as front."""
        rng = self.rng
        w = x1 - x0
        a, b = x0 + 0.36 * w, x0 + 0.72 * w              # the forum between x = a and b
        fs, fn = y0 + 24.0, y1 - 44.0                    # and between y = fs and fn
        self.lot("forum", a, fs, b, fn, "S", {}, kind="forum")
        self.lot("capitolium", a + 8, fn, b - 8, y1 - 2, "S", {}, kind="temple", order="corinthian",
                 columns=6.0)
        for k, (u0, u1) in enumerate(((a, a + 8), (b - 8, b))):     # shops beside the Capitolium
            self.lot(f"forum-n{k}", u0, fn, u1, y1, "N", {"N": streets["N"]}, kind="taberna",
                     storeys=1.0, wealth=0.5, trade="shop")
        third = (b - a) / 3
        for k in range(3):
            self.lot(f"forum-hall{k}", a + k * third, y0, a + (k + 1) * third, fs - 2, "N",
                     {"S": streets["S"]}, kind="basilica", order="ionic")
        # west: the basilica (its short side on the forum), the Temple of Apollo in its porticus behind
        # a row of shops on the cardo, houses, the Forum Baths
        self.lot("basilica", x0, y0, a - 2, y0 + 28, "E", {"W": streets["W"], "S": streets["S"]},
                 kind="basilica", order="ionic")
        self.lot("apollo", x0 + 10, y0 + 32, a - 2, y0 + 82, "E", {}, kind="temple", order="ionic",
                 columns=6.0)
        for k, (v0, v1) in enumerate(_cuts(y0 + 32, y0 + 82, 4.5, 7.0, rng)):
            self.lot(f"forum-ws{k}", x0, v0, x0 + 10, v1, "W", {"W": streets["W"]},
                     **self.house_props("taberna", False))
        for k, (v0, v1) in enumerate(_cuts(y0 + 84, y1 - 60, 9.0, 16.0, rng)):
            self.lot(f"forum-w{k}", x0, v0, a - 2, v1, "W", {"W": streets["W"]},
                     **self.house_props("domus" if v1 - v0 > 11 else "casa", False))
        self.lot("forum-baths", x0, y1 - 58, a - 2, y1, "N", {"N": streets["N"], "W": streets["W"]},
                 kind="baths")
        # east: the macellum on the corner, temples of the Lares and of Vespasian, Eumachia's building,
        # shops along the cardo behind them and at the south corner
        self.lot("macellum", b, y1 - 46, x1, y1, "W", {"N": streets["N"], "E": streets["E"]}, kind="macellum")
        self.lot("lares", b + 2, y1 - 80, x1 - 9, y1 - 48, "W", {}, kind="temple", order="corinthian",
                 columns=4.0)
        self.lot("vespasian", b + 2, y1 - 110, x1 - 9, y1 - 82, "W", {}, kind="temple", order="corinthian",
                 columns=4.0)
        self.lot("eumachia", b + 2, fs, x1 - 9, y1 - 112, "W", {}, kind="basilica", order="corinthian")
        for k, (v0, v1) in enumerate(_cuts(fs, y1 - 48, 4.5, 7.0, rng)):
            self.lot(f"forum-es{k}", x1 - 9, v0, x1, v1, "E", {"E": streets["E"]},
                     **self.house_props("taberna", False))
        self.lot("forum-se", b, y0, x1, fs - 2, "E", {"E": streets["E"], "S": streets["S"]},
                 kind="taberna", storeys=2.0, wealth=0.6, trade="shop")

    # ---------------------------------------------------------------------------- streets and walls

    def street(self, name: str, x0: float, y0: float, x1: float, y1: float) -> None:
        """A street segment between two crossings, its first edge along its length."""
        front = "S" if x1 - x0 > y1 - y0 else "W"
        self.lot(name, x0, y0, x1, y1, front, {}, kind="street")

    def wall(self, x0: float, y0: float, x1: float, y1: float, gates_x: list, gates_y: list) -> None:
        """The town wall outside the ring street, in curtains of about 36 m, a tower on every fourth
        joint and on both sides of each gate (a 12 m gap where a main street leaves the town); the wall
        faces out (its front is the outside, where an enemy would stand)."""
        t = WALL
        runs = [("S", x0 - t, x1 + t, y0 - t, gates_x), ("N", x0 - t, x1 + t, y1, gates_x),
                ("W", y0, y1, x0 - t, gates_y), ("E", y0, y1, x1, gates_y)]
        k = 0
        for side, u0, u1, v, gates in runs:
            cuts = [u0]
            for g in gates:
                cuts += [g - 6.0, g + 6.0]
            cuts.append(u1)
            for s0, s1 in zip(cuts[::2], cuts[1::2]):
                n = max(1, round((s1 - s0) / 36.0))
                joints = [s0 + (s1 - s0) * i / n for i in range(n + 1)]
                for c0, c1 in pairwise(joints):
                    self.lot(f"wall-{side}{k}", *_across(side, c0, c1, v, v + t), side, {}, kind="wall")
                    k += 1
                for i, c in enumerate(joints):
                    at_gate = (i == 0 and s0 != u0) or (i == n and s1 != u1)
                    if at_gate or (0 < i < n and i % 4 == 2):
                        out0, out1 = (v + t - TOWER, v + t) if side in "SW" else (v, v + TOWER)
                        self.lot(f"tower-{side}{k}", *_across(side, c - TOWER / 2, c + TOWER / 2, out0, out1),
                                 side, {}, kind="tower")
                        k += 1


def _across(side: str, u0: float, u1: float, v0: float, v1: float) -> tuple[float, float, float, float]:
    """The box (x0, y0, x1, y1) of a piece of wall: u along the wall, v across it."""
    return (u0, v0, u1, v1) if side in "SN" else (v0, u0, v1, u1)


def _cuts(a: float, b: float, lo: float, hi: float, rng) -> list[tuple[float, float]]:
    """Cut [a, b] into pieces of lo..hi, the last taking the rest."""
    out, u = [], a
    while b - u > 1.0:
        w = float(rng.uniform(lo, hi))
        if b - u - w < lo * 0.6:
            w = b - u
        out.append((u, u + w))
        u += w
    return out


def town(seed: int = 7) -> list[dict]:
    """The lots of one town as GeoJSON features, its south-west corner (outside the wall) near (0, 0)."""
    rng = np.random.default_rng(seed)
    widths = rng.uniform(38.0, 58.0, COLUMNS)
    lengths = rng.uniform(70.0, 100.0, ROWS)
    main_col, main_row = COLUMNS // 2 + 1, ROWS // 2
    # street k runs before insula k (k = 0 is the ring street on the west / south, COLUMNS the east / north)
    col_street = [MAIN_STREET if k == main_col else STREET for k in range(COLUMNS + 1)]
    row_street = [MAIN_STREET if k == main_row else STREET for k in range(ROWS + 1)]
    xs = np.concatenate([[0.0], np.cumsum([col_street[k] + widths[k] for k in range(COLUMNS)])])
    ys = np.concatenate([[0.0], np.cumsum([row_street[k] + lengths[k] for k in range(ROWS)])])
    x_lo = [xs[k] + col_street[k] for k in range(COLUMNS)]
    y_lo = [ys[k] + row_street[k] for k in range(ROWS)]
    x_end, y_end = xs[-1] + col_street[-1], ys[-1] + row_street[-1]
    t = Town(rng, east_line=0.7 * x_end)

    fc, fr = FORUM_CELLS
    forum = {(fc, fr), (fc + 1, fr), (fc, fr + 1), (fc + 1, fr + 1)}
    # Each insula's edges stand back from the grid by up to 0.9 m, so streets vary in width and the
    # blocks are not all aligned, as the surveyed plan of Pompeii is not (the forum quarter stays put).
    inset = {(c, r): (0.0, 0.0, 0.0, 0.0) if (c, r) in forum else tuple(np.round(rng.uniform(0, 0.9, 4), 2))
             for c in range(COLUMNS) for r in range(ROWS)}

    def edges(c: int, r: int) -> tuple[float, float, float, float]:
        w, e, s, n = inset[c, r]
        return x_lo[c] + w, y_lo[r] + s, x_lo[c] + widths[c] - e, y_lo[r] + lengths[r] - n

    # whole-width buildings at the south end of a few insulae: the Stabian baths at the main crossing,
    # temples (Isis, Venus, Fortuna, the Doric temple), and great houses like the House of the Faun
    specials = {(main_col, main_row): "baths", (1, 1): "temple", (6, 1): "temple", (fc - 1, fr + 2): "temple",
                (9, 4): "temple", (2, 4): "bigdomus", (fc + 2, fr + 3): "bigdomus", (8, 2): "bigdomus",
                (10, 5): "temple"}
    for c in range(COLUMNS):
        for r in range(ROWS):
            if (c, r) in forum:
                continue
            streets = {"W": col_street[c], "E": col_street[c + 1], "S": row_street[r], "N": row_street[r + 1]}
            t.insula(f"i{c}-{r}", *edges(c, r), streets, specials.get((c, r)))
    t.forum_complex(x_lo[fc], y_lo[fr], x_lo[fc + 1] + widths[fc + 1], y_lo[fr + 1] + lengths[fr + 1],
                    {"W": col_street[fc], "E": col_street[fc + 2], "S": row_street[fr], "N": row_street[fr + 2]})
    # streets: segments between crossings, from block edge to block edge (none inside the forum
    # quarter), and the crossings themselves
    for c in range(COLUMNS + 1):
        for r in range(ROWS):
            if c == fc + 1 and r in (fr, fr + 1):
                continue
            x0 = edges(c - 1, r)[2] if c > 0 else 0.0
            x1 = edges(c, r)[0] if c < COLUMNS else x_end
            t.street(f"sv{c}-{r}", x0, y_lo[r], x1, y_lo[r] + lengths[r])
    for r in range(ROWS + 1):
        for c in range(COLUMNS):
            if r == fr + 1 and c in (fc, fc + 1):
                continue
            y0 = edges(c, r - 1)[3] if r > 0 else 0.0
            y1 = edges(c, r)[1] if r < ROWS else y_end
            t.street(f"sh{r}-{c}", x_lo[c], y0, x_lo[c] + widths[c], y1)
    for c in range(COLUMNS + 1):
        for r in range(ROWS + 1):
            if (c, r) == (fc + 1, fr + 1):
                continue
            t.lot(f"x{c}-{r}", xs[c], ys[r], xs[c] + col_street[c], ys[r] + row_street[r], "S", {},
                  kind="crossing")
    t.wall(0.0, 0.0, x_end, y_end, [xs[main_col] + col_street[main_col] / 2],
           [ys[main_row] + row_street[main_row] / 2])
    return t.features


def lots(scale: int = 1, seed: int = 7, street_width: bool = False) -> dict:
    """The FeatureCollection of ``scale`` copies of the town on a square grid, 100 m apart.

    Every copy is the same town (the same seed), translated, its ids prefixed ``t<k>-``: a benchmark
    wants equal work per tile, and translating is 30 times faster than drawing each town again.
    ``streetWidth`` is left out unless asked for: the paper-notation grammar cannot read it (only
    CityEngine's street selectors and ``Shape.visible`` do), and grammarc spends about 10 us a lot on it.
    """
    template = town(seed)
    if not street_width:
        for feature in template:
            del feature["properties"]["streetWidth"]
    if scale == 1:
        return {"type": "FeatureCollection", "features": template}
    rings = np.array([f["geometry"]["coordinates"][0] for f in template])   # (lots, 5, 2): all rectangles
    w, h = np.ptp(rings.reshape(-1, 2), axis=0)
    side = math.ceil(math.sqrt(scale))
    features = []
    for k in range(scale):
        shifted = np.round(rings + [(k % side) * (w + 100.0), (k // side) * (h + 100.0)], 2).tolist()
        for f, ring in zip(template, shifted):
            features.append({"type": "Feature", "id": f"t{k}-{f['id']}", "properties": f["properties"],
                             "geometry": {"type": "Polygon", "coordinates": [ring]}})
    return {"type": "FeatureCollection", "features": features}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scale", type=int, default=1, help="tile the town N times (default 1)")
    parser.add_argument("--seed", type=int, default=7, help="the town's layout seed (default 7)")
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "lots.geojson")
    parser.add_argument("--street-width", action="store_true",
                        help="write CityEngine's streetWidth per lot (for street.* selectors; off: it costs "
                             "reading time and the paper notation cannot use it)")
    args = parser.parse_args()
    collection = lots(args.scale, args.seed, args.street_width)
    # json.dumps, not json.dump: dump streams through the pure-Python encoder, ten times slower
    args.out.write_text(json.dumps(collection, separators=(",", ":")) + "\n")
    kinds: dict[str, int] = {}
    for feature in collection["features"]:
        kinds[feature["properties"]["kind"]] = kinds.get(feature["properties"]["kind"], 0) + 1
    print(f"{args.out}: {len(collection['features'])} lots; "
          + ", ".join(f"{k} {n}" for k, n in sorted(kinds.items())))


if __name__ == "__main__":
    main()
