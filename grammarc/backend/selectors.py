"""Component selectors as CityEngine reads them: which faces (by their normals) and edges (by their
directions) ``front``, ``top``, ``vertical``, ``aslant``... name.

Normals are in the parent's scope frame (front +z, back -z, right +x, left -x, top +y, bottom -y), or in the
lot's (``object.``) or the world's (``world.``) when a selector names that frame.
"""

from __future__ import annotations

import numpy as np

#: A face is "top" or "bottom" when its normal is within 45 degrees of the scope's y axis; "horizontal"
#: and "vertical" within this tolerance of exactly so.
_FLAT_TOLERANCE = 1e-6


def classify_faces(normal: np.ndarray, selectors: tuple[str, ...], frames: dict | None = None) -> np.ndarray:
    """Index of the first selector each face matches (len(selectors) for none), from normals (m, 3) in
    the parent's scope frame: front +z, back -z, right +x, left -x, top +y, bottom -y. ``frames`` gives
    the normals in the lot's frame (``object.`` selectors) and the world's (``world.``)."""
    which = np.full(len(normal), len(selectors), dtype=np.int64)
    for i in range(len(selectors) - 1, -1, -1):
        prefix, _, name = selectors[i].rpartition(".")
        which[_face_masks((frames or {}).get(prefix, normal))[name]] = i
    return which


def _face_masks(normal: np.ndarray) -> dict[str, np.ndarray]:
    x, y, z = normal[:, 0], normal[:, 1], normal[:, 2]
    top, bottom = y > np.sqrt(0.5), y < -np.sqrt(0.5)
    side = ~top & ~bottom
    front = side & (z >= np.abs(x))
    back = side & (-z >= np.abs(x)) & ~front
    right = side & (x > np.abs(z))
    left = side & (-x > np.abs(z))
    vertical = np.abs(y) <= _FLAT_TOLERANCE
    horizontal = np.abs(y) >= 1 - _FLAT_TOLERANCE
    masks = {
        "front": front, "back": back, "left": left, "right": right, "top": top, "bottom": bottom,
        "side": side, "vertical": vertical, "horizontal": horizontal,
        "aslant": ~vertical & ~horizontal & (y > 0), "nutant": ~vertical & ~horizontal & (y < 0),
        "all": np.ones(len(normal), dtype=bool),
        # the faces an offset makes: a shape not offset has none
        "inside": np.zeros(len(normal), dtype=bool), "border": np.zeros(len(normal), dtype=bool),
    }
    return masks


def classify_edges(direction: np.ndarray | None, selectors: tuple[str, ...], n: int) -> np.ndarray:
    """Index of the first selector each edge (or vertex, ``direction`` None) matches: an edge is
    vertical along the world's y axis, horizontal across it, aslant otherwise."""
    masks = {"all": np.ones(n, dtype=bool)}
    if direction is not None:
        y = np.abs(direction[:, 1])
        masks.update(vertical=y >= 1 - _FLAT_TOLERANCE, horizontal=y <= _FLAT_TOLERANCE,
                     aslant=(y > _FLAT_TOLERANCE) & (y < 1 - _FLAT_TOLERANCE))
    which = np.full(n, len(selectors), dtype=np.int64)
    for i in range(len(selectors) - 1, -1, -1):
        which[masks[selectors[i]]] = i
    return which
