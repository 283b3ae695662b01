"""What every lots format shares: a builder that collects lots while a file is parsed, then cleans, orients
and validates them all at once; GeoJSON features to lots; property columns; street flags.

The format modules (``io.geojson``, ``io.geojson_sequence``, ``io.obj_lots``, ``io.arrow_lots``) parse
their files into a ``LotBuilder``, a lot or a block of lots at a time; ``LotBuilder.finish`` then runs
over all lots at once: numpy and kernels over the ragged arrays, and shapely's vectorized predicates on
the array of polygons of the lots that may be bad (not plainly convex, or near the least area). Python
loops only where parsing needs them (over JSON features) and over the bad lots' messages. A bad lot is
listed with its number, its id and a reason (``grammarc.model.lots.BadLot``), and the other lots load.

Conventions, those of CityEngine and Esri PRT:

- Map to world: world x = map x, world y = the lot's base height, world z = -map y (north is -z): the
  base is the lowest z of the lot's vertices where the file gives them (a 3D GeoJSON, a footprint draped
  on terrain: the building stands on its lowest corner, its lot flat), else 0. In metres: lots in
  longitude/latitude are reprojected first (``io.crs``: the coordinate system the file declares, a
  format's default, the user's ``--lots-crs`` and ``--crs``).
- The exterior ring of a lot has a +Y Newell normal (counter-clockwise on the map, as RFC 7946 wants),
  holes a -Y normal. A ring wound the other way is reversed keeping its first vertex first
  (v0, v_{n-1}, ..., v1): the first edge v0 -> v1 is the lot's scope x axis downstream.
- Rings are open (the first vertex is not repeated); edges shorter than ``TOL.merge`` (0.8 mm) collapse
  as in PRT (``geometry.short_edges``), and lots with less area than ``TOL.area_floor`` are bad.
"""

from __future__ import annotations

import json
import numbers
import re
from dataclasses import replace

import numpy as np
import shapely
from numba import njit

from grammarc.constants import TOL
from grammarc.errors import LotsError
from grammarc.geometry.short_edges import collapse_short_edges
from grammarc.io.crs import georeference
from grammarc.io.lot_format import NO_OPTIONS, LotsOptions
from grammarc.model.lots import BadLot, Lots
from grammarc.ragged import offsets_from_counts, segment_reduce

__all__ = [
    "STREET_WIDTH", "LotBuilder", "id_text", "parse_features", "property_column", "property_columns", "street_flags",
]

#: The lot property that marks street edges, as CityEngine's object attribute.
STREET_WIDTH = "streetWidth"
# GEOS reasons end with the offending point, e.g. "Self-intersection[3 4.5]".
_GEOS_REASON = re.compile(r"^(?P<what>.*)\[(?P<x>\S+) (?P<y>\S+)\]$")


