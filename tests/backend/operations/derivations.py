"""Helpers of the derivation tests: a grammar text derived on lots in either dialect, and the records read
back by symbol, asset, normal, mesh face and report.

Lots made here are map rectangles (0,0)-(w,h) unless said otherwise: their scope has x = world +x, y up,
z = world +z and origin (0, 0, -h), so a scope translation (tx, ty, tz) lands at world (tx, ty, tz - h). A
box leaf is a ``builtin:cube`` whose transform's columns are the scope axes times the sizes; a flat
rectangle is a ``builtin:quad`` whose first two columns span the face (their cross product is the face's
outward normal); polygons go to the mesh table.
"""

from __future__ import annotations

import math

import numpy as np
from conftest import LOT_ZOO, in_world

from grammarc.build import BuildOptions, derive
from grammarc.compiler import compile_grammar
from grammarc.io.lots import lots_from_polygons

VERSION = 'version "2022.0"\n'


def rect(w, h):
    return [np.array([[0, 0], [w, 0], [w, h], [0, h]], float)]


def rotated_rectangle(degrees=30.0, w=10.0, h=4.0, at=(5.0, 5.0)):
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    ring = np.array([[0, 0], [w, 0], [w, h], [0, h]], float) @ np.array([[c, s], [-s, c]]) + at
    return [ring]


def make_lots_polys(*names):
    return [LOT_ZOO[n] for n in names]


def run(write, text, polygons, *, lot_attrs=None, version=True, **options):
    """The records of ``text`` (CityEngine's, unless ``version`` is false) derived on ``polygons``, in world
    coordinates."""
    grammar = compile_grammar(write("g.cga", (VERSION if version else "") + text))
    return in_world(derive(grammar, lots_from_polygons(polygons, attrs=lot_attrs), BuildOptions(**options)))


def paper(write, text, polygons, **options):
    """``run`` of a grammar in the paper's notation."""
    return run(write, text, polygons, version=False, **options)


def names(r):
    """Symbol name of each record."""
    return [str(s) for s in r["symbols"][r["symbol"]]]


def of_symbol(records, name):
    """Rows of the records whose symbol is ``name``."""
    return records["symbol"] == list(records["symbols"]).index(name)


def assets(r):
    return [str(a) for a in r["assets"][r["asset"]]]


def rows(r, name):
    return np.array(names(r)) == name


def quad_normals(r):
    """Outward unit normal of each quad record: the cross product of its first two columns."""
    x = r["xform"].astype(float)
    n = np.cross(x[:, :, 0], x[:, :, 1])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def quad_centres(r):
    x = r["xform"].astype(float)
    return x[:, :, 3] + (x[:, :, 0] + x[:, :, 1]) / 2


def totals(r):
    return r["reports"].table(r["reports"].totals())


def per_lot(r):
    return {lot: r["reports"].table(entries) for lot, entries in r["reports"].lots.items()}


def mesh_faces(r):
    """Each mesh face as its list of rings (world coordinates)."""
    m = r["mesh"]
    faces = []
    for f in range(len(m.lot)):
        rings = range(m.face_offsets[f], m.face_offsets[f + 1])
        faces.append([m.vertices[m.ring_offsets[k]:m.ring_offsets[k + 1]].astype(float) for k in rings])
    return faces


def same_records(a, b):
    """Assert that two derivations made the same records (instances and mesh faces)."""
    for key in ("asset", "xform", "lot", "symbol"):
        np.testing.assert_array_equal(a[key], b[key])
    for key in ("vertices", "ring_offsets", "face_offsets", "lot", "symbol"):
        np.testing.assert_array_equal(getattr(a["mesh"], key), getattr(b["mesh"], key))


def ring_area(ring):
    """Area of a planar ring in 3D (Newell's method)."""
    return np.linalg.norm(np.cross(ring, np.roll(ring, -1, axis=0)).sum(axis=0)) / 2


def face_area(rings):
    return ring_area(rings[0]) - sum(ring_area(h) for h in rings[1:])
