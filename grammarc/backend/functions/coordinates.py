"""Coordinate systems and the initial shape: ``convert``, ``initialShape.name``, ``initialShape.startRule``.

``convert(coordinate, from, to, pos|orient, x, y, z)`` takes a position, or an orientation (Euler angles in
degrees, ``backend.euler``), from one of CityEngine's coordinate systems to another, and gives one of its
components. The systems, as grammarc's shapes have them:

- ``world``: the coordinates of the lots and the records (y up);
- ``object``: the lot's own scope, which ``initialShape.origin`` is relative to;
- ``pivot``: the shape's pivot (``backend.pivot``), which ``scope.t*`` and ``scope.r*`` are relative to
  (``evaluate._scope_field``): the object system where the grammar keeps no pivot;
- ``scope``: the shape's scope, its origin and axes.

A system is an origin and axes (rows, in world): a position p goes to world as ``origin + p @ axes`` and
back as ``(q - origin) @ axes.T``; an orientation's rotation (rows: its axes in the system's coordinates)
goes to world as ``rotation @ axes``. All of it is numpy over the batch.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend import euler, pivot
from grammarc.backend.functions.table import distinct, function

if TYPE_CHECKING:
    from grammarc.backend.env import Env


@function("convert")
def convert(call, args, env: Env):
    """The component (n,) float64 of (x, y, z) converted; the selectors are the call's string constants."""
    coordinate, source, target, kind = (a.value for a in call.args[:4])
    n = len(env.shapes)
    values = np.stack([np.broadcast_to(np.asarray(a, dtype=np.float64), (n,)) for a in args[4:]], axis=1)
    from_origin, from_axes = system(source, env)
    to_origin, to_axes = system(target, env)
    if kind == "pos":
        world = from_origin + np.einsum("ni,nij->nj", values, from_axes)
        out = np.einsum("nj,nij->ni", world - to_origin, to_axes)
    else:
        axes = np.einsum("nij,njk->nik", euler.orientation(*values.T), from_axes)  # rows: axes in world
        out = euler.angles(np.einsum("nij,nkj->nik", axes, to_axes))
    return out[:, "xyz".index(coordinate)]


def system(name: str, env: Env) -> tuple[np.ndarray, np.ndarray]:
    """The origins (n, 3) and axes (n, 3, 3) (rows, in world) of coordinate system ``name`` per shape."""
    shapes, chunk = env.shapes, env.chunk
    if name == "scope":
        return shapes.origin, chunk.frames[shapes.frame]
    if name == "world":
        n = len(shapes)
        return np.zeros((n, 3)), np.broadcast_to(np.eye(3), (n, 3, 3))
    if name == "pivot":
        return pivot.pivot_system(env.plan.pivot_slot, chunk, shapes)
    return chunk.lot_origin[shapes.lot], chunk.lot_axes[shapes.lot]


@function("initialShape.name")
def initial_shape_name(call, args, env: Env):
    """The lot's identifier (its feature's ``id``, else its ``id`` or ``name`` property, else its number)."""
    ids, strings = env.chunk.lot_ids, env.plan.strings
    return distinct(lambda lot: strings.intern(str(ids[lot])), env.shapes.lot, dtype=np.int32)


@function("initialShape.startRule")
def initial_shape_start_rule(call, args, env: Env):
    """The start rule's name, without the arity of an overloaded rule (``Lot/2``) or the arguments of a
    ``--start Lot(12)``: the same for every lot, as grammarc starts every lot with one rule."""
    name = env.plan.symbols[env.plan.start].name
    return env.plan.strings.intern(re.split(r"[/(]", name, maxsplit=1)[0])
