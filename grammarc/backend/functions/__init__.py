"""CGA's built-in functions, computed on a batch of shapes, registered by name in one table.

Each is an ordinary function ``f(call, args, env)`` registered with ``@function("name")`` (``table``);
``evaluate`` looks a call up there. Its signature (parameter and result types) is in ``ir.functions``. The
families, as that table groups them:

- ``math``: arithmetic, trigonometry in degrees, ``rand``, ``p``;
- ``strings``: ``str float bool``, ``count find len splitString substring`` and ce.lib's string utilities,
  string concatenation and comparison;
- ``lists``: the ``;``-separated string lists (ce.lib's ``list*``, ``listRandom`` per shape);
- ``files``: ``fileRandom``;
- ``geometry``: ``geometry.area``... of the shape's geometry;
- ``arrays``: CityEngine's arrays.

A new function is its signature, its lowering if it needs one, and its function here: importing this
package registers them.
"""

from grammarc.backend.functions import (  # noqa: F401 - each registers its functions
    arrays,
    files,
    geometry,
    lists,
    math,
    strings,
)
from grammarc.backend.functions.table import FUNCTIONS

__all__ = ["FUNCTIONS"]
