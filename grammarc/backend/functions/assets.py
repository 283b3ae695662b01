"""Asset functions: an asset's size, and assets chosen from a search by how well they fit the scope.

``assetInfo(asset, sx|sy|sz|tx|ty|tz)`` is the size of the asset's bounding box in its own units, or its
lowest corner (CGA reference: the translation is the corner with the lowest x, y and z), read once per
distinct asset from ``AssetMesh.bounds``; an asset that cannot be found or read gives 0, as CityEngine
gives 0 with a warning in its log.

The choosers follow the reference's ``ce.lib``, which builds them on two sorts:

* ``assetsSortSize(list, axes, maxScaleError)`` orders the list's assets by the scaling the scope would
  put on them along ``axes`` (``x y z xy xz yz xyz``): the largest ``|scope / asset - 1|`` over those
  axes, best first; a ``maxScaleError`` above 0 keeps only the assets within it (0.1: at most 10 %);
* ``assetsSortRatio(list, axes)`` by how far their proportions are from the scope's along ``axes``
  (``xy xz yz xyz``): ``|log(asset ratio / scope ratio)|``, the largest over the pairs of ``xyz``.

Ties keep the list's order (a search's list is sorted by name); an asset that cannot be read, or is flat
along an axis the scope is not, sorts last. ``assetBestSize(query, axes)`` is the first of the sorted
search, ``assetApproxSize(query, axes, n)`` one of its first ``n`` drawn from the shape's stream (none
for ``n`` < 1: ``""``), ``assetFitSize(query, axes, maxScaleError)`` one of those within the error (any
when it is 0), ``assetBestRatio`` and ``assetApproxRatio`` the same by ratio. A selector the reference
does not list sorts as ``xyz``, as the ``ce.lib`` does.

Everything per shape is numpy over a (shapes, candidates) table of errors, per distinct query and
selector; the sorted lists are made once per distinct order.

``assetNamingInfo(asset, g|m)`` lists an OBJ asset's group (``g``) or material (``usemtl``) names in the
order they first appear; ``assetNamingInfos`` as a ``str[]``. Other formats list none.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend.functions.files import found, pick, roots, string_list
from grammarc.backend.functions.strings import string_arrays
from grammarc.backend.functions.table import distinct, function, groups
from grammarc.errors import AssetError
from grammarc.ir.asset_names import resolve_asset

if TYPE_CHECKING:
    from grammarc.backend.env import Env

#: ``assetInfo``'s selectors: (row of ``AssetMesh.bounds`` or -1 for the extent, axis).
INFO = {"sx": (-1, 0), "sy": (-1, 1), "sz": (-1, 2), "tx": (0, 0), "ty": (0, 1), "tz": (0, 2)}
#: Axes compared by size, and pairs of axes compared by ratio; the last entry is the default.
SIZE_AXES = {"x": (0,), "y": (1,), "z": (2,), "xy": (0, 1), "xz": (0, 2), "yz": (1, 2), "xyz": (0, 1, 2)}
RATIO_AXES = {"xy": ((0, 1),), "xz": ((0, 2),), "yz": ((1, 2),), "xyz": ((0, 1), (0, 2), (1, 2))}


def bounds(env: Env, name: str) -> np.ndarray | None:
    """(2, 3) float64 the asset's bounding box in its own units, None when it cannot be loaded."""
    try:
        return env.plan.load_asset(name, roots(env)).bounds
    except AssetError:
        return None


@function("assetInfo")
def asset_info(call, args, env: Env):
    names = list(env.plan.strings.ids)

    def info(asset: int, query: int) -> float:
        box = bounds(env, names[asset])
        if names[query] not in INFO:
            return np.nan
        row, axis = INFO[names[query]]
        if box is None:
            return 0.0
        return float(box[1, axis] - box[0, axis]) if row < 0 else float(box[row, axis])
    return distinct(info, args[0], args[1])


