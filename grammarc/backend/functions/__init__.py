"""CGA's built-in functions, computed on a batch of shapes, registered by name in one table.

Each is an ordinary function ``f(call, args, env)`` registered with ``@function("name")`` (``table``);
``evaluate`` looks a call up there. Its signature (parameter and result types) is in ``ir.functions``. The
families, as that table groups them:

- ``math``: arithmetic, trigonometry in degrees, ``rand``, ``p``, ``print`` (which gives its value);
- ``strings``: ``str float bool``, ``count find len splitString substring`` and ce.lib's string utilities,
  string concatenation and comparison;
- ``lists``: the ``;``-separated string lists (ce.lib's ``list*``, ``listRandom`` per shape);
- ``files``: searches in the grammar's roots (``fileSearch``, ``fileRandom``...) and paths taken apart;
- ``assets``: an asset's size (``assetInfo``) and assets chosen by how they fit the scope;
- ``images``: an image's resolution (``imageInfo``) and images chosen by their proportions;
- ``tables``: ``readTextFile``, ``readStringTable``, ``readFloatTable`` of the grammar's folders;
- ``colors``: ``colorRamp`` and the conversions between colour strings, RGB and HSV;
- ``coordinates``: ``convert`` between coordinate systems, ``initialShape.name`` and ``startRule``;
- ``geometry``: ``geometry.area``... of the shape's geometry;
- ``texture``: ``geometry.uMin``... of its texture coordinates;
- ``arrays``: CityEngine's arrays.

A new function is its signature, its lowering if it needs one, and its function here: importing this
package registers them.
"""

from grammarc.backend.functions import (  # noqa: F401 - each registers its functions
    arrays,
    assets,
    colors,
    coordinates,
    files,
    geometry,
    images,
    lists,
    math,
    strings,
    tables,
    texture,
)
from grammarc.backend.functions.table import FUNCTIONS

__all__ = ["FUNCTIONS"]
