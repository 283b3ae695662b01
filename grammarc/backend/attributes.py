"""Control parameters per lot: ``attr`` defaults, lot properties and ``--attr`` overrides.

The Puuc paper reads its 20-30 parameters per building from GIS; so does grammarc. For each attribute, in
declaration order, the value of a lot is: the ``--attr`` override if one was given (it holds for every
lot), else the lot's property of the same name where the lot has one, else the default expression,
evaluated on the lot's own shape (defaults may use earlier attributes, ``rand`` and ``Scope``; in
CityEngine's dialect a default draws from a stream of its own, as PRT's do: ``backend.streams``).
A property of the wrong type (text for a numeric attribute) makes its lot bad, with the value named.

An array attribute (``attr heights = [10, 20]``) is a column of ``backend.arrays.Arrays``, one array per
lot. A lot overrides it with a JSON array property (GeoJSON ``"heights": [10, 20]``, a list of rows
``[[1, 2], [3, 4]]`` for a 2-D array) or a single value (a 1x1 array); ``--attr`` cannot give arrays.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np

from grammarc.backend.arrays import Arrays
from grammarc.backend.evaluate import Env, evaluate, evaluate_array
from grammarc.backend.streams import attribute_keys
from grammarc.errors import LotFailure, UsageError
from grammarc.ir import nodes as ir
from grammarc.ir.traverse import iter_exprs

T = ir.Type


def parse_override(text: str) -> tuple[str, object]:
    """``name=value`` from the command line: a number, ``true``/``false``, or else a string."""
    name, sep, value = text.partition("=")
    if not sep or not name.strip():
        raise UsageError(f"--attr expects NAME=VALUE, got `{text}`")
    value = value.strip()
    if value in ("true", "false"):
        return name.strip(), value == "true"
    try:
        return name.strip(), float(value)
    except ValueError:
        return name.strip(), value.strip('"')


def check_overrides(module: ir.Module, overrides: dict[str, object]) -> None:
    types = {a.name: a.type for a in module.attrs}
    consts = {a.name for a in module.attrs if a.const}
    for name, value in overrides.items():
        if name in consts:
            raise UsageError(f"--attr {name}: `{name}` is a constant, which cannot be overridden")
        if name not in types:
            known = ", ".join(types) or "none"
            raise UsageError(f"--attr {name}: the grammar declares no attribute `{name}` (attributes: {known})")
        want = types[name]
        if want.is_array:
            raise UsageError(f"--attr {name}: `{name}` is an array ({want.value}), which --attr cannot give; "
                             "give it per lot as a property of the lots")
        got = T.BOOL if isinstance(value, bool) else T.NUM if isinstance(value, float) else T.STR
        if want is not got and want is not T.UNKNOWN:
            raise UsageError(f"--attr {name}={value}: `{name}` is a {want.value}, not a {got.value}")


def attribute_columns(module: ir.Module, env: Env, lot_attrs: dict[str, np.ndarray],
                      overrides: dict[str, object], strings) -> dict[str, np.ndarray]:
    """Fill ``env.chunk.attrs`` with one (L,) column per attribute; ``env.shapes`` are the lots' shapes."""
    columns = env.chunk.attrs
    n = len(env.shapes)
    lots = env
    for attr in dependency_order(module.attrs):
        env = _drawing(lots, attr.name)
        if attr.type.is_array:
            column = evaluate(attr.default, env)
            if attr.name in lot_attrs and not attr.const:
                column = _arrays_from_lots(attr, lot_attrs[attr.name], column, strings)
            columns[attr.name] = column
            continue
        dtype = np.int32 if attr.type is T.STR else bool if attr.type is T.BOOL else np.float64
        if attr.name in overrides and not attr.const:
            value = overrides[attr.name]
            value = strings.intern(value) if attr.type is T.STR else value
            columns[attr.name] = np.full(n, value, dtype=dtype)
            continue
        column = evaluate_array(attr.default, env, dtype=dtype) if attr.type is not T.STR else \
            np.asarray(evaluate_array(attr.default, env, dtype=np.int32))
        if attr.name in lot_attrs and not attr.const:
            column = _from_lots(attr, lot_attrs[attr.name], column.copy(), strings, env)
        columns[attr.name] = column
    return columns


def _drawing(env: Env, name: str) -> Env:
    """``env`` whose shapes draw from the stream of attribute ``name``'s default (``streams.attribute_keys``:
    PRT's defaults draw from a stream of their own, not from the lot's)."""
    if not env.plan.sequential_random:
        return env
    return replace(env, shapes=replace(env.shapes, key=attribute_keys(env.shapes.key, name)))


