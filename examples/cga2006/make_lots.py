"""Make the lots of the four grammars of examples/cga2006, deterministically.

Each grammar ``X.cga`` takes ``X.geojson`` beside it (``grammarc build`` finds it by name):

- ``simple_building.geojson``: a block of 12 touching lots (section 4, Fig. 13), two rows of 6 back
  to back, each row facing its street, 11-16 m frontage, 14 m deep, each lot with its own
  ``building_height`` (6, 9 or 12 m), so that a higher building's side wall is partly hidden by its
  lower neighbour and partly free. The four end lots are corner lots on the side streets.
- ``office.geojson``: 6 office lots of 30-44 x 26-36 m along a street (section 5, Fig. 14, 15).
- ``suburb.geojson``: 8 single-family lots of 18-24 x 34 m along a street (section 6, Fig. 16), each
  with its own front yard depth ``front_yard`` (3-9 m) and garage side ``garage_left``.
- ``petronas.geojson``: one 60 x 60 m square lot (Fig. 6).

Every lot is a rectangle whose first edge is its (main) street front (grammarc puts it at the scope's +z) and
carries CityEngine's ``streetWidth`` (one number per edge, > 0 where a street runs).

    python make_lots.py [--out FOLDER]

The same arguments always write the same bytes.
"""

from __future__ import annotations

import argparse
import json
from itertools import pairwise
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
#: Street width in front of every lot.
STREET = 10.0


def _lot(lot_id: str, x0: float, y0: float, x1: float, y1: float, streets: dict, front: str = "S",
         **props) -> dict:
    """A rectangle whose first edge is its side ``front`` ("S" or "N"), counter-clockwise as RFC 7946
    asks; ``streets`` maps the sides ("S", "E", "N", "W") that face a street to its width."""
    corners = {"S": ((x0, y0), (x1, y0), (x1, y1), (x0, y1)), "N": ((x1, y1), (x0, y1), (x0, y0), (x1, y0))}
    order = {"S": "SENW", "N": "NWSE"}[front]
    ring = [[round(x, 2), round(y, 2)] for x, y in corners[front]]
    props = {**props, "streetWidth": [float(streets.get(side, 0.0)) for side in order]}
    return {"type": "Feature", "id": lot_id, "properties": props,
            "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]}}


def _row(widths) -> list[tuple[float, float]]:
    """Touching intervals of the given widths from x = 0."""
    edges = np.concatenate([[0.0], np.cumsum(widths)])
    return [(float(a), float(b)) for a, b in pairwise(edges)]


def simple_building(rng: np.random.Generator) -> list[dict]:
    """Two rows of 6 touching lots back to back, 80 m long, the south row facing the south street and
    the north row the north one; the end lots are corner lots on the side streets."""
    features = []
    for row, (front, y0, y1) in enumerate((("S", 0.0, 14.0), ("N", 14.0, 28.0))):
        widths = rng.uniform(14.0, 20.0, 6)
        widths = np.round(widths * 80.0 / widths.sum(), 1)
        widths[-1] = round(80.0 - widths[:-1].sum(), 1)
        for k, (x0, x1) in enumerate(_row(widths)):
            streets = {front: STREET, **({"W": STREET} if k == 0 else {}), **({"E": STREET} if k == 5 else {})}
            features.append(_lot(f"house{row}{k}", x0, y0, x1, y1, streets, front,
                                 building_height=float(rng.choice([6.0, 9.0, 12.0]))))
    return features


def office(rng: np.random.Generator) -> list[dict]:
    widths = np.round(rng.uniform(30.0, 44.0, 6), 1)
    features = []
    for k, (x0, x1) in enumerate(_row(widths + 8.0)):      # 8 m between the lots
        depth = round(float(rng.uniform(26.0, 36.0)), 1)
        features.append(_lot(f"office{k}", x0, 0.0, x1 - 8.0, depth, {"S": STREET},
                             building_height=float(rng.choice([24.0, 30.0, 36.0]))))
    return features


def suburb(rng: np.random.Generator) -> list[dict]:
    widths = np.round(rng.uniform(18.0, 24.0, 8), 1)
    return [_lot(f"home{k}", x0, 0.0, x1, 34.0, {"S": STREET},
                 front_yard=round(float(rng.uniform(3.0, 9.0)), 1), garage_left=float(rng.random() < 0.5))
            for k, (x0, x1) in enumerate(_row(widths))]


def petronas(rng: np.random.Generator) -> list[dict]:
    return [_lot("tower1", 0.0, 0.0, 60.0, 60.0, {"S": STREET})]


def collections(seed: int = 2006) -> dict[str, dict]:
    """The FeatureCollection of each grammar, by file name."""
    rng = np.random.default_rng(seed)
    return {f"{make.__name__}.geojson": {"type": "FeatureCollection", "features": make(rng)}
            for make in (simple_building, office, suburb, petronas)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=HERE, help="the folder to write to (default: here)")
    args = parser.parse_args()
    for name, collection in collections().items():
        (args.out / name).write_text(json.dumps(collection, separators=(",", ":")) + "\n")
        print(f"{args.out / name}: {len(collection['features'])} lots")


if __name__ == "__main__":
    main()
