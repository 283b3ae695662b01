"""Wavefront OBJ geometry written fast: a baked city's vertices and triangles, in groups (``io.bake``).

The reader of OBJ geometry (lots, assets) is ``model.obj``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["obj_bytes", "with_lines"]


#: Decimals of the coordinates ``obj_bytes`` writes (``_fixed`` writes them as three digit pairs): a
#: micrometre, below the float32 step of a record's coordinates beyond 10 m from the origin.
DECIMALS = 6


def obj_bytes(vertices: np.ndarray, faces: np.ndarray, header: str = "", uv: np.ndarray | None = None,
              uv_shift: int = 0) -> bytes:
    """An OBJ file of ``vertices`` (V, 3) and triangles ``faces`` (T, 3) (0-based), as bytes; with texture
    coordinates ``uv`` (V, 2), a ``vt`` after each ``v`` and faces ``f a/a' b/b' c/c'``, the ``vt`` index
    ``uv_shift`` less than the ``v`` index (the vertices written before without one, in a streamed file).

    A baked city has 10^7 triangles and more, too many to format one by one with Python's ``str.format``
    (as trimesh does). Here a numba kernel writes the digits into one buffer:
    coordinates in fixed point with ``DECIMALS`` decimals, trailing zeros dropped; indices 1-based.
    """
    vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    lines = "".join(f"# {line}\n" for line in header.splitlines() if line)
    textured = uv is not None
    uv = np.ascontiguousarray(uv if textured else np.zeros((0, 2)), dtype=np.float64)
    if not (np.isfinite(vertices).all() and np.isfinite(uv).all()):
        raise ValueError("obj_bytes: vertices and texture coordinates must be finite")
    # the longest line: "v " + 3 * ("-" + 19 digits + "." + decimals + " "), "f " + 3 * (19 digits + " ");
    # with texture coordinates "vt " + 2 * (...) and "/" + 19 digits after each index
    size = len(vertices) * (2 + 3 * (22 + DECIMALS)) + len(faces) * (2 + 3 * 20) + 1
    if textured:
        size += len(vertices) * (3 + 2 * (22 + DECIMALS)) + len(faces) * 3 * 20
    buffer = np.empty(size, np.uint8)
    used = _write_obj(vertices, faces, uv, textured, uv_shift, buffer)
    return lines.encode() + buffer[:used].tobytes()


@njit(cache=True, nogil=True)
def _write_obj(vertices, faces, uv, textured, uv_shift, out):
    at = 0
    for i in range(vertices.shape[0]):
        out[at] = 118  # v
        at = _line(vertices[i], out, at + 1)
        if textured:
            out[at] = 118  # vt
            out[at + 1] = 116
            at = _line(uv[i], out, at + 2)
    for i in range(faces.shape[0]):
        out[at] = 102  # f
        at += 1
        for k in range(3):
            out[at] = 32
            at = _integer(faces[i, k] + 1, out, at + 1)
            if textured:  # the vertex's own texture coordinate
                out[at] = 47
                at = _integer(faces[i, k] + 1 - uv_shift, out, at + 1)
        out[at] = 10
        at += 1
    return at


@njit(cache=True, nogil=True)
def _line(values, out, at):
    """The rest of a ``v`` or ``vt`` line: each value after a blank, then the newline."""
    for k in range(values.shape[0]):
        out[at] = 32
        at = _fixed(values[k], out, at + 1)
    out[at] = 10
    return at + 1


#: "00" .. "99": digits are written two at a time (half the divisions).
_PAIRS = np.array([ord(c) for k in range(100) for c in f"{k:02d}"], dtype=np.uint8)


@njit(cache=True, nogil=True)
def _integer(value, out, at):
    """The decimal digits of ``value`` >= 0 at ``out[at:]``; the position after them."""
    digits = 1
    bound = 10
    while value >= bound and digits < 19:
        digits += 1
        bound *= 10
    end = at + digits
    pos = end
    while value >= 100:
        pair = value % 100
        value //= 100
        out[pos - 2] = _PAIRS[2 * pair]
        out[pos - 1] = _PAIRS[2 * pair + 1]
        pos -= 2
    if value >= 10:
        out[pos - 2] = _PAIRS[2 * value]
        out[pos - 1] = _PAIRS[2 * value + 1]
    else:
        out[pos - 1] = 48 + value
    return end


@njit(cache=True, nogil=True)
def _fixed(value, out, at):
    """``value`` in fixed point with ``DECIMALS`` (6) decimals, trailing zeros and a bare point dropped."""
    units = np.int64(np.round(abs(value) * 1_000_000))
    if units and value < 0:
        out[at] = 45  # -
        at += 1
    at = _integer(units // 1_000_000, out, at)
    fraction = units % 1_000_000
    if fraction:
        out[at] = 46  # .
        for k, pair in enumerate((fraction // 10_000, fraction // 100 % 100, fraction % 100)):
            out[at + 1 + 2 * k] = _PAIRS[2 * pair]
            out[at + 2 + 2 * k] = _PAIRS[2 * pair + 1]
        at += 7
        while out[at - 1] == 48:
            at -= 1
    return at


def with_lines(text: bytes, first_lines: np.ndarray, lines: list[str]) -> bytes:
    """``text`` (lines ending in newlines, as ``obj_bytes`` writes them) with ``lines[k]`` inserted before
    its line ``first_lines[k]`` (increasing): the ``g`` and ``usemtl`` statements before groups of faces."""
    inserted = "".join(lines).encode()
    ends = np.cumsum([len(line.encode()) for line in lines], dtype=np.int64)
    out = np.empty(len(text) + len(inserted), np.uint8)
    _interleave(np.frombuffer(text, np.uint8), np.asarray(first_lines, np.int64),
                np.frombuffer(inserted, np.uint8), ends, out)
    return out.tobytes()


@njit(cache=True, nogil=True)
def _interleave(text, first_lines, inserted, ends, out):
    at = 0
    line = 0
    group = 0
    line_start = True
    for i in range(len(text)):
        if line_start:
            while group < len(first_lines) and first_lines[group] == line:
                for k in range(ends[group - 1] if group else 0, ends[group]):
                    out[at] = inserted[k]
                    at += 1
                group += 1
            line_start = False
        out[at] = text[i]
        at += 1
        if text[i] == 10:
            line += 1
            line_start = True