class LotBuilder:
    """Collects lots while a file is parsed; ``finish`` cleans, orients and validates them all at once.

    Rings are (k, 3) float64 world coordinates if ``world``, else (k, 2) or (k, 3) float64 map coordinates
    (x, y and an elevation z, NaN where a position has none). A format
    sets ``declared``, the coordinate system its file names, and ``implied``, its default where the file names
    none (``io.crs``).
    """

    def __init__(self, world: bool):
        self.world = world
        self.declared: str | None = None
        self.implied: str | None = None
        self.rings: list[np.ndarray] = []  # rings, or a block of rings (``add_block``)
        self.sizes = _Column(np.int64)  # vertices per ring
        self.ring_counts = _Column(np.int64)  # rings per lot
        self.index = _Column(np.int64)
        self.ids = _Column(object)
        self.props: list[dict] = []
        self.vertices = 0  # positions added so far
        #: (first position, flags) of the lots or blocks that have street edges: a flag per position, its
        #: edge faces a street
        self.street: list[tuple[int, np.ndarray]] = []
        self.bad: list[BadLot] = []
        self.polygons = 0  # lots added or rejected; a file without any has "no polygon"
        self.end = 0  # lot numbers the parsed features took (GeoJSON)
        self.queued: list[tuple] = []  # lots of map positions not converted yet (``add_positions``)

    def reject(self, index: int, lot_id: str, reason: str) -> None:
        """A polygon that is bad before any geometry check (malformed, empty)."""
        self.polygons += 1
        self.bad.append(BadLot(index, lot_id, reason))

    def add(self, index: int, lot_id: str, rings: list[np.ndarray], props: dict) -> None:
        """Add a lot: its exterior ring, then its holes. A ``streetWidth`` property (CityEngine's: a
        number per edge of the exterior ring, > 0 where a street runs) marks its street edges."""
        self._convert()  # lots come in order
        self._add(index, lot_id, rings if self.world else [_with_z(ring) for ring in rings], props)

    def _add(self, index: int, lot_id: str, rings: list[np.ndarray], props: dict) -> None:
        """``add`` of rings already (k, 3): world positions, or map positions with their elevation."""
        if not rings:
            self.reject(index, lot_id, "empty polygon")
            return
        widths = props.get(STREET_WIDTH)
        if widths is not None:
            flags = street_flags(widths, rings[0])
            if isinstance(flags, str):
                self.reject(index, lot_id, flags)
                return
            self.street.append((self.vertices, flags))
            props = {name: value for name, value in props.items() if name != STREET_WIDTH}
        self.polygons += 1
        self.rings.extend(rings)
        sizes = [len(ring) for ring in rings]
        self.sizes.extend(sizes)
        self.vertices += sum(sizes)
        self.ring_counts.append(len(rings))
        self.index.append(index)
        self.ids.append(lot_id)
        self.props.append(props)

    def add_block(self, index: np.ndarray, ids: list[str], vertices: np.ndarray, sizes: np.ndarray,
                  ring_counts: np.ndarray, street: np.ndarray) -> None:
        """Add many lots at once from columns (a columnar file): ``vertices`` of all their rings,
        ``sizes`` vertices per ring, ``ring_counts`` rings per lot, ``street`` a flag per vertex. Their
        properties are not kept here: the caller passes them to ``finish`` as columns."""
        self._convert()
        self.polygons += len(ids)
        self.street.append((self.vertices, street))
        self._add_rings(vertices if self.world else _with_z(vertices), sizes)
        self.ring_counts.add_block(ring_counts)
        self.index.add_block(index)
        self.ids.add_block(ids)

    def _add_rings(self, vertices: np.ndarray, sizes) -> None:
        """The rings of lots added as one block: all their vertices (V, 3), and vertices per ring."""
        self.rings.append(vertices)
        self.sizes.add_block(sizes)
        self.vertices += len(vertices)

    def add_positions(self, index: int, lot_id: str, rings, props: dict) -> None:
        """Add a lot given as lists of map positions (GeoJSON): x, y and an optional elevation; further
        components are ignored. Lots are queued and their positions made into one array per
        ``POSITION_BATCH`` lots (``_convert``), rather than an array per ring."""
        self.queued.append((index, lot_id, rings, props))
        if len(self.queued) >= POSITION_BATCH:
            self._convert()

    def _convert(self) -> None:
        """Add the queued lots: all their positions in one conversion, when they are all alike (numbers,
        two or more per position, the same number of them); else lot by lot, ring by ring."""
        if not self.queued:  # lots added otherwise (``add``, ``add_block``) queue nothing
            return
        queued, self.queued = self.queued, []
        flat: list = []
        offsets = [0]
        try:
            for _, _, rings, _ in queued:
                for ring in rings:
                    flat.extend(ring)
                    offsets.append(len(flat))
            positions = np.array(flat, dtype=np.float64) if flat else np.zeros((0, 3))
        except (TypeError, ValueError):
            positions = None
        if positions is None or positions.ndim != 2 or positions.shape[1] < 2:
            for entry in queued:
                self._add_one(*entry)
            return
        xyz = _with_z(positions[:, :3])
        if all(rings and STREET_WIDTH not in props for _, _, rings, props in queued):
            # lots with rings and no street edges (most files): added as one block, as ``_add`` adds each
            self.polygons += len(queued)
            self._add_rings(xyz, np.diff(offsets))
            for index, lot_id, rings, props in queued:
                self.ring_counts.append(len(rings))
                self.index.append(index)
                self.ids.append(lot_id)
                self.props.append(props)
            return
        k = 0
        for index, lot_id, rings, props in queued:
            self._add(index, lot_id, [xyz[offsets[j]:offsets[j + 1]] for j in range(k, k + len(rings))], props)
            k += len(rings)

    def _add_one(self, index: int, lot_id: str, rings, props: dict) -> None:
        """``add_positions`` of one lot, ring by ring (positions of mixed length; malformed ones)."""
        try:
            xyz = [_ring_xyz(ring) for ring in rings]
        except (TypeError, ValueError, IndexError):
            self.reject(index, lot_id, "malformed coordinates")
            return
        self._add(index, lot_id, xyz, props)

    def finish(self, attrs: dict[str, np.ndarray], source: str, options: LotsOptions = NO_OPTIONS) -> Lots:
        """Bring every lot to metres (``io.crs.georeference``, as the user's ``options`` ask), then clean,
        orient and validate them all at once; ``attrs`` are columns over all added lots."""
        self._convert()
        counts, ring_counts = self.sizes.array(), self.ring_counts.array()
        vertices = np.concatenate([np.zeros((0, 3)), *self.rings])
        xy = np.column_stack([vertices[:, 0], np.subtract(0.0, vertices[:, 2])]) if self.world else vertices[:, :2]
        lot_counts = np.add.reduceat(counts, offsets_from_counts(ring_counts)[:-1]) if len(counts) else counts
        beyond = _beyond_the_earth(vertices, lot_counts)
        if beyond.any():  # points at 0 that _validate rejects with their reason; the CRS is judged without them
            on_earth = ~np.repeat(beyond, lot_counts)
            moved, crs_name, note = georeference(xy[on_earth], lot_counts[~beyond], self.declared, self.implied,
                                                 options, source)
            vertices, xy = np.where(on_earth[:, None], vertices, 0.0), np.zeros_like(moved, shape=xy.shape)
            xy[on_earth] = moved
        else:
            xy, crs_name, note = georeference(xy, lot_counts, self.declared, self.implied, options, source)
        if not self.world or note is not None:
            # world (x, height, -y); 0.0 - y keeps z = +0.0 where y = 0
            x, y = xy.T
            height = vertices[:, 1] if self.world else _base_heights(vertices[:, 2], lot_counts)
            vertices = np.column_stack([x, height, np.subtract(0.0, y)])
        # edges shorter than TOL.merge collapse as PRT collapses them (geometry.short_edges)
        order, kept, owner = collapse_short_edges(vertices, offsets_from_counts(counts), TOL.merge)
        vertices, ring_offsets = vertices[order], offsets_from_counts(kept)
        given = np.zeros(self.vertices, dtype=bool)
        for start, flags in self.street:
            given[start:start + len(flags)] = flags
        street = np.zeros(len(vertices), dtype=bool)
        if given.any():  # most files mark no street edge
            np.logical_or.at(street, owner, given)
        lot_offsets = offsets_from_counts(ring_counts)
        normals = _newell(vertices, ring_offsets)
        exterior = np.zeros(len(normals), dtype=bool)
        exterior[lot_offsets[:-1]] = True
        vertex_order, edge_order = _orient(ring_offsets, exterior, normals[:, 1])
        vertices, street = vertices[vertex_order], street[edge_order]
        lots = Lots(
            ids=self.ids.array(),
            index=self.index.array(),
            vertices=vertices,
            ring_offsets=ring_offsets,
            lot_offsets=lot_offsets,
            street=street,
            attrs=attrs,
            bad=(),
            source=source,
            crs=crs_name,
            crs_note=note,
        )
        reasons = _validate(lots, normals, self.world, options.min_area, beyond)
        rejected = np.flatnonzero(reasons != "")
        bad = self.bad + [BadLot(int(lots.index[i]), lots.ids[i], reasons[i]) for i in rejected]
        good = lots.take(np.flatnonzero(reasons == "")) if len(rejected) else lots  # a copy only to drop some
        return replace(good, bad=tuple(sorted(bad, key=lambda b: b.index)))

    def finish_file(self, attrs: dict[str, np.ndarray], path, options: LotsOptions = NO_OPTIONS) -> Lots:
        """``finish`` for a whole lots file, which must hold a polygon (a good or a bad one)."""
        self._convert()
        if self.polygons == 0:
            raise LotsError(f"no polygon in lots file {path}")
        return self.finish(attrs, str(path), options)


