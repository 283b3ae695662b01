"""A shape's material: its colour and opacity packed in one column, its texture channels as string columns.

CityEngine's material attributes (``material.color.r``, ``material.opacity``, ``material.colormap``...)
are per-shape values that successors inherit. The derivation keeps those a grammar sets or reads:

- the colour and the opacity share the colour column (``slots.COLOR_SLOT``), one float per shape:
  0xRRGGBB plus the transparency ``255 - alpha`` times 2^24, so that an opaque colour is the number it
  always was (and a record without ``set(material.opacity)`` the bytes it always was);
- each texture channel the grammar sets or reads is a column of its own named as the attribute
  (``material.colormap``), the interned id of its path ("" for none).

Terminals carry the channels into the record as a table of distinct channel tuples (``collect_materials``),
each tuple the texts of every channel of ``ir.MATERIAL_MAPS`` ("" where none), and an index into it per
row; the paths are kept as the grammar wrote them and resolved by the writers that read the files.
"""

from __future__ import annotations

import weakref

import numpy as np

from grammarc.ir import nodes as ir

#: The transparency's place in the packed colour (a fused kernel packs colours too: ``fusion.codegen``).
ALPHA_UNIT = float(1 << 24)
#: The texture channel columns' names, in the record's order.
MAP_FIELDS = tuple(f"material.{m}" for m in ir.MATERIAL_MAPS)
#: The material attributes read from the colour column.
COLOR_FIELDS = frozenset(ir.MATERIAL_FIELDS) - frozenset(MAP_FIELDS)


def rgba(packed: np.ndarray) -> np.ndarray:
    """(n, 4) uint8 RGBA colours from packed colours (n,) stored as floats (module docstring)."""
    value = packed.astype(np.int64)
    out = np.empty((len(value), 4), np.uint8)
    # a uint8 column keeps the low byte of what it is given: the channel, without masks and a stack
    out[:, 0] = value >> 16
    out[:, 1] = value >> 8
    out[:, 2] = value
    out[:, 3] = 255 - (value >> 24 & 255)
    return out


def hex_color(text: str) -> float:
    """0xRRGGBB of "#rrggbb" (or "#rgb"), NaN when the text is no such colour."""
    digits = text.strip().lstrip("#")
    if len(digits) == 3:
        digits = "".join(c * 2 for c in digits)
    try:
        return float(int(digits, 16)) if len(digits) == 6 else float("nan")
    except ValueError:
        return float("nan")


#: The colours of each table of interned strings (``hex_colors``), by id, as far as its strings had come.
_HEX_COLORS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def hex_colors(strings) -> np.ndarray:
    """The colour (``hex_color``: NaN for a text that is none) of each string interned in ``strings``
    (``plan.Strings``), by id: ``color`` of a string maps over interned ids, in the interpreter and in the
    fused kernels alike. Each text is read once, as strings are interned."""
    table = _HEX_COLORS.get(strings, np.empty(0))
    if len(table) < len(strings.ids):
        texts = list(strings.ids)[len(table):]
        table = _HEX_COLORS[strings] = np.concatenate([table, [hex_color(text) for text in texts]])
    return table


def with_transparency_of(rgb: np.ndarray, packed: np.ndarray) -> np.ndarray:
    """New colours 0xRRGGBB (n,) keeping the transparency of the shapes' packed colours (n,)."""
    return rgb + np.floor(packed / ALPHA_UNIT) * ALPHA_UNIT


def with_opacity(packed: np.ndarray, opacity: np.ndarray) -> np.ndarray:
    """The packed colours (n,) with a new opacity (n,) in [0, 1] (clipped)."""
    transparency = 255 - np.round(np.clip(opacity, 0.0, 1.0) * 255)
    return packed % ALPHA_UNIT + transparency * ALPHA_UNIT


def channel(name: str, packed: np.ndarray | None):
    """``material.color.r|g|b`` or ``material.opacity`` in [0, 1] of packed colours (n,) float64, or the
    default (white, opaque) where the grammar sets no colour (``packed`` None)."""
    if packed is None:
        return 1.0
    value = packed.astype(np.int64)
    if name == "material.opacity":
        return (255 - (value >> 24 & 255)) / 255.0
    return (value >> (16 - 8 * "rgb".index(name[-1])) & 255) / 255.0


def material_ids(plan, shapes, rows=slice(None)) -> np.ndarray | None:
    """(m, k) int32: the string ids of the ``k`` texture channels the grammar carries (``Plan.material_slots``)
    of ``shapes`` rows ``rows``; None when it carries none."""
    if not plan.material_slots:
        return None
    return np.stack([shapes.dynamic[slot][rows] for _, slot in plan.material_slots], axis=1).astype(np.int32, copy=False)


def collect_materials(plan, ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The chunk's table of materials and each row's index into it, from the rows' channel ids (n, k).

    Returns
    -------
    materials : (M, len(ir.MATERIAL_MAPS)) str
        The distinct channel tuples, in order of their ids, as texts ("" where a channel is not set).
    material : (n,) int32
        Each row's material.
    """
    names = list(plan.strings.ids)
    # rows come in long runs of one material (a chunk's ~5 * 10^5 rows of candler in ~2,000 runs): the
    # first row of each run is sorted, not every row. Rows are compared column by column: numpy's
    # ``any(axis=1)`` over a row of a few columns costs several times as much
    changed = np.zeros(len(ids), dtype=bool)
    changed[:1] = True
    for column in range(ids.shape[1]):
        changed[1:] |= ids[1:, column] != ids[:-1, column]
    first = np.flatnonzero(changed)
    heads = ids[first]
    # one int64 key per row (the ids in base len(names)) sorts far faster than rows (np.unique(axis=0))
    radix = np.int64(len(names)) ** np.arange(ids.shape[1], dtype=np.int64)
    if float(len(names)) ** ids.shape[1] < 2.0 ** 62:
        keys, inverse = np.unique(heads.astype(np.int64) @ radix, return_inverse=True)
        distinct = keys[:, None] // radix % np.int64(len(names))
    else:
        distinct, inverse = np.unique(heads, axis=0, return_inverse=True)
    inverse = np.repeat(inverse.reshape(-1), np.diff(np.r_[first, len(ids)]))
    materials = np.full((len(distinct), len(MAP_FIELDS)), "", dtype=object)
    for column, (k, _) in enumerate(plan.material_slots):
        materials[:, k] = [names[int(i)] for i in distinct[:, column]]
    return materials.astype(str), inverse.reshape(-1).astype(np.int32)
