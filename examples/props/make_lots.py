"""Make props.geojson: the lots of the props example, deterministically.

Two wind parks (large fields with their turbine height), three parks with trees at a spacing, and a row
of yards fenced along their edges; each lot carries its control parameters as GeoJSON properties.

    python make_lots.py [--out props.geojson]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def rectangle(x: float, y: float, w: float, d: float) -> list:
    return [[[x, y], [x + w, y], [x + w, y + d], [x, y + d], [x, y]]]


def lots() -> list[dict]:
    features = []

    def lot(name, ring, **properties):
        features.append({"type": "Feature", "id": name, "properties": properties,
                         "geometry": {"type": "Polygon", "coordinates": ring}})

    lot("wind-a", rectangle(0, 0, 140, 70), use="wind", turbineHeight=60)
    lot("wind-b", rectangle(150, 0, 140, 70), use="wind", turbineHeight=80)
    for k, spacing in enumerate((8, 10, 12)):
        lot(f"park-{k}", rectangle(k * 50, 80, 44, 36), use="park", treeSpacing=spacing)
    for k in range(6):
        lot(f"yard-{k}", rectangle(150 + k * 24, 80, 22, 28), use="yard", fenceHeight=1.0 + 0.1 * k)
    return features


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "props.geojson")
    args = parser.parse_args()
    args.out.write_text(json.dumps({"type": "FeatureCollection", "features": lots()}) + "\n")


if __name__ == "__main__":
    main()