def extents(env: Env, names) -> np.ndarray:
    """(c, 3) float64 the sizes of assets ``names``; NaN where one cannot be loaded."""
    boxes = [bounds(env, name) for name in names]
    return np.array([b[1] - b[0] if b is not None else [np.nan] * 3 for b in boxes], dtype=np.float64).reshape(-1, 3)


def size_errors(scope: np.ndarray, sizes: np.ndarray, axes: tuple[int, ...]) -> np.ndarray:
    """(k, c) the largest ``|scope / asset - 1|`` over ``axes`` of scopes (k, 3) and assets (c, 3); an
    axis flat in both costs nothing, an unreadable asset is infinitely bad."""
    a = np.asarray(axes)
    target, own = scope[:, None, a], sizes[None, :, a]
    with np.errstate(divide="ignore", invalid="ignore"):
        error = np.abs(target / own - 1.0)
    error = np.where((own == 0) & (target == 0), 0.0, error)
    return np.nan_to_num(error, nan=np.inf).max(axis=2)


def ratio_errors(scope: np.ndarray, sizes: np.ndarray, pairs) -> np.ndarray:
    """(k, c) the largest ``|log(asset ratio / scope ratio)|`` over the axis ``pairs`` of scopes (k, 3)
    and assets or images (c, 3); undefined ratios are infinitely bad."""
    with np.errstate(divide="ignore", invalid="ignore"):
        logs = [np.abs(np.log(sizes[None, :, a] / sizes[None, :, b]) - np.log(scope[:, a, None] / scope[:, b, None]))
                for a, b in pairs]
    return np.nan_to_num(np.max(logs, axis=0), nan=np.inf, posinf=np.inf)


def ranked(errors: np.ndarray, ids: np.ndarray, keep: np.ndarray | None = None) -> np.ndarray:
    """(k, c) int32 the candidate ids of each shape from best to worst (stable: ties keep the list's
    order), -1 where ``keep`` (k, c) over the ranks drops them."""
    order = np.argsort(errors, axis=1, kind="stable")
    chosen = ids[order]
    return chosen if keep is None else np.where(keep, chosen, -1)


def fitting(errors: np.ndarray, bound: np.ndarray) -> np.ndarray:
    """(k, c) over the ranks of ``errors`` (k, c): those within ``bound`` (k, 1), all where it is 0."""
    return (bound <= 0) | (np.sort(errors, axis=1) <= bound)


#: ``errors(env, rows, sizes, selector)``: (k, c) how badly each candidate fits the scopes of shapes ``rows``.
Errors = Callable[..., np.ndarray]


def by_size(env: Env, rows: np.ndarray, sizes: np.ndarray, selector: str) -> np.ndarray:
    return size_errors(env.shapes.size[rows], sizes, SIZE_AXES.get(selector, SIZE_AXES["xyz"]))


def by_ratio(env: Env, rows: np.ndarray, sizes: np.ndarray, selector: str) -> np.ndarray:
    return ratio_errors(env.shapes.size[rows], sizes, RATIO_AXES.get(selector, RATIO_AXES["xyz"]))


def sort_list(call, args, env: Env, errors: Errors, measure: Callable, within=None) -> np.ndarray:
    """A string list per shape (a ``;`` list in ``args[0]``) sorted by ``errors``: (n,) int32 ids, each
    distinct order made once. ``measure(env, names)`` gives the candidates' (c, 3) sizes; ``within`` (n,)
    a largest error kept (0: all)."""
    strings = env.plan.strings
    texts = list(strings.ids)
    n = len(env.shapes)
    out = np.empty(n, dtype=np.int32)
    for (items, selector), rows in groups(n, args[0], args[1]):
        names = [name for name in texts[items].split(";") if name]
        errors_ = errors(env, rows, measure(env, names), texts[selector])
        keep = None
        if within is not None:
            keep = fitting(errors_, np.broadcast_to(np.asarray(within, dtype=np.float64), (n,))[rows, None])
        orders = ranked(errors_, np.arange(len(names)), keep)
        unique, inverse = np.unique(orders, axis=0, return_inverse=True)
        lists = np.array([strings.intern(string_list([names[i] for i in row if i >= 0]) if (row >= 0).any()
                                         else "") for row in unique], dtype=np.int32)
        out[rows] = lists[inverse.reshape(-1)]
    return out


