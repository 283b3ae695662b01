"""Texture-space queries: ``geometry.uMin``, ``uMax``, ``vMin``, ``vMax`` (the least and greatest texture
coordinates of the shape's geometry) and ``geometry.du``, ``geometry.dv`` (their extent, in texture units
or, ``unitSpace``, in metres on the surface), of a texture set (``backend.texture_space``).

The set is the first argument (0 when left out); a shape without coordinates of that set answers 0.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend.functions.table import function
from grammarc.backend.texture_space import metres_per_unit, texture_bounds, texture_maps

if TYPE_CHECKING:
    from grammarc.backend.env import Env


@function("geometry.uMin", "geometry.uMax", "geometry.vMin", "geometry.vMax", "geometry.du", "geometry.dv")
def texture_extent(call, args, env: Env):
    name = call.func.split(".")[1]
    uv_set = int(np.ravel(args[0])[0]) if args else 0
    maps = texture_maps(env.plan, env.chunk, env.shapes, uv_set)
    low, high = texture_bounds(env.chunk, env.shapes, maps)
    row = "uv".index(name[-1] if name[0] == "d" else name[0])
    if name[0] == "d":
        value = high[:, row] - low[:, row]
        if np.ravel(args[1])[0] == env.plan.strings.intern("unitSpace"):
            value = value * metres_per_unit(maps)[:, row]
    else:
        value = (low if name.endswith("Min") else high)[:, row]
    return np.nan_to_num(value, nan=0.0)
