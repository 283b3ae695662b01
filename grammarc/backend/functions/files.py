"""File functions: paths of the grammar's roots, chosen and taken apart per shape."""

from __future__ import annotations

from typing import TYPE_CHECKING

from grammarc.backend.functions.table import function
from grammarc.backend.random import uniform

if TYPE_CHECKING:
    from grammarc.backend.env import Env


@function("fileRandom")
def file_random(call, args, env: Env):
    return uniform(env.chunk.lot_key[env.shapes.lot], 0x5F11E)
