"""Helpers of the built-in function tests: files written in a grammar's folder, the grammar derived there on
strips of lots (one shape per lot), and what its ``report`` calls saw per lot."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from conftest import in_world

from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar
from grammarc.io.lots import lots_from_polygons

VERSION = 'version "2022.0"\n'


def write_files(root: Path, files: dict) -> None:
    """Write ``{relative path: text or bytes}`` under ``root``."""
    for name, content in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)


def box_obj(size, corner=(0.0, 0.0, 0.0), head: str = "") -> str:
    """An OBJ box of ``size`` whose lowest corner is ``corner``, ``head`` lines (groups...) first."""
    (x, y, z), (w, h, d) = corner, size
    vertices = "".join(f"v {x + i * w} {y + j * h} {z + k * d}\n" for i in (0, 1) for j in (0, 1) for k in (0, 1))
    return vertices + head + "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\n"


def rectangles(*sizes) -> list:
    """Lots: rectangles (w, h) side by side; a lot's scope is w x 0 x h."""
    lots, x = [], 0.0
    for w, h in sizes:
        lots.append([np.array([[x, 0], [x + w, 0], [x + w, h], [x, h]], float)])
        x += w + 1
    return lots


def derived(root: Path, text: str, lots: list, **options):
    """The records of the CityEngine grammar ``text`` written in ``root`` and derived on ``lots``, in world
    coordinates."""
    path = root / "g.cga"
    path.write_text(VERSION + "@StartRule\n" + text)
    return in_world(derive(compile_grammar(path), lots_from_polygons(lots), BuildOptions(**options)))


def reported(records, key: str) -> list:
    """The value reported under ``key`` on each lot, in lot order (one shape per lot)."""
    lots = records["reports"].lots
    return [records["reports"].table(lots[lot])[f"{key}_min"] for lot in sorted(lots)]
