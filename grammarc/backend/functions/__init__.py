"""CGA's built-in functions, computed on a batch of shapes, registered by name in one table.

Each is an ordinary function ``f(call, args, env)`` registered with ``@function("name")`` (``table``);
``evaluate`` looks a call up there. Its signature (parameter and result types) is in ``ir.functions``. The
families, as that table groups them:

- ``math``: arithmetic, trigonometry in degrees, ``rand``, ``p``;
- ``strings``: ``str``, ``float``, ``bool``, ``len``, and string concatenation;
- ``lists``: the ``;``-separated string lists;
- ``files``: ``fileRandom``;
- ``tables``: ``readTextFile``, ``readStringTable``, ``readFloatTable`` of the grammar's folders;
- ``colors``: ``colorRamp`` and the conversions between colour strings, RGB and HSV;
- ``coordinates``: ``convert`` between coordinate systems, ``initialShape.name`` and ``startRule``;
- ``geometry``: ``geometry.area``... of the shape's geometry;
- ``arrays``: CityEngine's arrays.

A new function is its signature, its lowering if it needs one, and its function here: importing this
package registers them.
"""

from grammarc.backend.functions import (  # noqa: F401 - each registers its functions
    arrays,
    colors,
    coordinates,
    files,
    geometry,
    lists,
    math,
    strings,
    tables,
)
from grammarc.backend.functions.table import FUNCTIONS

__all__ = ["FUNCTIONS"]
