"""Make city.geojson: the lots of the example city, deterministically.

Blocks of 4 x 3 lots on a street grid; most lots are rectangles ("block": stochastic mass models), some
are L-shaped or have a courtyard ("plain": extruded footprints). Each lot carries its control
parameters as GeoJSON properties: height, floor_h and kind, as the Puuc paper reads them from GIS.

    python make_lots.py [--blocks N] [--out city.geojson]
"""

from __future__ import annotations

import argparse
import json

import numpy as np


def lots(blocks: int, seed: int = 1):
    rng = np.random.default_rng(seed)
    features = []
    lot_w, lot_d, street = 24.0, 30.0, 14.0
    side = int(np.ceil(np.sqrt(blocks)))
    for b in range(blocks):
        bx, by = (b % side) * (4 * lot_w + street), (b // side) * (3 * lot_d + street)
        for i in range(4):
            for j in range(3):
                x, y = bx + i * lot_w, by + j * lot_d
                w, d = lot_w - 2.0, lot_d - 2.0
                shape = rng.choice(["rect", "rect", "rect", "L", "courtyard"])
                outer = [[x, y], [x + w, y], [x + w, y + d], [x, y + d]]
                rings = [outer]
                kind = "block"
                if shape == "L":
                    cut_w, cut_d = w * rng.uniform(0.3, 0.6), d * rng.uniform(0.3, 0.6)
                    rings = [[[x, y], [x + w, y], [x + w, y + d - cut_d], [x + w - cut_w, y + d - cut_d],
                              [x + w - cut_w, y + d], [x, y + d]]]
                    kind = "plain"
                elif shape == "courtyard":
                    m = 6.0
                    rings.append([[x + m, y + m], [x + m, y + d - m], [x + w - m, y + d - m],
                                  [x + w - m, y + m]])
                    kind = "plain"
                features.append({
                    "type": "Feature",
                    "id": f"b{b}-{i}{j}",
                    "properties": {
                        "height": round(float(rng.choice([9.6, 12.8, 16.0, 22.4, 28.8])), 1),
                        "floor_h": round(float(rng.uniform(3.0, 3.6)), 2),
                        "kind": kind,
                    },
                    "geometry": {"type": "Polygon",
                                 "coordinates": [r + [r[0]] for r in rings]},
                })
    return {"type": "FeatureCollection", "features": features}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--blocks", type=int, default=36)
    parser.add_argument("--out", default="city.geojson")
    args = parser.parse_args()
    with open(args.out, "w") as f:
        json.dump(lots(args.blocks), f, indent=None)
        f.write("\n")


if __name__ == "__main__":
    main()
