"""Records written by hand for the render tests: boxes at known places, in known colours."""

from __future__ import annotations

import numpy as np

from grammarc.io.npz import InstanceWriter
from grammarc.model.records import MeshChunk, TerminalChunk

#: The background colour, as the PNG stores it.
SKY = np.array([172, 200, 230], np.uint8)


def box_xform(low, size) -> np.ndarray:
    """(3, 4) float32 mapping the unit box onto the axis-aligned box at ``low`` of ``size`` (world)."""
    return np.concatenate([np.diag(np.asarray(size, float)), np.asarray(low, float)[:, None]], axis=1).astype(
        np.float32)


def write_record(path, xforms, colors=None, asset=None, assets=("builtin:cube",), meta=None):
    """An instance record at ``path``, one instance per (3, 4) xform, symbol 0; returns the path."""
    xforms = np.asarray(xforms, np.float32).reshape(-1, 3, 4)
    n = len(xforms)
    chunk = TerminalChunk(
        asset=np.zeros(n, np.int32) if asset is None else np.asarray(asset, np.int32),
        xform=xforms,
        lot=np.arange(n, dtype=np.int32),
        symbol=np.zeros(n, np.int32),
        mesh=MeshChunk.empty(),
        color=None if colors is None else np.asarray(colors, np.uint8),
    )
    with InstanceWriter(path, assets=list(assets), symbols=["box"], meta=meta or {}) as out:
        out.write(chunk)
    return path