class _Column:
    """A column of the builder, grown a value at a time (GeoJSON's lots) or a block at a time (a columnar
    file's): values wait in a list, blocks stay arrays, so a block of 10^5 lots is not made into Python
    objects and back."""

    def __init__(self, dtype):
        self.dtype = dtype
        self._blocks: list[np.ndarray] = []
        self._values: list = []

    def append(self, value) -> None:
        self._values.append(value)

    def extend(self, values) -> None:
        self._values.extend(values)

    def add_block(self, values) -> None:
        self._flush()
        self._blocks.append(np.asarray(values, dtype=self.dtype))

    def array(self) -> np.ndarray:
        """Every value so far, in order."""
        self._flush()
        return self._blocks[0] if len(self._blocks) == 1 else np.concatenate([np.zeros(0, self.dtype), *self._blocks])

    def _flush(self) -> None:
        if self._values:
            block = np.empty(len(self._values), dtype=self.dtype)  # objects stay objects, whatever they are
            block[:] = self._values
            self._blocks.append(block)
            self._values = []


def street_flags(widths, ring: np.ndarray) -> np.ndarray | str:
    """Where a ring's edges face a street, from a ``streetWidth`` value.

    Parameters
    ----------
    widths : object
      The value: a list of one number per edge, > 0 where the edge faces a street.
    ring : (k, 2) or (k, 3) float64
      The exterior ring's positions; a ring given closed has one edge fewer than positions.

    Returns
    -------
    flags : (k,) bool or str
      Per position, whether its edge faces a street (False at a closing position); or why ``widths``
      does not fit the ring, the bad lot's reason.
    """
    if not isinstance(widths, list) or not all(isinstance(w, numbers.Real) for w in widths):
        return f"{STREET_WIDTH} is not a list of numbers"
    closed = len(ring) > 1 and np.array_equal(ring[0], ring[-1], equal_nan=True)
    edges = len(ring) - 1 if closed else len(ring)
    if len(widths) != edges:
        return f"{STREET_WIDTH} has {len(widths)} values for {edges} edges"
    return np.r_[np.asarray(widths, dtype=np.float64) > 0, np.zeros(int(closed), dtype=bool)]


