"""The record's chunks: what the derivation hands to every writer, a batch of terminals at a time.

A ``TerminalChunk`` holds a batch's instances (an asset and the affine map of its unit box, per row) and,
in a ``MeshChunk``, the leaf polygons that could not be instances (faces with holes). The derivation builds
them, and every writer (the npz record, USD, glTF, the baked meshes) and the renderer take them: they
live on the model floor so that neither side imports the other. Ragged columns follow ``grammarc.ragged``'s
convention (offsets starting at 0).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from grammarc.ir.nodes import MATERIAL_MAPS
from grammarc.ragged import ragged_take

__all__ = ["WHITE", "LotOrigins", "MaterialTable", "MeshChunk", "TerminalChunk", "record_mesh", "world_columns"]

#: Colour of rows that carry none: opaque white (RGBA).
WHITE = np.array([255, 255, 255, 255], np.uint8)


# eq=False: the generated __eq__ would compare arrays elementwise and fail on truth testing.
@dataclass(frozen=True, eq=False)
class LotOrigins:
    """Where each lot's records are placed: ``world = origin of the row's lot + xform @ p`` (float64).

    A record's transforms and mesh vertices are float32, which has steps of 1 mm or less only within 8 km of
    their zero (a float32 step is 0.5 m at a UTM northing of 5.75 million metres). So they are relative
    to their lot's origin, its initial shape's scope origin, kept here in float64: a lot spans metres to
    a few kilometres, and its rows keep sub-millimetre positions wherever it lies on Earth. No origins
    (``empty()``) means the rows are in world coordinates, as in a hand-made chunk.

    Attributes
    ----------
    lot : (k,) int32
        The lots' numbers in the input, ascending.
    origin : (k, 3) float64
        Their origins in world coordinates.
    """

    lot: np.ndarray
    origin: np.ndarray

    @staticmethod
    def empty() -> LotOrigins:
        """No origins: rows are in world coordinates."""
        return LotOrigins(np.zeros(0, np.int32), np.zeros((0, 3)))

    @staticmethod
    def of_lots(lot: np.ndarray, origin: np.ndarray) -> LotOrigins:
        """The origins ``origin`` (k, 3) of lots ``lot`` (k,) in any order."""
        order = np.argsort(lot, kind="stable")
        return LotOrigins(np.asarray(lot, np.int32)[order], np.asarray(origin, np.float64).reshape(-1, 3)[order])

    @staticmethod
    def from_table(table: np.ndarray | None) -> LotOrigins:
        """The origins of a record's ``lot_origin`` table (L, 3), row = lot, NaN for lots without records;
        None (a record written before origins) is ``empty()``."""
        if table is None:
            return LotOrigins.empty()
        table = np.asarray(table, np.float64).reshape(-1, 3)
        lots = np.flatnonzero(np.isfinite(table).all(axis=1)).astype(np.int32)
        return LotOrigins(lots, table[lots])

    @staticmethod
    def concat(parts: Sequence[LotOrigins]) -> LotOrigins:
        """The origins of ``parts`` together (a lot in several parts has the same origin in each)."""
        if not parts:
            return LotOrigins.empty()
        lot, first = np.unique(np.concatenate([p.lot for p in parts]), return_index=True)
        return LotOrigins(lot.astype(np.int32), np.concatenate([p.origin for p in parts])[first])

    def table(self) -> np.ndarray:
        """(L, 3) float64, row = lot, L the highest lot plus one: a record's ``lot_origin``, NaN for lots
        without an origin."""
        out = np.full((int(self.lot[-1]) + 1 if len(self.lot) else 0, 3), np.nan)
        out[self.lot] = self.origin
        return out

    def world_xform(self, xform: np.ndarray, lot: np.ndarray | None) -> np.ndarray:
        """(n, 3, 4) float64: transforms ``xform`` (n, 3, 4) of rows of lots ``lot`` (n,) in world
        coordinates (``lot`` may be None where there are no origins)."""
        out = np.array(xform, np.float64)
        if len(self.lot):
            out[:, :, 3] += self.of(lot)
        return out

    def of(self, lot: np.ndarray) -> np.ndarray:
        """(m, 3) float64: the origins of lots ``lot`` (m,) int; zeros when there are none (``empty()``).

        Raises ``ValueError`` if some lot has none."""
        lot = np.asarray(lot)
        if not len(self.lot):
            return np.zeros((len(lot), 3))
        at = np.minimum(np.searchsorted(self.lot, lot), len(self.lot) - 1)
        if len(lot) and (self.lot[at] != lot).any():
            missing = lot[self.lot[at] != lot][0]
            raise ValueError(f"LotOrigins: lot {int(missing)} has records but no origin")
        return self.origin[at]


@dataclass(frozen=True, eq=False)
class MeshChunk:
    """Leaf polygons that cannot be instances: faces with holes, relative to their lot's origin
    (``LotOrigins``).

    Attributes
    ----------
    vertices : (V, 3) float32
        Ring vertices, ring after ring, relative to the origin of their face's lot.
    ring_offsets : (R+1,) int64
        Ring ``r`` is ``vertices[ring_offsets[r]:ring_offsets[r+1]]`` (Arrow-style, starts at 0).
    face_offsets : (F+1,) int64
        Face ``f`` is rings ``face_offsets[f]:face_offsets[f+1]``: its outline, then its holes.
    lot : (F,) int32
        Lot of each face.
    symbol : (F,) int32
        Symbol of each face, an index into the writer's ``symbols``.
    color : (F, 4) uint8, optional
        RGBA colour of each face (CityEngine's ``color`` and ``material.opacity``); None: white.
    material : (F,) int32, optional
        Each face's row of ``materials``; None (and ``materials`` None) where the grammar sets no texture.
    materials : (M, len(MATERIAL_MAPS)) str, optional
        The texture paths of each material, one column per channel of ``ir.MATERIAL_MAPS`` ("" for none).
    uv : (V, 2) float32, optional
        Texture coordinates of set 0 of each vertex (NaN: its face has none); None: no face has any.
    """

    vertices: np.ndarray
    ring_offsets: np.ndarray
    face_offsets: np.ndarray
    lot: np.ndarray
    symbol: np.ndarray
    color: np.ndarray | None = None
    material: np.ndarray | None = None
    materials: np.ndarray | None = None
    uv: np.ndarray | None = None

    def colors(self) -> np.ndarray:
        """(F, 4) uint8: the faces' colours, white where none was given."""
        if self.color is not None:
            return self.color
        return _white(len(self.lot))

    @staticmethod
    def empty() -> MeshChunk:
        """A chunk without faces: zero-length arrays of the right dtypes, offsets ``[0]``."""
        return MeshChunk(
            vertices=np.zeros((0, 3), np.float32),
            ring_offsets=np.zeros(1, np.int64),
            face_offsets=np.zeros(1, np.int64),
            lot=np.zeros(0, np.int32),
            symbol=np.zeros(0, np.int32),
            color=np.zeros((0, 4), np.uint8),
        )

    @staticmethod
    def concat(chunks: Sequence[MeshChunk]) -> MeshChunk:
        """The faces of ``chunks``, in order, as one chunk whose offsets index the joined arrays."""
        if not chunks:
            return MeshChunk.empty()
        n_vertices = np.array([len(c.vertices) for c in chunks], np.int64)
        n_rings = np.array([len(c.ring_offsets) - 1 for c in chunks], np.int64)
        n_faces = np.array([len(c.face_offsets) - 1 for c in chunks], np.int64)
        return MeshChunk(
            vertices=np.concatenate([c.vertices for c in chunks]),
            ring_offsets=_join_offsets([c.ring_offsets for c in chunks], n_vertices, n_rings),
            face_offsets=_join_offsets([c.face_offsets for c in chunks], n_rings, n_faces),
            lot=np.concatenate([c.lot for c in chunks]),
            symbol=np.concatenate([c.symbol for c in chunks]),
            color=np.concatenate([c.colors() for c in chunks]),
            **_joined_materials(chunks, [c.material for c in chunks], [c.materials for c in chunks]),
            uv=None if all(c.uv is None for c in chunks) else np.concatenate([c.texture() for c in chunks]),
        )

    def vertex_lots(self) -> np.ndarray:
        """(V,) int32: the lot of each vertex (its face's)."""
        return np.repeat(self.lot, np.diff(self.ring_offsets[self.face_offsets]))

    def world(self, origins: LotOrigins) -> np.ndarray:
        """(V, 3) float64: the vertices in world coordinates, their lots' ``origins`` added."""
        vertices = np.asarray(self.vertices, np.float64)
        return vertices + origins.of(self.vertex_lots()) if len(origins.lot) else vertices.copy()

    def texture(self) -> np.ndarray:
        """(V, 2) float32: the vertices' texture coordinates, NaN where none were given."""
        return self.uv if self.uv is not None else np.full((len(self.vertices), 2), np.nan, np.float32)

    def take(self, faces: np.ndarray) -> MeshChunk:
        """The faces numbered ``faces`` (F',) int, in that order, with their rings and vertices; the
        material table stays whole."""
        faces = np.asarray(faces, np.int64)
        rings, face_offsets = ragged_take(self.face_offsets, faces)
        vertices, ring_offsets = ragged_take(self.ring_offsets, rings)
        return MeshChunk(
            vertices=self.vertices[vertices], ring_offsets=ring_offsets, face_offsets=face_offsets,
            lot=self.lot[faces], symbol=self.symbol[faces],
            color=None if self.color is None else self.color[faces],
            material=None if self.material is None else self.material[faces], materials=self.materials,
            uv=None if self.uv is None else self.uv[vertices],
        )


def _joined_materials(chunks: Sequence, material: list, materials: list) -> dict:
    """``material`` and ``materials`` of joined chunks: the tables one after the other, each chunk's rows
    shifted by the tables before it (a chunk without textures gets a table of one material, none)."""
    if all(table is None for table in materials):
        return {}
    blank = np.full((1, len(MATERIAL_MAPS)), "")
    tables = [blank if table is None else table for table in materials]
    bases = np.cumsum([0] + [len(table) for table in tables[:-1]])
    rows = [np.full(len(c.lot), base, np.int32) if m is None else m + np.int32(base)
            for c, m, base in zip(chunks, material, bases)]
    return {"material": np.concatenate(rows).astype(np.int32), "materials": np.concatenate(tables)}


def _join_offsets(offsets: list[np.ndarray], n_items: np.ndarray, n_groups: np.ndarray) -> np.ndarray:
    """Join per-chunk offsets, shifting each chunk's by the items (vertices, rings) of the chunks before it."""
    # n_items [3, 5], n_groups [1, 2]: bases [0, 3], repeated per group [0, 3, 3], added to the offsets
    # without their leading 0: [3] + [2, 5] -> [3, 5, 8], and 0 in front.
    bases = np.cumsum(n_items) - n_items
    tails = np.concatenate([o[1:] for o in offsets]) + np.repeat(bases, n_groups)
    return np.concatenate([np.zeros(1, np.int64), tails])


@dataclass(frozen=True, eq=False)
class TerminalChunk:
    """A batch of terminals: instances of assets, and the leaf polygons that could not be instances.

    Attributes
    ----------
    asset : (n,) int32
        Index into the writer's ``assets``.
    xform : (n, 3, 4) float32
        Affine map from the asset's unit box to its lot's frame: ``world = origin + xform[:, :, :3] @ p +
        xform[:, :, 3]``, ``origin`` the lot's in ``origins``.
    lot : (n,) int32
        Lot (initial shape) of each instance.
    symbol : (n,) int32
        Index into the writer's ``symbols``: the shape's symbol when it became a terminal.
    mesh : MeshChunk
        Faces of this batch that are not instances.
    color : (n, 4) uint8, optional
        RGBA colour of each instance (CityEngine's ``color`` and ``material.opacity``); None: white.
    material : (n,) int32, optional
        Each instance's row of ``materials``; None (and ``materials`` None) where the grammar sets no texture.
    materials : (M, len(MATERIAL_MAPS)) str, optional
        The texture paths of each material (as ``MeshChunk.materials``; the mesh's table is the same).
    origins : LotOrigins
        The origins of the chunk's lots, which its transforms and mesh vertices are relative to; empty:
        they are in world coordinates.
    uv : (n, 2, 4) float32, optional
        Texture coordinates of set 0 of each instance as an affine map of its asset's unit box:
        ``uv = uv[:, :, :3] @ p + uv[:, :, 3]`` (NaN: none); None: no instance has any.
    """

    asset: np.ndarray
    xform: np.ndarray
    lot: np.ndarray
    symbol: np.ndarray
    mesh: MeshChunk
    color: np.ndarray | None = None
    material: np.ndarray | None = None
    materials: np.ndarray | None = None
    uv: np.ndarray | None = None
    origins: LotOrigins = field(default_factory=LotOrigins.empty)

    def colors(self) -> np.ndarray:
        """(n, 4) uint8: the instances' colours, white where none was given."""
        if self.color is not None:
            return self.color
        return _white(len(self.asset))

    def world_xform(self) -> np.ndarray:
        """(n, 3, 4) float64: the transforms in world coordinates, their lots' origins added."""
        return self.origins.world_xform(self.xform, self.lot)

    def texture(self) -> np.ndarray:
        """(n, 2, 4) float32: the instances' texture maps, NaN where none were given."""
        return self.uv if self.uv is not None else np.full((len(self.asset), 2, 4), np.nan, np.float32)


def world_columns(record: Mapping) -> tuple[np.ndarray, np.ndarray]:
    """A record's transforms (N, 3, 4) and mesh vertices (V, 3) in world coordinates, float64: its
    ``lot_origin`` table added (``LotOrigins``; a record without one is in world coordinates already).

    ``record`` is the dict of ``io.npz.read_instances`` (``mesh_vertices``, ``mesh_lot`` and the offsets)
    or of ``build.derive`` (the mesh table as ``"mesh"``, a ``MeshChunk``); either may lack the mesh."""
    origins = LotOrigins.from_table(record.get("lot_origin"))
    xform = origins.world_xform(record.get("xform", np.zeros((0, 3, 4))), record.get("lot"))
    mesh = record_mesh(record)
    return xform, mesh.world(origins) if mesh is not None else np.zeros((0, 3))


def record_mesh(record: Mapping) -> MeshChunk | None:
    """The mesh table of a record (``world_columns``), None without one."""
    if record.get("mesh") is not None or "mesh_face_offsets" not in record:
        return record.get("mesh")
    return MeshChunk(
        vertices=np.asarray(record["mesh_vertices"]).reshape(-1, 3),
        ring_offsets=np.asarray(record["mesh_ring_offsets"], np.int64),
        face_offsets=np.asarray(record["mesh_face_offsets"], np.int64),
        lot=np.asarray(record.get("mesh_lot", np.zeros(0, np.int32))),
        symbol=np.asarray(record.get("mesh_symbol", np.zeros(0, np.int32))),
    )


class MaterialTable:
    """A record's materials (texture paths per channel of ``MATERIAL_MAPS``) numbered as the writer meets
    them, row 0 none: what a writer merges its chunks' own tables into.

    A chunk's own table is in the order its derivation met the materials, which depends on which lots
    share the chunk; the writer numbers them by their first use instead (the lowest lot, its instances
    before its faces, then their order), which is the same however the lots are chunked, as the chunks
    come in the order of their lots and each lot's records are in an order of their own."""

    def __init__(self) -> None:
        self.rows: dict[tuple[str, ...], int] = {("",) * len(MATERIAL_MAPS): 0}

    def add(self, chunk: TerminalChunk) -> tuple[np.ndarray, np.ndarray]:
        """(n,) and (F,) int32: the rows of the chunk's instances and faces in this table (0 without textures)."""
        if chunk.materials is None:
            return np.zeros(len(chunk.asset), np.int32), np.zeros(len(chunk.mesh.lot), np.int32)
        used = np.concatenate([chunk.material, chunk.mesh.material])
        lot = np.concatenate([chunk.lot, chunk.mesh.lot])
        kind = np.repeat(np.array([0, 1], np.int8), [len(chunk.material), len(chunk.mesh.material)])
        order = np.lexsort((np.arange(len(used)), kind, lot))  # rows of each lot in their own order
        first, at = np.unique(used[order], return_index=True)
        lookup = np.zeros(len(chunk.materials), np.int32)
        for row in first[np.argsort(at)]:
            lookup[row] = self.rows.setdefault(tuple(map(str, chunk.materials[row])), len(self.rows))
        return lookup[chunk.material], lookup[chunk.mesh.material]

    def table(self) -> np.ndarray:
        """(M, len(MATERIAL_MAPS)) str: the materials in their order."""
        return np.array(list(self.rows), dtype=str).reshape(-1, len(MATERIAL_MAPS))


_WHITE_ROWS = [np.zeros((0, 4), np.uint8)]


def _white(n: int) -> np.ndarray:
    """(n, 4) opaque white, C-contiguous: a view of one block kept for the chunks that follow, where a
    broadcast white would be copied for every chunk of every writer."""
    if len(_WHITE_ROWS[0]) < n:
        _WHITE_ROWS[0] = np.full((max(n, 2 * len(_WHITE_ROWS[0])), 4), 255, np.uint8)
    return _WHITE_ROWS[0][:n]
