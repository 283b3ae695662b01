"""Component selectors as CityEngine reads them: which faces (by their normals) and edges (by their
directions) ``front``, ``top``, ``vertical``, ``aslant``... name, which edges of a roof ``eave``, ``ridge``,
``hip`` and ``valley`` name (``geometry.meshes.roof_edge_kinds``), and which component an index ``3`` or an
index expression ``n + 1`` takes (``index_masks``).

Normals are in the parent's scope frame (front +z, back -z, right +x, left -x, top +y, bottom -y), or in the
lot's (``object.``), the world's (``world.``) or the lot's street frame (``street.``, ``geometry.streets``)
when a selector names that frame (``selector_frames`` turns them into it); ``street.front`` also takes the
faces and edges that lie along a street (``street_along``); ``world.south``... are CityEngine's compass names of ``world.``
selectors (``ir.WORLD_COMPASS``). ``streetSide`` and ``noStreetSide``, CityEngine's older names, are
``street.front`` and the other side edges of lots with street edges, and nothing on other lots (PRT's
reporting.rpk sets nothing back on the kit's footprints, which have none); ``street.`` selectors fall
back to the lot's own frame there, as CityEngine documents.
"""

from __future__ import annotations

import numpy as np

from grammarc.geometry.streets import along_street
from grammarc.ir.nodes import ROOF_EDGE_SELECTORS, WORLD_COMPASS
from grammarc.ragged import rank_within

#: A face is "top" or "bottom" when its normal is within 45 degrees of the scope's y axis; "horizontal"
#: and "vertical" within this tolerance of exactly so.
_FLAT_TOLERANCE = 1e-6


def classify_faces(normal: np.ndarray, selectors: tuple[str, ...], frames: dict | None = None,
                   picked: dict[str, np.ndarray] | None = None) -> np.ndarray:
    """Index of the first selector each face matches (len(selectors) for none), from normals (m, 3) in
    the parent's scope frame: front +z, back -z, right +x, left -x, top +y, bottom -y. ``frames`` gives
    the normals in the lot's frame (``object.`` selectors) and the world's (``world.``); ``picked`` the
    faces of the index selectors (``index_masks``)."""
    which = np.full(len(normal), len(selectors), dtype=np.int64)
    frames = frames or {}
    for i in range(len(selectors) - 1, -1, -1):
        if picked and selectors[i] in picked:
            which[picked[selectors[i]]] = i
            continue
        named = WORLD_COMPASS.get(selectors[i]) or STREET_ALIASES.get(selectors[i], selectors[i])
        prefix, _, name = named.rpartition(".")
        mask = _face_masks(frames.get(prefix, normal), frames.get(f"{prefix}_along"))[name]
        if selectors[i] in STREET_ALIASES:  # PRT: nothing on a lot without street edges
            mask = mask & frames["street_known"]
        which[mask] = i
    return which


#: CityEngine's older street selectors of ``setback``.
STREET_ALIASES = {"streetSide": "street.front", "noStreetSide": "street.rest"}


def _face_masks(normal: np.ndarray, along: np.ndarray | None = None) -> dict[str, np.ndarray]:
    x, y, z = normal[:, 0], normal[:, 1], normal[:, 2]
    top, bottom = y > np.sqrt(0.5), y < -np.sqrt(0.5)
    side = ~top & ~bottom
    front = side & (z >= np.abs(x))
    back = side & (-z >= np.abs(x)) & ~front
    right = side & (x > np.abs(z))
    left = side & (-x > np.abs(z))
    if along is not None:  # lying along a street makes a side front, whichever way the frame turns
        front, back, right, left = front | (side & along), back & ~along, right & ~along, left & ~along
    vertical = np.abs(y) <= _FLAT_TOLERANCE
    horizontal = np.abs(y) >= 1 - _FLAT_TOLERANCE
    masks = {
        "front": front, "back": back, "left": left, "right": right, "top": top, "bottom": bottom,
        "side": side, "rest": side & ~front, "vertical": vertical, "horizontal": horizontal,
        "aslant": ~vertical & ~horizontal & (y > 0), "nutant": ~vertical & ~horizontal & (y < 0),
        "all": np.ones(len(normal), dtype=bool),
        # the faces of an offset (or of a shape's border: ``component_splits``); here none
        "inside": np.zeros(len(normal), dtype=bool), "border": np.zeros(len(normal), dtype=bool),
    }
    return masks


