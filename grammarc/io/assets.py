"""Temporary re-export: asset names are resolved by ``grammarc.ir.asset_names`` now (the compiler resolves
them, and the IR imports nothing from ``grammarc.io``). Goes when its importers (``io.bake``,
``cluster``, ``tests/io/test_rpk.py``) import from there."""

from grammarc.ir.asset_names import (
    BUILTINS,
    CYLINDER_SIDES_RANGE,
    LEAF_CUBE,
    LEAF_QUAD,
    ResolvedAsset,
    builtin_name,
    resolve_asset,
)

__all__ = ["BUILTINS", "CYLINDER_SIDES_RANGE", "LEAF_CUBE", "LEAF_QUAD", "ResolvedAsset", "builtin_name",
           "resolve_asset"]
