"""Wavefront OBJ geometry read: vertices and polygon faces, nothing else.

Lots (one per face) and assets (meshes fitted to scopes) are read from OBJ files; both want only the
``v`` and ``f`` lines. Materials, texture coordinates and normals are ignored (they would need Pillow and
are not part of grammarc's records), and so is every other line. The reader sits on the model floor
because asset meshes (``model.assets``) are loaded with it; the OBJ writer is ``io.obj``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["ObjError", "read_obj"]


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