def _ring_xyz(ring) -> np.ndarray:
    """A ring's positions as (k, 3) float64: x, y and the elevation, NaN where a position has none."""
    try:
        array = np.asarray(ring, dtype=np.float64)
    except ValueError:  # positions of mixed length, e.g. some with an elevation
        array = np.array([[*position[:3], *[np.nan] * (3 - len(position[:3]))] for position in ring],
                         dtype=np.float64)
    if array.size == 0:
        return np.zeros((0, 3))
    if array.ndim != 2 or array.shape[1] < 2:
        raise ValueError("a ring is a list of positions")
    return _with_z(array[:, :3])


def _with_z(ring: np.ndarray) -> np.ndarray:
    """Map positions (k, 2) or (k, 3) as (k, 3), the elevation NaN where there is none."""
    ring = np.asarray(ring, dtype=np.float64)
    if ring.shape[1] == 3:
        return ring
    out = np.empty((len(ring), 3))
    out[:, :2] = ring
    out[:, 2] = np.nan
    return out


def _base_heights(z: np.ndarray, lot_counts: np.ndarray) -> np.ndarray:
    """(V,) float64: each vertex's lot's base height, the lowest elevation ``z`` (V,) of the lot's vertices
    (``lot_counts`` (L,) of them each), 0 where it has none."""
    if not len(z) or np.isnan(z).all():
        return np.zeros(len(z))
    has = lot_counts > 0  # a lot may have no vertex (an empty ring): reduceat cannot start past the end
    lowest = np.fmin.reduceat(z, offsets_from_counts(lot_counts)[:-1][has])  # fmin: NaN only where all are
    return np.repeat(np.nan_to_num(lowest, nan=0.0), lot_counts[has])


def _feature_id(feature: dict, props: dict, index: int, id_field: str | None) -> str:
    for value in (props.get(id_field),) if id_field is not None else \
            (feature.get("id"), props.get("id"), props.get("name")):
        if value is not None:
            return id_text(value)
    return str(index)


