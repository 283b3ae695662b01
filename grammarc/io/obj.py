"""Wavefront OBJ geometry: vertices and polygon faces, nothing else; read, and written fast.

Lots (one per face) and assets (meshes fitted to scopes) are read from OBJ files; both want only the
``v`` and ``f`` lines. Materials, texture coordinates and normals are ignored (they would need Pillow and
are not part of grammarc's records), and so is every other line.
"""

from __future__ import annotations

import numpy as np
from numba import njit


class ObjError(ValueError):
    """A ``v`` or ``f`` line that cannot be read; the message starts with ``path:line:``."""


def read_obj(text: str, path: str = "<obj>") -> tuple[np.ndarray, list[np.ndarray]]:
    """Vertices (V, 3) float64 and faces (a list of (k,) int64 arrays of 0-based vertex indices).

    Face tokens may be ``i``, ``i/t``, ``i//n`` or ``i/t/n``; a negative ``i`` counts back from the last
    vertex read. Indices are not checked against the vertex count (callers report their own way).
    """
    points: list[list[float]] = []
    faces: list[np.ndarray] = []
    for number, line in enumerate(text.splitlines(), start=1):
        fields = line.split()
        if not fields or fields[0] not in ("v", "f"):
            continue
        try:
            if fields[0] == "v":
                point = [float(value) for value in fields[1:4]]
                if len(point) != 3:
                    raise ValueError("a vertex needs x y z")
                points.append(point)
            else:
                indices = [int(token.split("/")[0]) for token in fields[1:]]
                faces.append(np.array([i - 1 if i > 0 else len(points) + i for i in indices], np.int64))
        except ValueError as error:
            raise ObjError(f"{path}:{number}: bad {fields[0]!r} line: {line.strip()!r} ({error})") from error
    return np.array(points, dtype=np.float64).reshape(-1, 3), faces


#: Decimals of the coordinates ``obj_bytes`` writes (``_fixed`` writes them as three digit pairs): a
#: micrometre, below the float32 step of a record's coordinates beyond 10 m from the origin.
DECIMALS = 6


def obj_bytes(vertices: np.ndarray, faces: np.ndarray, header: str = "") -> bytes:
    """An OBJ file of ``vertices`` (V, 3) and triangles ``faces`` (T, 3) (0-based), as bytes.

    A baked city has 10^7 triangles and more; formatting them with Python's ``str.format`` (as trimesh
    does) took 15 s for 50 candler buildings. Here a numba kernel writes the digits into one buffer:
    coordinates in fixed point with ``DECIMALS`` decimals, trailing zeros dropped; indices 1-based.
    """
    vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    if not np.isfinite(vertices).all():
        raise ValueError("obj_bytes: vertices must be finite")
    lines = "".join(f"# {line}\n" for line in header.splitlines() if line)
    # the longest line: "v " + 3 * ("-" + 19 digits + "." + decimals + " "), "f " + 3 * (19 digits + " ")
    buffer = np.empty(len(vertices) * (2 + 3 * (22 + DECIMALS)) + len(faces) * (2 + 3 * 20) + 1, np.uint8)
    used = _write_obj(vertices, faces, buffer)
    return lines.encode() + buffer[:used].tobytes()


@njit(cache=True, nogil=True)
def _write_obj(vertices, faces, out):
    at = 0
    for i in range(vertices.shape[0]):
        out[at] = 118  # v
        at += 1
        for k in range(3):
            out[at] = 32
            at = _fixed(vertices[i, k], out, at + 1)
        out[at] = 10
        at += 1
    for i in range(faces.shape[0]):
        out[at] = 102  # f
        at += 1
        for k in range(3):
            out[at] = 32
            at = _integer(faces[i, k] + 1, out, at + 1)
        out[at] = 10
        at += 1
    return at


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
