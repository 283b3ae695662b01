"""Image functions: an image's resolution, and images chosen from a search by their proportions.

``imageInfo(image, sx|sy)`` is the image's width or height in pixels, read from the file's header by
Pillow once per file (resolved as an insert's asset is); an image that cannot be found or read gives 0.
``imagesSortRatio(list, axes)`` orders a string list of images by how far their width / height is from
the scope's ratio of ``axes`` (``xy xz yx yz zx zy``: the first axis goes with the width), best first,
as ``assetsSortRatio`` does assets (``backend.functions.assets``). ``imageBestRatio(query, axes)`` is the
first of the sorted search; ``imageApproxRatio(query, axes, n)`` one of its first ``n`` drawn from the
shape's stream, or of all of them when ``n`` < 1, as the reference's ``ce.lib`` defines them; a selector
it does not list is ``xy``.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend.functions.assets import choose, ratio_errors, sort_list
from grammarc.backend.functions.files import roots
from grammarc.backend.functions.table import distinct, function
from grammarc.ir.asset_names import resolve_asset

if TYPE_CHECKING:
    from grammarc.backend.env import Env

#: Pairs of scope axes compared with an image's width / height; the first is the default.
IMAGE_AXES = {"xy": (0, 1), "xz": (0, 2), "yx": (1, 0), "yz": (1, 2), "zx": (2, 0), "zy": (2, 1)}


def image_size(env: Env, name: str) -> tuple[float, float]:
    """The width and height of image ``name`` in pixels; NaN, NaN when it cannot be read."""
    path = resolve_asset(name, list(roots(env))).path
    if path is None:
        return np.nan, np.nan
    return _header_size(path, path.stat().st_mtime_ns)


@lru_cache(maxsize=1024)
def _header_size(path: Path, mtime_ns: int) -> tuple[float, float]:
    """Pillow reads only the header until the pixels are asked for."""
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as image:
            return float(image.size[0]), float(image.size[1])
    except (OSError, UnidentifiedImageError, ValueError):
        return np.nan, np.nan


@function("imageInfo")
def image_info(call, args, env: Env):
    names = list(env.plan.strings.ids)

    def info(image: int, query: int) -> float:
        if names[query] not in ("sx", "sy"):
            return np.nan
        size = image_size(env, names[image])[names[query] == "sy"]
        return 0.0 if np.isnan(size) else size
    return distinct(info, args[0], args[1])


def sizes(env: Env, names) -> np.ndarray:
    """(c, 3) float64 width, height and 1 of images ``names``, laid out for ``ratio_errors``."""
    return np.array([(*image_size(env, name), 1.0) for name in names], dtype=np.float64).reshape(-1, 3)


def by_ratio(env: Env, rows: np.ndarray, found: np.ndarray, selector: str) -> np.ndarray:
    """The width / height of images against the scope's ratio of the selector's axes."""
    a, b = IMAGE_AXES.get(selector, IMAGE_AXES["xy"])
    scope = env.shapes.size[rows][:, [a, b, b]]
    return ratio_errors(scope, found, ((0, 1),))


@function("imagesSortRatio")
def images_sort_ratio(call, args, env: Env):
    return sort_list(call, args, env, by_ratio, sizes)


@function("imageBestRatio", "imageApproxRatio")
def image_choice(call, args, env: Env):
    return choose(call, args, env, by_ratio, sizes, "best" if call.func == "imageBestRatio" else "approx_or_all")