def id_text(value) -> str:
    """A lot id as text: a whole number stored as a float (an ``osm_id`` column of a GIS file) without its
    ``.0``, so that a file's ids are the same in every format."""
    return str(int(value)) if isinstance(value, float) and value.is_integer() else str(value)


def parse_features(features, first_index: int = 0, id_field: str | None = None) -> LotBuilder:
    """The lots of GeoJSON features, whose first polygon is number ``first_index`` of its file (a
    partition of a GeoJSON sequence starts where the polygons before it end).

    A Polygon is one lot and a MultiPolygon one lot per polygon (ids ``"<feature id>:<k>"``, each with
    the feature's properties); other geometries are bad lots. A lot's id is its property ``id_field``
    where one is given (``--id-field``), else the feature's ``id``, else its property ``id``, else
    ``name``; without any, its number. The builder's ``end`` is the count of lot numbers
    the features took, its ``props`` the properties of its lots (``property_columns``).
    """
    builder = LotBuilder(world=False)
    index = first_index
    for feature in features:
        if not isinstance(feature, dict):
            continue
        props = feature.get("properties") if isinstance(feature.get("properties"), dict) else {}
        geometry = feature.get("geometry") if isinstance(feature.get("geometry"), dict) else {}
        kind = geometry.get("type")
        lot_id = _feature_id(feature, props, index, id_field)
        if kind == "Polygon":
            builder.add_positions(index, lot_id, geometry.get("coordinates") or [], props)
            index += 1
        elif kind == "MultiPolygon" and not geometry.get("coordinates"):
            builder.reject(index, lot_id, "empty polygon")
            index += 1
        elif kind == "MultiPolygon":
            for k, rings in enumerate(geometry["coordinates"]):
                builder.add_positions(index, f"{lot_id}:{k}", rings or [], props)
                index += 1
        else:
            builder.bad.append(BadLot(index, lot_id, f"not a polygon ({kind or 'null geometry'})"))
            index += 1
    builder.end = index - first_index
    builder._convert()  # the last lots, whose properties the caller reads
    return builder


#: Lots of GeoJSON positions converted together (``LotBuilder.add_positions``).
POSITION_BATCH = 4096

#: The types of a property column that is numbers as it is (``bool`` is not ``int`` here).
_PLAIN_NUMBERS = {int, float, type(None)}


def property_column(values: list) -> np.ndarray:
    """One property column, typed over all its values.

    Returns
    -------
    column : (n,) float64 or object
      float64 with nan for None if every value is a number or None, else object: ``str`` values as they
      are, None kept, anything else as its JSON text (booleans ``true`` and ``false``: a boolean is no
      number, and an attribute of numbers given one makes its lot bad, ``backend.attributes``).
    """
    if set(map(type, values)) <= _PLAIN_NUMBERS:  # what JSON gives: one pass in C, None is nan
        return np.array(values, dtype=np.float64)
    if all(v is None or (isinstance(v, numbers.Real) and not isinstance(v, bool)) for v in values):
        return np.array([np.nan if v is None else float(v) for v in values], dtype=np.float64)
    column = np.empty(len(values), dtype=object)
    column[:] = [v if v is None or isinstance(v, str) else json.dumps(v.item() if isinstance(v, np.generic) else v)
                 for v in values]
    return column


def property_columns(props: list[dict]) -> dict[str, np.ndarray]:
    """Per-lot property dicts as columns (``property_column``), named in first-seen order."""
    names = dict.fromkeys(name for p in props for name in p)
    return {name: property_column([p.get(name) for p in props]) for name in names}


# ------------------------------------------------------------------------------------- ragged kernels


@njit(cache=True, nogil=True)
def _newell(vertices, ring_offsets):
    """(R, 3) float64 Newell normals, twice the vector area; ``normal[:, 1]`` = 2 x the map signed area.

    Each vertex is taken relative to its ring's first, so large world coordinates lose no precision; one
    pass over the vertices (numpy's took five temporaries of every vertex, a fifth of reading a city's
    lots)."""
    normals = np.zeros((len(ring_offsets) - 1, 3))
    for r in range(len(ring_offsets) - 1):
        start, stop = ring_offsets[r], ring_offsets[r + 1]
        for i in range(start, stop):
            j = i + 1 if i + 1 < stop else start
            a0, a1, a2 = (vertices[i, 0] - vertices[start, 0], vertices[i, 1] - vertices[start, 1],
                          vertices[i, 2] - vertices[start, 2])
            b0, b1, b2 = (vertices[j, 0] - vertices[start, 0], vertices[j, 1] - vertices[start, 1],
                          vertices[j, 2] - vertices[start, 2])
            normals[r, 0] += a1 * b2 - a2 * b1
            normals[r, 1] += a2 * b0 - a0 * b2
            normals[r, 2] += a0 * b1 - a1 * b0
    return normals