def dependency_order(attrs: tuple[ir.AttrDecl, ...]) -> list[ir.AttrDecl]:
    """Attributes ordered so that each comes after those its default uses (CityEngine lets a default use
    an attribute declared further down); declaration order otherwise. A cycle keeps declaration order
    for the attributes on it (their defaults then see the other's default as not yet set)."""
    by_name = {a.name: a for a in attrs}
    done: dict[str, ir.AttrDecl] = {}
    visiting: set[str] = set()

    def visit(attr: ir.AttrDecl) -> None:
        if attr.name in done or attr.name in visiting:
            return
        visiting.add(attr.name)
        for e in iter_exprs(attr.default):
            if isinstance(e, ir.AttrRef) and e.name in by_name:
                visit(by_name[e.name])
        visiting.discard(attr.name)
        done[attr.name] = attr

    for attr in attrs:
        visit(attr)
    return list(done.values())


def _from_lots(attr: ir.AttrDecl, values: np.ndarray, column: np.ndarray, strings, env) -> np.ndarray:
    """``column`` with the lots' own values where they have one; text is converted once per distinct
    value, not once per lot."""
    if values.dtype != object:
        given = ~np.isnan(values)
        if attr.type is T.STR:
            column[given] = _per_distinct(values[given], lambda v: strings.intern(f"{v:g}"))
        else:
            column[given] = values[given] if attr.type is T.NUM else values[given] != 0
        return column
    given = values != None  # elementwise on an object array: `is not None` would compare the array
    if attr.type is T.STR:
        column[given] = _per_distinct(values[given], strings.intern)
        return column
    parsed = np.full(len(values), np.nan)
    parsed[given] = _per_distinct(values[given], lambda text: _number(text, attr.type))
    bad = given & np.isnan(parsed)
    if bad.any():  # each lot's reason quotes its own value
        lots = np.flatnonzero(bad)
        reasons = [f"attribute `{attr.name}` is \"{values[lot]}\", not a {attr.type.value}" for lot in lots]
        raise LotFailure(reasons[0], lots, reasons)
    column[given] = parsed[given] if attr.type is T.NUM else parsed[given] != 0
    return column


def _arrays_from_lots(attr: ir.AttrDecl, values: np.ndarray, column: Arrays, strings) -> Arrays:
    """``column`` with the lots' own arrays where they have one: JSON arrays (or single values) parsed
    once per distinct text; a value of the wrong element type or shape makes its lots bad."""
    n = len(column)
    given = ~np.isnan(values) if values.dtype != object else values != None  # elementwise
    if not given.any():
        return column
    raw = values[given]
    distinct, inverse = np.unique(raw.astype(str) if raw.dtype == object else raw, return_inverse=True)
    inverse = inverse.reshape(-1)
    texts = [str(v) if values.dtype == object else json.dumps(float(v)) for v in distinct]
    parsed = [_parse_array(text, attr.type, strings) for text in texts]
    failed = np.array([p is None for p in parsed])[inverse]
    if failed.any():  # each lot's reason quotes its own value
        reasons = [f"attribute `{attr.name}` is {texts[k]}, not a {attr.type.value}" for k in inverse[failed]]
        raise LotFailure(reasons[0], np.flatnonzero(given)[failed], reasons)
    dtype = column.values.dtype
    table = Arrays(np.concatenate([column.values, *(np.asarray(p[0], dtype=dtype) for p in parsed)]),
                   np.concatenate([column.offsets, column.offsets[-1] + np.cumsum([len(p[0]) for p in parsed],
                                                                                  dtype=np.int64)]),
                   np.concatenate([column.columns, np.array([p[1] for p in parsed], dtype=np.int64)]))
    which = np.arange(n)
    which[given] = n + inverse
    return table.take(which)


def _parse_array(text: str, want: ir.Type, strings) -> tuple[list, int] | None:
    """A lot's array property as (elements row by row, columns), or None when it is not a ``want``: a
    JSON array of elements, a JSON array of equally long rows, or a single element."""
    try:
        value = json.loads(text)
    except ValueError:
        value = text  # a plain string property: one string element
    rows = value if isinstance(value, list) and value and all(isinstance(r, list) for r in value) else [
        value if isinstance(value, list) else [value]]
    width = len(rows[0])
    if any(len(r) != width for r in rows):
        return None
    elements = [e for r in rows for e in r]
    element = want.element
    if element is T.NUM and all(isinstance(e, (int, float)) and not isinstance(e, bool) for e in elements):
        return [float(e) for e in elements], width if elements else 0
    if element is T.BOOL and all(isinstance(e, bool) for e in elements):
        return elements, width if elements else 0
    if element is T.STR and all(isinstance(e, str) for e in elements):
        return [strings.intern(e) for e in elements], width if elements else 0
    return None


def _number(text: str, want: ir.Type) -> float:
    """A lot's text value as a number (``true``/``false`` for booleans); NaN when it is not one."""
    text = text.strip()
    if want is T.BOOL and text in ("true", "false"):
        return float(text == "true")
    try:
        return float(text)
    except ValueError:
        return float("nan")


def _per_distinct(values: np.ndarray, convert) -> np.ndarray:
    """``convert`` applied to each distinct value of ``values`` (k,), spread back to all k."""
    if not len(values):
        return np.zeros(0)
    distinct, inverse = np.unique(values.astype(str) if values.dtype == object else values,
                                  return_inverse=True)
    return np.array([convert(v) for v in distinct])[inverse.reshape(-1)]
