"""The WKB kernel decodes what shapely decodes, as shapely's ragged arrays, and declines anything else."""

import struct

import numpy as np
import pytest

pa = pytest.importorskip("pyarrow")
import shapely

from grammarc.io.wkb import decode_polygons

SQUARE = shapely.box(0, 0, 10, 10)
HOLED = shapely.Polygon([(0, 0), (20, 0), (20, 20), (0, 20)], [[(5, 5), (5, 8), (8, 8), (8, 5)]])
MULTI = shapely.MultiPolygon([SQUARE, shapely.box(30, 0, 35, 4)])
RAISED = shapely.Polygon([(0, 0, 2.5), (4, 0, 3), (4, 3, 3.5), (0, 0, 2.5)])
#: A ring closed in x and y but not in z, which GEOS reads (it compares x and y only)
TILTED = struct.pack("<BII", 1, 1003, 1) + struct.pack("<I", 4) + struct.pack("<12d", 0, 0, 1, 4, 0, 1, 4, 3, 1, 0, 0, 2)


class Wkb(pa.ExtensionType):
    """geoarrow's WKB type as a file may declare it: an extension over binary."""

    def __init__(self):
        super().__init__(pa.binary(), "geoarrow.wkb")

    def __arrow_ext_serialize__(self):
        return b""

    @classmethod
    def __arrow_ext_deserialize__(cls, storage_type, serialized):
        return cls()


def shapely_arrays(geometries):
    """What the reader made before the kernel: shapely's parts of each row and their ragged arrays, z NaN
    where a row has none."""
    parts, row = shapely.get_parts(geometries, return_index=True)
    _, coords, (ring_offsets, part_offsets) = shapely.to_ragged_array(parts, include_z=True)
    return np.bincount(row, minlength=len(geometries)), coords, ring_offsets, part_offsets


def decoded(values, kind=None):
    return decode_polygons(pa.array(values, type=kind or pa.binary()))


@pytest.mark.parametrize("byte_order", [0, 1])
@pytest.mark.parametrize("flavor", ["iso", "extended"])
def test_rows_decode_as_shapely_reads_them(byte_order, flavor):
    geometries = np.array([SQUARE, HOLED, MULTI, RAISED, shapely.MultiPolygon([RAISED, RAISED])])
    values = shapely.to_wkb(geometries, byte_order=byte_order, flavor=flavor, output_dimension=3)
    result = decoded(list(values))
    parts, coords, ring_offsets, part_offsets = shapely_arrays(geometries)
    assert result.kinds.tolist() == [3, 3, 6, 3, 6]
    assert result.parts.tolist() == parts.tolist() == [1, 1, 2, 1, 2]
    np.testing.assert_array_equal(result.coords, coords)
    np.testing.assert_array_equal(result.ring_offsets, ring_offsets)
    np.testing.assert_array_equal(result.part_offsets, part_offsets)
    assert np.isnan(result.coords[:5, 2]).all() and result.coords[-1, 2] == 2.5


def test_a_ring_closed_in_x_and_y_is_read_as_geos_reads_it():
    result = decoded([TILTED])
    np.testing.assert_array_equal(result.coords, shapely.get_coordinates(shapely.from_wkb(TILTED), include_z=True))


def test_slices_chunks_large_binary_and_extension_storage_decode_alike():
    values = list(shapely.to_wkb(np.array([SQUARE, HOLED, MULTI, SQUARE])))
    whole = decoded(values)
    part = decode_polygons(pa.array(values).slice(1, 2))
    _, coords, ring_offsets, _ = shapely_arrays(np.array([HOLED, MULTI]))
    np.testing.assert_array_equal(part.coords[:, :2], coords[:, :2])
    np.testing.assert_array_equal(part.ring_offsets, ring_offsets)
    for column in (pa.chunked_array([pa.array(values[:1]), pa.array(values[1:3]), pa.array(values[3:])]),
                   pa.array(values, pa.large_binary()), pa.ExtensionArray.from_storage(Wkb(), pa.array(values))):
        again = decode_polygons(column)
        np.testing.assert_array_equal(again.coords, whole.coords)
        np.testing.assert_array_equal(again.ring_offsets, whole.ring_offsets)
        np.testing.assert_array_equal(again.part_offsets, whole.part_offsets)
    assert decode_polygons(pa.array([], pa.binary())).coords.shape == (0, 3)


@pytest.mark.parametrize("value", [
    None,  # a null
    shapely.to_wkb(shapely.Point(1, 2)),  # another type
    shapely.to_wkb(shapely.Polygon()),  # an empty polygon
    struct.pack("<BII", 1, 6, 1) + struct.pack("<BII", 1, 3, 0),  # a multipolygon of an empty polygon
    shapely.to_wkb(SQUARE)[:-3],  # cut short
    shapely.to_wkb(SQUARE) + b"\0",  # bytes left over
    shapely.to_wkb(shapely.set_srid(SQUARE, 4326), include_srid=True),  # an SRID
    struct.pack("<BII", 1, 2003, 1) + struct.pack("<I", 4) + struct.pack("<12d", 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0),
    struct.pack("<BII", 1, 3, 1) + struct.pack("<I", 4) + struct.pack("<8d", 0, 0, 1, 0, 1, 1, 0, 1),  # open
    struct.pack("<BII", 1, 3, 1) + struct.pack("<I", 3) + struct.pack("<6d", 0, 0, 1, 0, 0, 0),  # 3 positions
    b"not wkb",
])
def test_anything_but_plain_polygons_is_declined(value):
    """A measure (ISO 2003), an open ring, a ring of 3 positions are as odd as the rest: shapely reads them."""
    assert decoded([shapely.to_wkb(SQUARE), value]) is None