@njit(cache=True, nogil=True)
def _orient(ring_offsets, exterior, normal_y):
    """Reverse exterior rings with a -Y normal and holes with a +Y one, keeping each ring's first vertex:
    where each vertex and each edge (from its vertex to the next) comes from, (V,) int64 each.

    A reversed ring of n vertices takes position p from position (n - p) % n: v0, v_{n-1}, ..., v1; its
    edge p is the old edge (n - p - 1) % n run backwards.
    """
    vertex_order = np.empty(ring_offsets[-1], dtype=np.int64)
    edge_order = np.empty(ring_offsets[-1], dtype=np.int64)
    for r in range(len(ring_offsets) - 1):
        start, n = ring_offsets[r], ring_offsets[r + 1] - ring_offsets[r]
        flip = normal_y[r] < 0 if exterior[r] else normal_y[r] > 0
        for p in range(n):
            vertex_order[start + p] = start + ((n - p) % n if flip else p)
            edge_order[start + p] = start + ((n - p - 1) % n if flip else p)
    return vertex_order, edge_order


def _beyond_the_earth(vertices: np.ndarray, lot_counts: np.ndarray) -> np.ndarray:
    """(L,) bool: the lots with a coordinate that is not finite or beyond ``TOL.coordinate`` (an elevation
    may be NaN: a position without one)."""
    return _beyond(vertices, lot_counts, TOL.coordinate)


@njit(cache=True, nogil=True)
def _beyond(vertices, lot_counts, limit):
    """``_beyond_the_earth`` in one pass over the vertices, none after a lot's first that is beyond."""
    beyond = np.zeros(len(lot_counts), dtype=np.bool_)
    start = 0
    for lot in range(len(lot_counts)):
        for i in range(start, start + lot_counts[lot]):
            # not (|v| <= limit) holds for NaN too; a NaN elevation is none, an infinite one is beyond
            if not (abs(vertices[i, 0]) <= limit and abs(vertices[i, 1]) <= limit) or abs(vertices[i, 2]) > limit:
                beyond[lot] = True
                break
        start += lot_counts[lot]
    return beyond


def _validate(lots: Lots, normals: np.ndarray, world: bool, min_area: float | None,
              beyond: np.ndarray) -> np.ndarray:
    """(L,) object: why each lot is bad, "" for a good lot; the first failed check gives the reason (a lot of
    less area than ``min_area``, ``--min-area``, is a sliver; ``beyond`` (L,) bool marks the lots with a
    coordinate that is no place on Earth)."""
    reasons = np.full(len(lots), "", dtype=object)
    reasons[beyond] = f"a coordinate is not finite or beyond {TOL.coordinate:g}"
    short_ring = (np.diff(lots.ring_offsets) < 3).astype(np.int64)
    short = segment_reduce(np.add, short_ring, lots.lot_offsets, 0) > 0
    reasons[short & (reasons == "")] = "fewer than 3 distinct vertices"
    norm = np.linalg.norm(normals, axis=1)
    wall_ring = (norm >= 2 * TOL.area_floor) & (np.abs(normals[:, 1]) < 0.5 * norm)
    wall = segment_reduce(np.add, wall_ring.astype(np.int64), lots.lot_offsets, 0) > 0
    reasons[wall & (reasons == "")] = "not a footprint: face normal is not vertical"

    candidates = np.flatnonzero(reasons == "")
    # GEOS is asked only about the lots that may be bad: not those that are plainly convex (so valid) and of
    # plainly more area than the least a lot may have (Newell's area within a thousandth of it is asked)
    least = TOL.area_floor if min_area is None else max(TOL.area_floor, min_area)
    convex = _plainly_convex(lots)[candidates]
    plain = convex & (np.abs(normals[lots.lot_offsets[:-1][candidates], 1]) / 2 > least * 1.001)
    asked, convex = candidates[~plain], convex[~plain]
    polygons = _map_polygons(lots.take(asked))
    why = np.full(len(asked), "Valid Geometry", dtype=object)
    why[~convex] = shapely.is_valid_reason(polygons[~convex])
    valid = why == "Valid Geometry"
    area = shapely.area(polygons)
    # a symmetric bowtie has zero area too; only a polygon whose convex hull is flat is "zero area"
    small = area < TOL.area_floor
    flat = np.zeros(len(asked), dtype=bool)
    flat[small] = shapely.area(shapely.convex_hull(polygons[small])) < TOL.area_floor
    zero = flat | (small & valid)
    reasons[asked[zero]] = "zero area"
    invalid = ~valid & ~zero
    reasons[asked[invalid]] = [_geos_reason(text, world) for text in why[invalid]]
    if min_area is not None:
        sliver = np.flatnonzero((area < min_area) & (reasons[asked] == ""))
        reasons[asked[sliver]] = [f"area {a:.3g} m2 under --min-area {min_area:g}" for a in area[sliver]]
    return reasons


