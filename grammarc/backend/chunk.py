"""The state of deriving one chunk of lots: frame table, polygon store, lot columns, outputs, counters.

Everything a chunk creates lives here and is dropped with it, so memory is bounded by the chunk.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from grammarc.backend.choices import Choices
from grammarc.backend.kernels.scope import turned_frames
from grammarc.backend.kernels.turns import distinct_turns
from grammarc.backend.occlusion import Occluders, OccluderStore
from grammarc.backend.snaps import SnapStore
from grammarc.constants import STRICT
from grammarc.geometry.meshes import MeshStore
from grammarc.geometry.polygons import PolygonStore
from grammarc.geometry.streets import Streets


class Table:
    """Growable table of float64 rows of one shape; a row's id (int32) is its number, and shapes hold ids so
    that they share rows instead of copying them."""

    def __init__(self, data: np.ndarray, count: int) -> None:
        self.data = data
        self.count = count

    def add(self, rows: np.ndarray) -> np.ndarray:
        """Append ``rows`` (m, *row shape); returns their ids (m,) int32."""
        m = len(rows)
        if self.count + m > len(self.data):
            grown = np.empty((max(2 * len(self.data), self.count + m), *self.data.shape[1:]))
            grown[: self.count] = self.data[: self.count]
            self.data = grown
        self.data[self.count: self.count + m] = rows
        ids = np.arange(self.count, self.count + m, dtype=np.int32)
        self.count += m
        return ids

    def __getitem__(self, ids: np.ndarray) -> np.ndarray:
        """The rows ``ids``, each copied as one block by ``np.take`` (``data[ids]`` copies them element by
        element, several times slower on rows this short)."""
        return self.data.take(ids, axis=0)


class Frames(Table):
    """Table of scope axes (F, 3, 3); row j of a frame is scope axis j in world."""

    def __init__(self, capacity: int = 256) -> None:
        super().__init__(np.empty((capacity, 3, 3)), 0)

    def add(self, axes: np.ndarray) -> np.ndarray:
        """Append frames (m, 3, 3); returns their ids (m,) int32."""
        if STRICT and len(axes):
            # frames stay orthonormal and right-handed through rotations and component splits
            gram = np.einsum("mij,mkj->mik", axes, axes)
            assert np.allclose(gram, np.eye(3), atol=1e-9), "a scope frame is not orthonormal"
            assert np.allclose(np.linalg.det(axes), 1.0, atol=1e-9), "a scope frame is left-handed"
        return super().add(axes)

    def turned(self, local_axes: np.ndarray, frame: np.ndarray,
               local: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The frames ``local_axes[local] @ self[frame]``, their ids (m,) int32 and axes (m, 3, 3): turn c
        gives the axes ``local_axes[local[c]]`` (``local`` None: ``local_axes[c]``), rows in the frame
        ``frame[c]``. Turns of the same frame id by the same axes (the same face of every window's box in
        a facade's frame) share one new row, computed and stored once (``kernels.turns``)."""
        local_axes = np.ascontiguousarray(local_axes, dtype=np.float64)
        local = None if local is None else np.asarray(local, dtype=np.int64)
        first, which = distinct_turns(frame, local_axes, local)
        if len(first) == len(frame):  # every turn its own (``first`` is every turn, in order)
            axes = turned_frames(local_axes if local is None else local_axes[local], self.data, frame)
            return self.add(axes), axes
        axes = turned_frames(local_axes[first if local is None else local[first]], self.data, frame[first])
        return self.add(axes)[which], np.take(axes, which, axis=0)


class TextureMaps(Table):
    """Table of texture maps (M, 2, 4), affine maps from world coordinates to (u, v)
    (``backend.texture_space``); map 0 is NaN, no texture coordinates. Shapes hold map ids, as they hold
    frame ids: children share their parent's maps, and most operations keep them."""

    def __init__(self, capacity: int = 64) -> None:
        super().__init__(np.full((capacity, 2, 4), np.nan), 1)


