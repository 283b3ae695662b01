"""What the examples' ``make_assets.py`` scripts share: a polygon mesh builder and the OBJ files it writes.

Each example makes its terminal objects in code, deterministically, so that the committed OBJ files can be
checked against their script. An asset is written in the unit box [0, 1]^3 (grammarc fits an asset's
bounding box to the scope it is inserted in: the grammar gives the size, the asset the form) with 4
decimals, so the same script always writes the same bytes. A script imports this module with its
folder's parent on ``sys.path`` (examples are not a package).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from itertools import pairwise
from pathlib import Path

import numpy as np


class Mesh:
    """Polygons (counter-clockwise seen from outside) over a growing vertex list."""

    def __init__(self) -> None:
        self.vertices: list[tuple[float, float, float]] = []
        self.faces: list[list[int]] = []

    def add(self, points, faces) -> Mesh:
        base = len(self.vertices)
        self.vertices.extend(tuple(map(float, p)) for p in points)
        self.faces.extend([base + i for i in face] for face in faces)
        return self

    def merge(self, other: Mesh) -> Mesh:
        return self.add(other.vertices, other.faces)

    def triangles(self) -> int:
        return sum(len(f) - 2 for f in self.faces)

    def obj(self, title: str, note: str) -> str:
        """The OBJ text, fitted to the unit box; ``note`` is its second comment line."""
        v = np.array(self.vertices)
        lo, hi = v.min(axis=0), v.max(axis=0)
        v = (v - lo) / np.where(hi - lo > 1e-12, hi - lo, 1.0)
        lines = [f"# {title}", f"# {note}"]
        lines += [f"v {x:.4f} {y:.4f} {z:.4f}".replace("-0.0000", "0.0000") for x, y, z in v]
        lines += ["f " + " ".join(str(i + 1) for i in face) for face in self.faces]
        return "\n".join(lines) + "\n"


def combine(*meshes: Mesh) -> Mesh:
    out = Mesh()
    for mesh in meshes:
        out.merge(mesh)
    return out


def box(x0, y0, z0, x1, y1, z1) -> Mesh:
    """An axis-aligned box (the corner order of grammarc's built-in cube), its faces wound outwards."""
    points = [(x1 if i & 1 else x0, y1 if i >> 1 & 1 else y0, z1 if i >> 2 & 1 else z0) for i in range(8)]
    quads = [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]]
    return Mesh().add(points, quads)


def obj_files(assets: dict[str, Callable[[], Mesh]], note: str) -> dict[str, tuple[str, int]]:
    """Each asset's file name, its OBJ text (titled by the first line of its maker's docstring) and its
    triangle count: what ``main`` writes, and what the examples' tests compare with the committed files."""
    files = {}
    for name, make in assets.items():
        mesh = make()
        files[f"{name}.obj"] = (mesh.obj(f"{name}: {make.__doc__.splitlines()[0]}", note), mesh.triangles())
    return files


def main(assets: dict[str, Callable[[], Mesh]], note: str, folder: Path, description: str) -> None:
    """``make_assets.py [--out DIR]``: write the assets (default ``folder``/assets) and their sizes."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--out", type=Path, default=folder / "assets")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    files = obj_files(assets, note)
    width = max(map(len, files))
    for name, (text, triangles) in files.items():
        (args.out / name).write_text(text)
        print(f"{name:{width}s} {triangles:4d} triangles")


def lathe(profile, sides: int, cx: float = 0.0, cz: float = 0.0, caps: bool = True, axis: str = "y") -> Mesh:
    """A solid of revolution about the vertical line through (cx, cz), or about the z axis (``axis="z"``,
    the Ionic capital's volutes): ``profile`` is (radius, height) from one end to the other; a radius of
    0 closes the solid in a point; ``caps`` closes the end rings. Columns, amphorae, basins, trees."""
    mesh, rings = Mesh(), []
    for r, h in profile:
        if r == 0:
            rings.append([len(mesh.vertices)])
            mesh.vertices.append((cx, h, cz) if axis == "y" else (cx, cz, h))
            continue
        start = len(mesh.vertices)
        for k in range(sides):
            a = 2 * math.pi * k / sides
            c, s = r * math.cos(a), r * math.sin(a)
            mesh.vertices.append((cx + c, h, cz - s) if axis == "y" else (cx + c, cz + s, h))
        rings.append(list(range(start, start + sides)))
    for lower, upper in pairwise(rings):
        for k in range(sides):
            k1 = (k + 1) % sides
            if len(lower) == 1:
                mesh.faces.append([lower[0], upper[k1], upper[k]])
            elif len(upper) == 1:
                mesh.faces.append([lower[k], lower[k1], upper[0]])
            else:
                mesh.faces.append([lower[k], lower[k1], upper[k1], upper[k]])
    if caps:
        if len(rings[0]) > 1:
            mesh.faces.append(list(reversed(rings[0])))
        if len(rings[-1]) > 1:
            mesh.faces.append(list(rings[-1]))
    return mesh


def extrude_x(profile, x0: float = 0.0, x1: float = 1.0) -> Mesh:
    """A prism along x over ``profile``: (z, y) points, counter-clockwise in the (z, y) plane. Roofs, steps,
    moldings: everything whose section is the same all along a wall."""
    n = len(profile)
    points = [(x0, y, z) for z, y in profile] + [(x1, y, z) for z, y in profile]
    faces = [list(range(n)), list(reversed(range(n, 2 * n)))]
    faces += [[k, n + k, n + (k + 1) % n, (k + 1) % n] for k in range(n)]
    return Mesh().add(points, faces)