def _plainly_convex(lots: Lots) -> np.ndarray:
    """(L,) bool: the lots without holes that turn left at every vertex, and plainly so (by more than a
    billionth of their edges' lengths), once around. Such a polygon is convex, so simple: GEOS would find
    it valid, and is asked only about the others (a city's lots are mostly such; its check of every lot
    was a fifth of the time it took to read a GeoParquet file)."""
    one_ring = np.diff(lots.lot_offsets) == 1
    convex = np.zeros(len(lots), dtype=bool)
    convex[one_ring] = _convex_rings(np.ascontiguousarray(lots.vertices),
                                     lots.ring_offsets)[lots.lot_offsets[:-1][one_ring]]
    return convex


@njit(cache=True, nogil=True)
def _convex_rings(vertices, ring_offsets):
    """(R,) bool: the rings (world vertices (V, 3), map x and y = x and -z) that turn plainly left at every
    vertex, their turns adding up to one turn around (a ring that winds twice adds up to two)."""
    convex = np.zeros(len(ring_offsets) - 1, dtype=np.bool_)
    for r in range(len(ring_offsets) - 1):
        start, n = ring_offsets[r], ring_offsets[r + 1] - ring_offsets[r]
        turning = 0.0
        left = n >= 3
        for k in range(n if left else 0):
            a, b, c = start + (k + n - 1) % n, start + k, start + (k + 1) % n
            x0, y0 = vertices[b, 0] - vertices[a, 0], vertices[a, 2] - vertices[b, 2]
            x1, y1 = vertices[c, 0] - vertices[b, 0], vertices[b, 2] - vertices[c, 2]
            cross = x0 * y1 - y0 * x1
            if not cross > 1e-9 * np.hypot(x0, y0) * np.hypot(x1, y1):  # NaN is not left either
                left = False
                break
            turning += np.arctan2(cross, x0 * x1 + y0 * y1)
        convex[r] = left and turning < 3 * np.pi
    return convex


def _map_polygons(lots: Lots) -> np.ndarray:
    """(L,) shapely Polygons in map coordinates (x, -z), rings closed as GeoArrow requires."""
    xy = np.column_stack([lots.vertices[:, 0], -lots.vertices[:, 2]])
    closed = np.insert(xy, lots.ring_offsets[1:], xy[lots.ring_offsets[:-1]], axis=0)
    ring_offsets = lots.ring_offsets + np.arange(len(lots.ring_offsets))
    offsets = (ring_offsets, lots.lot_offsets)
    return shapely.from_ragged_array(shapely.GeometryType.POLYGON, closed, offsets)


def _geos_reason(text: str, world: bool) -> str:
    """'Self-intersection[3 4.5]' -> 'self-intersection at (3.0, 4.5)' in the input's coordinates."""
    match = _GEOS_REASON.match(text)
    if match is None:
        return text[:1].lower() + text[1:]
    what, x, y = match["what"], float(match["x"]), float(match["y"])
    where = f"x={x}, z={0.0 - y}" if world else f"({x}, {y})"
    return f"{what[:1].lower()}{what[1:]} at {where}"
