"""Lots of an OBJ file (``.obj``): one lot per face, in world coordinates, as the PRT kit's footprints.

Each face is one lot without holes, ids ``"face<k>"``, its number the face's; ``v`` lines are world
coordinates (y up, kept as they are) and every line but ``v`` and ``f`` is ignored (``io.obj``). A face
whose normal is not roughly vertical (a wall) is a bad lot, and so is one with a vertex index out of range.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from grammarc.errors import LotsError
from grammarc.io.lot_builder import LotBuilder
from grammarc.io.lot_format import NO_OPTIONS, LotsFormat, LotsOptions, read_text
from grammarc.model.lots import Lots
from grammarc.model.obj import ObjError, read_obj

__all__ = ["FORMAT", "read_obj_lots"]


def read_obj_lots(path: Path, options: LotsOptions = NO_OPTIONS) -> Lots:
    """All lots of an OBJ file; a ``LotsError`` names a malformed line (``path:line:``), or says the
    file holds no face."""
    try:
        vertices, faces = read_obj(read_text(path), str(path))
    except ObjError as error:
        raise LotsError(str(error)) from error
    builder = LotBuilder(world=True)
    for k, face in enumerate(faces):
        if np.any((face < 0) | (face >= len(vertices))):
            builder.reject(k, f"face{k}", "vertex index out of range")
        else:
            builder.add(k, f"face{k}", [vertices[face]], {})
    return builder.finish_file({}, path, options)


FORMAT = LotsFormat(kind="obj", suffixes=(".obj",), title=None, read=read_obj_lots)
