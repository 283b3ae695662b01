"""The record's chunks: joined meshes shift their offsets, colours default to white, rows and vertices are
placed by their lots' origins."""

import dataclasses

import numpy as np
import pytest

from grammarc.ir.nodes import MATERIAL_MAPS
from grammarc.model.records import WHITE, LotOrigins, MaterialTable, MeshChunk, TerminalChunk, world_columns


def triangle() -> MeshChunk:
    """One face, a triangle, lot 0, symbol 0, no colour."""
    return MeshChunk(
        vertices=np.zeros((3, 3), np.float32),
        ring_offsets=np.array([0, 3], np.int64),
        face_offsets=np.array([0, 1], np.int64),
        lot=np.array([0], np.int32),
        symbol=np.array([0], np.int32),
    )


def test_concat_shifts_offsets():
    square_with_hole = MeshChunk(
        vertices=np.ones((7, 3), np.float32),
        ring_offsets=np.array([0, 4, 7], np.int64),
        face_offsets=np.array([0, 2], np.int64),
        lot=np.array([1], np.int32),
        symbol=np.array([2], np.int32),
    )
    joined = MeshChunk.concat([triangle(), MeshChunk.empty(), square_with_hole, triangle()])
    assert joined.ring_offsets.tolist() == [0, 3, 7, 10, 13]
    assert joined.face_offsets.tolist() == [0, 1, 3, 4]
    assert joined.lot.tolist() == [0, 1, 0]
    assert joined.vertices.shape == (13, 3)
    empty = MeshChunk.concat([])
    assert empty.ring_offsets.tolist() == [0] and empty.face_offsets.tolist() == [0]


def test_take_selects_faces_with_their_rings_and_vertices():
    holed = MeshChunk(
        vertices=np.arange(21, dtype=np.float32).reshape(7, 3) + 100,
        ring_offsets=np.array([0, 4, 7], np.int64),
        face_offsets=np.array([0, 2], np.int64),
        lot=np.array([1], np.int32),
        symbol=np.array([2], np.int32),
    )
    joined = MeshChunk.concat([triangle(), holed, triangle()])
    taken = joined.take(np.array([1, 0]))
    assert taken.face_offsets.tolist() == [0, 2, 3] and taken.ring_offsets.tolist() == [0, 4, 7, 10]
    np.testing.assert_array_equal(taken.vertices[:7], holed.vertices)
    assert taken.lot.tolist() == [1, 0] and taken.symbol.tolist() == [2, 0]
    assert taken.colors().tolist() == [list(WHITE)] * 2
    none = joined.take(np.zeros(0, np.int64))
    assert none.face_offsets.tolist() == [0] and len(none.vertices) == 0


def test_colours_default_to_white():
    plain = TerminalChunk(asset=np.zeros(3, np.int32), xform=np.zeros((3, 3, 4), np.float32),
                          lot=np.zeros(3, np.int32), symbol=np.zeros(3, np.int32), mesh=triangle())
    assert plain.colors().tolist() == [WHITE.tolist()] * 3 and plain.colors().flags.c_contiguous
    assert plain.mesh.colors().tolist() == [WHITE.tolist()]
    red = np.tile(np.array([[255, 0, 0, 255]], np.uint8), (3, 1))
    assert dataclasses.replace(plain, color=red).colors() is red
    assert MeshChunk.empty().colors().shape == (0, 4)


def textured(chunk: MeshChunk, *colormaps: str) -> MeshChunk:
    """``chunk`` with a table of these colour maps, its faces taking the first."""
    table = np.full((len(colormaps), len(MATERIAL_MAPS)), "", dtype=object)
    table[:, 0] = colormaps
    return dataclasses.replace(chunk, material=np.zeros(len(chunk.lot), np.int32), materials=table.astype(str))


def test_concat_joins_the_tables_of_materials():
    """Each chunk's rows are shifted by the tables before it; a chunk without textures takes none."""
    joined = MeshChunk.concat([textured(triangle(), "a.jpg", "b.jpg"), triangle(), textured(triangle(), "c.jpg")])
    assert joined.materials[:, 0].tolist() == ["a.jpg", "b.jpg", "", "c.jpg"]
    assert joined.material.tolist() == [0, 2, 3]
    assert MeshChunk.concat([triangle(), triangle()]).materials is None


def _lots(lots: list[int], material: list[int], face_lot: int, face_material: int,
          maps: tuple[str, ...]) -> TerminalChunk:
    """Instances of ``lots`` with rows ``material`` of the table ``maps``, and one face of lot ``face_lot``
    with row ``face_material``."""
    n = len(lots)
    mesh = dataclasses.replace(textured(triangle(), *maps), lot=np.array([face_lot], np.int32),
                               material=np.array([face_material], np.int32))
    return TerminalChunk(asset=np.zeros(n, np.int32), xform=np.zeros((n, 3, 4), np.float32),
                         lot=np.array(lots, np.int32), symbol=np.zeros(n, np.int32), mesh=mesh,
                         material=np.array(material, np.int32), materials=mesh.materials)


