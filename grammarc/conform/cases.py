"""Cases of the differential harness: a footprint of a class, a rule package and attributes sampled for it.

A case is a pure function of (package, footprint class, seed): ``make_case`` regenerates the same lot and
attributes from them. Attributes are sampled where the rule file annotates their range, as a CityEngine user
moves the inspector's sliders: ``@Range(min=a, max=b[, stepsize=s])`` and the older ``@Range(a, b)`` draw
uniformly between the bounds (on the steps); ``@Range(v1, v2, v3...)`` and ``@Enum(...)`` pick a value.
Attributes without such an annotation keep their defaults: the author gave no values to try, and a
random default (``attr h = rand(10, 30)``) is part of the rule package's behaviour under test.

``write_lots`` writes cases as one GeoJSON FeatureCollection, each lot named by its case and carrying its
attributes as properties: the file PRT's side (``prt_batch``) and grammarc's build both read, and, for one
case alone, the case file that reproduces a mismatch (``prt_reference.py RPK CASE.geojson`` and
``grammarc build RPK --lots CASE.geojson``).
"""

from __future__ import annotations

import json
import math
import os
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from shapely.geometry import Polygon, mapping

from grammarc.conform.footprints import footprint
from grammarc.ir import nodes as ir

__all__ = ["Case", "cases_from_file", "make_case", "sample_attrs", "write_lots"]


@dataclass(frozen=True)
class Case:
    """One lot of the harness: its rule package, footprint class, seed, attributes and polygon."""

    package: str
    kind: str
    seed: int
    attrs: dict = field(hash=False)
    polygon: Polygon = field(hash=False)

    @property
    def name(self) -> str:
        return f"{self.package}.{self.kind}.{self.seed}"

    @property
    def prt_seed(self) -> int:
        """PRT's seed of the lot, from its name: PRT's streams of consecutive seeds are almost the same
        (its generator is a small linear congruential one), so the cases' seeds are spread over it."""
        return zlib.crc32(self.name.encode()) % 714025


def make_case(package: str, module: ir.Module, kind: str, seed: int) -> Case:
    """The case of ``package`` (its checked ``module``) on a footprint of class ``kind`` from ``seed``."""
    rng = np.random.default_rng([seed, zlib.crc32(package.encode())])
    return Case(package, kind, seed, sample_attrs(module, rng), footprint(kind, seed))


def cases_from_file(package: str, module: ir.Module, path: str | os.PathLike) -> list[Case]:
    """Cases of ``package`` on the footprints of a GeoJSON file (real lots, in metres): one case per
    polygon, of the class named by the file's stem, numbered (its seed) in the file's order; attributes
    sampled as for generated footprints. A MultiPolygon gives a case per part."""
    from shapely.geometry import shape

    kind = Path(path).stem
    with open(path, encoding="utf-8") as file:
        features = json.load(file)["features"]
    polygons = [part for f in features for part in getattr(shape(f["geometry"]), "geoms", [shape(f["geometry"])])]
    return [Case(package, kind, i, sample_attrs(module, np.random.default_rng([i, zlib.crc32(package.encode())])),
                 polygon) for i, polygon in enumerate(polygons)]


def sample_attrs(module: ir.Module, rng: np.random.Generator) -> dict:
    """Values of the attributes of ``module`` whose annotations give a range or choices (see the module).

    Numbers are rounded to 1 mm (1e-3), so that a case file reads plainly and both engines get the same
    double. Style attributes (``Style$name``) and constants are left alone.
    """
    values = {}
    for attr in module.attrs:
        if attr.const or "$" in attr.name:
            continue
        annotations = dict(attr.annotations)
        args = annotations.get("Range", annotations.get("Enum"))
        if not args:
            continue
        keywords = dict(a.split("=", 1) for a in args if "=" in a)
        choices = [_value(a) for a in args if "=" not in a]
        if "min" in keywords and "max" in keywords:
            low, high, step = float(keywords["min"]), float(keywords["max"]), float(keywords.get("stepsize", 0))
            value = rng.uniform(low, high)
            values[attr.name] = round(low + round((value - low) / step) * step if step > 0 else value, 3)
        elif "Range" in annotations and len(choices) == 2 and all(_is_number(c) for c in choices):
            values[attr.name] = round(rng.uniform(*sorted(choices)), 3)
        elif choices:
            values[attr.name] = choices[int(rng.integers(len(choices)))]
    return values


def _value(text: str):
    """An annotation's argument as a value: a quoted string, true/false, or a number."""
    text = text.strip()
    if len(text) >= 2 and text[0] == text[-1] == '"':
        return text[1:-1]
    if text in ("true", "false"):
        return text == "true"
    return float(text)


def _is_number(value) -> bool:
    return isinstance(value, float) and math.isfinite(value)


def write_lots(path: str | os.PathLike, cases: list[Case], spacing: float = 0.0) -> None:
    """Write ``cases`` as a GeoJSON FeatureCollection, case ``i`` moved by ``spacing`` times its cell of a
    square grid (``spacing`` 0: where it is), so that no lot's geometry reaches another's."""
    columns = max(1, math.ceil(math.sqrt(len(cases))))
    features = []
    for i, case in enumerate(cases):
        dx, dy = (i % columns) * spacing, (i // columns) * spacing
        geometry = mapping(Polygon(np.asarray(case.polygon.exterior.coords) + (dx, dy),
                                   [np.asarray(h.coords) + (dx, dy) for h in case.polygon.interiors]))
        features.append({"type": "Feature", "properties": {"name": case.name, **case.attrs, "seed": case.prt_seed},
                         "geometry": {"type": "Polygon", "coordinates": [[list(p) for p in ring]
                                                                         for ring in geometry["coordinates"]]}})
    with open(path, "w", encoding="utf-8") as file:
        json.dump({"type": "FeatureCollection", "features": features}, file)