class TrimPlanes(Table):
    """Table of shapes' trim planes (P, width) (``slots.TRIM_PLANES``): (nx, ny, nz, d) per plane, the two
    vertical ones first; row 0 is NaN, no planes. A ``comp(f)`` adds a row per face it gives planes, and
    whatever that face becomes shares it, as shapes share frames."""

    def __init__(self, width: int, capacity: int = 256) -> None:
        super().__init__(np.full((capacity, width), np.nan), 1)


@dataclass
class Outputs:
    """Terminal rows and leaf meshes of a chunk, as lists of arrays concatenated at the end.

    Rows come in pieces of one asset and one symbol (``terminals.append_records``): ``asset`` and
    ``symbol`` hold a piece's ids, not a column, which ``derive.collect`` writes once, in sorted order.
    """

    asset: list = field(default_factory=list)
    xform: list = field(default_factory=list)
    lot: list = field(default_factory=list)
    symbol: list = field(default_factory=list)
    meshes: list = field(default_factory=list)
    #: (n, 4) uint8 colours beside ``asset``, when the grammar sets colours.
    color: list = field(default_factory=list)
    #: (n, k) int32 texture channel ids beside ``asset`` and (F, k) beside each of ``meshes``, when the
    #: grammar carries texture channels (``backend.materials``).
    material: list = field(default_factory=list)
    mesh_material: list = field(default_factory=list)
    #: (n, 2, 4) float32 texture maps beside ``asset``, when the grammar has texture coordinates of set 0.
    uv: list = field(default_factory=list)
    #: ``report`` rows: (lot, key ids, values, kind) per call.
    reports: list = field(default_factory=list)


@dataclass
class Chunk:
    """One chunk of lots being derived, made whole by ``derive.initial_chunk``.

    ``lot_index`` (L,) int64 numbers the lots in the input (for records and random keys), ``lot_ids``
    (L,) their identifiers, ``lot_key`` (L,) uint64 their root random keys (``fileRandom`` draws from them),
    ``attrs`` the per-lot attribute columns (L,) after overrides (evaluated into it in dependency order, as
    a default may read the attributes before it), ``lot_origin`` (L, 3) and ``lot_axes`` (L, 3, 3) the
    lots' own scopes (``Scope.tx`` is relative to them; the records are, too: ``model.records.LotOrigins``),
    ``streets`` their street edges and street frames
    (``geometry.streets``). The stores, outputs and counters grow as the derivation goes.
    """

    lot_index: np.ndarray
    lot_ids: np.ndarray
    lot_key: np.ndarray
    attrs: dict[str, np.ndarray]
    lot_origin: np.ndarray
    lot_axes: np.ndarray
    streets: Streets
    frames: Frames
    polygons: PolygonStore
    #: The occluders of every lot from a first pass (``inter`` queries), when there was one.
    foreign: Occluders | None = None
    #: The lots' initial shapes' size (L, 3), frame (L,) and geom (L,), with ``lot_origin``:
    #: what ``resetGeometry`` goes back to.
    lot_shapes: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
    outputs: Outputs = field(default_factory=Outputs)
    meshes: MeshStore = field(default_factory=MeshStore)
    #: Occluders made so far (``backend.occlusion``).
    occluders: OccluderStore = field(default_factory=OccluderStore)
    #: Snap planes of the paper's ``Snap`` / ``SnapLines`` (``backend.snaps``).
    snaps: SnapStore = field(default_factory=SnapStore)
    #: Texture maps the shapes' texture columns name (``backend.texture_space``).
    texture_maps: TextureMaps = field(default_factory=TextureMaps)
    #: Trim planes the shapes' ``slots.TRIM_PLANES`` name (``Plan.trim_width`` wide: ``derive.derive_chunk``
    #: sets it up where the grammar has them).
    trim_planes: TrimPlanes | None = None
    #: A search's fixed choices, one state per lot (``backend.choices``); None in a build.
    choices: Choices | None = None
    #: Shapes created so far per lot, for the ``max_shapes`` limit, and in all.
    shape_count: np.ndarray = field(init=False)
    shape_total: int = field(init=False, default=0)

    def __post_init__(self) -> None:
        self.shape_count = np.zeros(len(self.lot_index), dtype=np.int64)