def test_a_material_table_numbers_the_materials_by_their_first_use():
    """By lot, a lot's instances before its faces, not by the chunk's own table (the order its derivation met
    them): the instances use a.jpg first, the face b.jpg."""
    table = MaterialTable()
    rows, faces = table.add(_lots([0, 0], [1, 0], 0, 0, ("b.jpg", "a.jpg")))
    assert (rows.tolist(), faces.tolist()) == ([1, 2], [2])
    plain = TerminalChunk(asset=np.zeros(2, np.int32), xform=np.zeros((2, 3, 4), np.float32),
                          lot=np.zeros(2, np.int32), symbol=np.zeros(2, np.int32), mesh=triangle())
    assert [r.tolist() for r in table.add(plain)] == [[0, 0], [0]]
    assert table.table()[:, 0].tolist() == ["", "a.jpg", "b.jpg"]


def test_a_material_table_does_not_depend_on_the_chunks():
    """Lot 0's face uses c.jpg, lot 1's instance d.jpg: one chunk of both, whose derivation met d.jpg first,
    numbers them as a chunk per lot does."""
    together = MaterialTable()
    together.add(_lots([1], [0], 0, 1, ("d.jpg", "c.jpg")))
    apart = MaterialTable()
    apart.add(_lots([], [], 0, 0, ("c.jpg",)))
    apart.add(_lots([1], [0], 1, 0, ("d.jpg",)))
    assert together.table()[:, 0].tolist() == apart.table()[:, 0].tolist() == ["", "c.jpg", "d.jpg"]


def test_lot_origins_place_rows_and_vertices_in_world_coordinates():
    origins = LotOrigins.of_lots(np.array([7, 2]), np.array([[5e5, 0, -5.75e6], [1.0, 2.0, 3.0]]))
    assert origins.lot.tolist() == [2, 7]  # ascending, whatever the order given
    xform = np.zeros((2, 3, 4), np.float32)
    xform[:, :, 3] = [[0.25, 0, 0], [0, 0, 0.125]]
    chunk = TerminalChunk(asset=np.zeros(2, np.int32), xform=xform, lot=np.array([7, 2], np.int32),
                          symbol=np.zeros(2, np.int32), mesh=triangle(), origins=origins)
    world = chunk.world_xform()
    assert world.dtype == np.float64
    assert world[:, :, 3].tolist() == [[500000.25, 0, -5750000.0], [1.0, 2.0, 3.125]]
    mesh = dataclasses.replace(triangle(), lot=np.array([7], np.int32))
    assert mesh.world(origins).tolist() == [[5e5, 0, -5.75e6]] * 3
    with pytest.raises(ValueError, match="lot 0 has records but no origin"):
        triangle().world(origins)
    assert TerminalChunk(np.zeros(1, np.int32), xform[:1], np.array([3], np.int32), np.zeros(1, np.int32),
                         triangle()).world_xform()[0, 0, 3] == 0.25  # no origins: world coordinates


def test_lot_origins_round_trip_through_a_records_table():
    a = LotOrigins.of_lots(np.array([0, 3]), np.array([[1.0, 0, 1], [2.0, 0, 2]]))
    b = LotOrigins.of_lots(np.array([3, 5]), np.array([[2.0, 0, 2], [4.0, 0, 4]]))
    table = LotOrigins.concat([a, b]).table()
    assert table.shape == (6, 3) and np.isnan(table[[1, 2, 4]]).all()  # lots without records
    again = LotOrigins.from_table(table)
    assert again.lot.tolist() == [0, 3, 5] and again.origin[:, 0].tolist() == [1.0, 2.0, 4.0]
    assert LotOrigins.from_table(None).lot.size == 0


def test_world_columns_of_a_read_record():
    record = {"xform": np.zeros((1, 3, 4), np.float32), "lot": np.array([1], np.int32),
              "lot_origin": np.array([[np.nan] * 3, [10.0, 0, -20.0]]),
              "mesh_vertices": np.ones((3, 3), np.float32), "mesh_ring_offsets": np.array([0, 3]),
              "mesh_face_offsets": np.array([0, 1]), "mesh_lot": np.array([1], np.int32)}
    xform, vertices = world_columns(record)
    assert xform[0, :, 3].tolist() == [10.0, 0, -20.0]
    assert vertices.tolist() == [[11.0, 1.0, -19.0]] * 3