def choose(call, args, env: Env, errors: Errors, measure: Callable, mode: str) -> np.ndarray:
    """One file per shape from the search ``args[0]`` ranked by ``errors`` under selector ``args[1]``:
    ``best`` the first, ``approx`` one of the first ``args[2]``, ``all`` one of any, ``fit`` one within
    the error ``args[2]``, ``approx_or_all`` as ``approx`` but any when ``args[2]`` < 1 (images)."""
    n = len(env.shapes)
    texts = list(env.plan.strings.ids)
    third = np.broadcast_to(np.asarray(args[2] if len(args) > 2 else 1.0, dtype=np.float64), (n,))

    def choices(key: tuple[int, int], rows: np.ndarray) -> np.ndarray:
        names = found(env, key[0])
        ids = np.array([env.plan.strings.intern(name) for name in names], dtype=np.int32)
        errors_ = errors(env, rows, measure(env, names), texts[key[1]])
        rank = np.arange(len(names))[None, :]
        value = third[rows, None]
        if mode == "best":
            keep = rank < 1
        elif mode == "fit":
            keep = fitting(errors_, value)
        else:  # the first floor(n), or for images all of them when n < 1
            count = np.floor(np.nan_to_num(value, nan=0.0))
            keep = (rank < count) | ((count < 1) & (mode == "approx_or_all"))
        return ranked(errors_, ids, keep)
    return pick(choices, [args[0], args[1]], call, env)


@function("assetsSortSize")
def assets_sort_size(call, args, env: Env):
    return sort_list(call, args, env, by_size, extents, within=args[2])


@function("assetsSortRatio")
def assets_sort_ratio(call, args, env: Env):
    return sort_list(call, args, env, by_ratio, extents)


#: The choosers: how they rank the search's assets, and which of them they draw from (``choose``).
CHOOSERS = {"assetBestSize": (by_size, "best"), "assetApproxSize": (by_size, "approx"),
            "assetFitSize": (by_size, "fit"), "assetBestRatio": (by_ratio, "best"),
            "assetApproxRatio": (by_ratio, "approx")}


@function(*CHOOSERS)
def asset_choice(call, args, env: Env):
    errors, mode = CHOOSERS[call.func]
    return choose(call, args, env, errors, extents, mode)


def naming(env: Env, name: str, selector: str) -> tuple[str, ...]:
    """The group (``g``) or material (``m``) names of an OBJ asset, in order of first appearance."""
    resolved = resolve_asset(name, list(roots(env)))
    if resolved.path is None or resolved.path.suffix.lower() != ".obj" or selector not in ("g", "m"):
        return ()
    return _obj_names(resolved.path, resolved.path.stat().st_mtime_ns, "g" if selector == "g" else "usemtl")


@lru_cache(maxsize=64)
def _obj_names(path: Path, mtime_ns: int, keyword: str) -> tuple[str, ...]:
    names: dict[str, None] = {}
    with path.open(encoding="utf-8", errors="replace") as lines:
        for line in lines:
            head, _, rest = line.strip().partition(" ")
            if head == keyword and rest.strip():
                names.setdefault(rest.strip(), None)
    return tuple(names)


@function("assetNamingInfo")
def asset_naming_info(call, args, env: Env):
    strings = env.plan.strings
    texts = list(strings.ids)
    return distinct(lambda asset, selector: strings.intern(
        "".join(f"{name};" for name in naming(env, texts[asset], texts[selector]))), args[0], args[1], dtype=np.int32)


@function("assetNamingInfos")
def asset_naming_infos(call, args, env: Env):
    texts = list(env.plan.strings.ids)
    return string_arrays(env, lambda asset, selector: naming(env, texts[asset], texts[selector]), args[0], args[1])