def classify_edges(direction: np.ndarray | None, selectors: tuple[str, ...], n: int,
                   picked: dict[str, np.ndarray] | None = None, roof: np.ndarray | None = None) -> np.ndarray:
    """Index of the first selector each edge (or vertex, ``direction`` None) matches: an edge is
    vertical along the world's y axis, horizontal across it, aslant otherwise; ``picked`` gives the
    components of the index selectors (``index_masks``); ``roof`` (n,) each edge's place on a roof, an
    index into ``ir.ROOF_EDGE_SELECTORS`` or -1 (``geometry.meshes.roof_edge_kinds``)."""
    masks = {"all": np.ones(n, dtype=bool), **(picked or {})}
    if direction is not None:
        y = np.abs(direction[:, 1])
        masks.update(vertical=y >= 1 - _FLAT_TOLERANCE, horizontal=y <= _FLAT_TOLERANCE,
                     aslant=(y > _FLAT_TOLERANCE) & (y < 1 - _FLAT_TOLERANCE))
        roof = np.full(n, -1) if roof is None else roof
        masks.update({name: roof == k for k, name in enumerate(ROOF_EDGE_SELECTORS)})
    which = np.full(n, len(selectors), dtype=np.int64)
    for i in range(len(selectors) - 1, -1, -1):
        which[masks[selectors[i]]] = i
    return which


def index_masks(selectors: tuple[str, ...], parent: np.ndarray, picks: list[np.ndarray]) -> dict[str, np.ndarray]:
    """The components (m,) bool that each index selector takes: ``"3"`` the component numbered 3 among its
    shape's (``parent`` (m,), in the order the split makes them: an extrusion's bottom 0, its sides along
    the footprint's edges, its top last, as CityEngine numbers them), ``"#k"`` the one numbered
    ``picks[k]`` (n,) float64 for its shape, rounded (a value that is no component's number takes none)."""
    indexed = [s for s in selectors if s.isdigit() or s.startswith("#")]
    if not indexed:
        return {}
    index = rank_within(parent)
    return {s: index == (int(s) if s.isdigit() else np.round(picks[int(s[1:])][parent])) for s in indexed}


def selector_frames(chunk, normal: np.ndarray, shapes, parent: np.ndarray, selectors,
                    base: tuple[np.ndarray, np.ndarray] | None = None) -> dict | None:
    """Normals (m, 3) of components of ``shapes`` rows ``parent`` (m,) in the world's, the lot's and its
    street's frames when a selector names them (``world.``, ``object.``, ``street.``), and which components
    lie along a street: their base edges ``base`` (start, end: (m, 3) world points), if given, on one of
    their lot's street edges. None when no selector names a frame."""
    if not any("." in s or s in STREET_ALIASES for s in selectors):
        return None
    world = np.einsum("mi,mij->mj", normal, chunk.frames[shapes.frame][parent])
    lot = shapes.lot[parent]
    frames = {"world": world, "object": np.einsum("mj,mij->mi", world, chunk.lot_axes[lot])}
    streets = chunk.streets
    if any(s.startswith("street.") or s in STREET_ALIASES for s in selectors):
        frames["street"] = np.einsum("mj,mij->mi", world, streets.axes[lot])
        frames["street_along"] = (along_street(streets, lot, base[0], base[1], world) if base is not None
                                  else np.zeros(len(lot), dtype=bool))
        frames["street_known"] = np.diff(streets.lot_offsets)[lot] > 0
    return frames
