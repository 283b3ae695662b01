"""CityEngine's string lists: strings of ``;``-separated items (``"a;b;c;"``), per shape."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend.functions.table import distinct, function

if TYPE_CHECKING:
    from grammarc.backend.env import Env


@function("listItem")
def list_item(call, args, env: Env):
    """``listItem(list, index)``: item ``index`` of the list ("" out of range)."""
    strings = env.plan.strings
    names = list(strings.ids)

    def item(text: int, i: float) -> int:
        parts = names[text].split(";")
        k = int(np.floor(i)) if np.isfinite(i) else -1
        return strings.intern(parts[k] if 0 <= k < len(parts) else "")
    return distinct(item, args[0], args[1], dtype=np.int32)
