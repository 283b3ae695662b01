"""Where PRT starts the rings of the pieces a clip, an offset or a setback makes (``clip.fit_pieces``).

CityEngine keeps a polygon's vertex order through splits, offsets and setbacks: a piece's first edge is
the one a later per-edge operation (``setbackPerEdge``, massing's tiers of ``listItem`` distances, a
``comp(f)``'s scope x) numbers 0. Each piece vertex is placed on its parent's boundary, or on the parent
edge it was moved in from (``places``), and each ring is turned to start where PRT starts it; the rules
(``ring_starts`` and the helpers after it) were each measured through PyPRT on designed lots and on the
differential harness's cases, which their docstrings name.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from grammarc.constants import TOL


@njit(cache=True, nogil=True)
def ring_starts(coords, ring_offsets, part_offsets, part_source, part_with_start, cut, part_inset,
                start_edges, moves, parent_coords, parent_rings, parent_offsets):
    """Each ring of each piece turned to start where CityEngine's clipping and offsets start it.

    Every piece vertex gets its place along the parent's boundary: i for the parent's vertex i (ring
    after ring), i + f for a point a fraction f along the edge from vertex i to vertex i + 1 (a cut's
    crossing); but in pieces moved in (not ``cut``) a vertex whose outgoing edge was moved in from parent
    edge i (an offset's, a setback's: parallel to it, in the same direction, the nearest such,
    ``places``) gets i; one inside with neither gets the place of the nearest parent vertex.

    CityEngine keeps a polygon's vertex order through offsets, setbacks and cuts: a setback's remainder
    starts at the edge moved in from the first parent edge that is left, or at that edge's end vertex
    where the remainder keeps it (its strip steps back to it, or ends at a reflex corner there); an inset (an offset's,
    ``part_inset``) where the first outer parent edge that is left ends, counting from the last: at
    vertex 0's mitre where the last edge and edge 0 are left. Where the offset took the last edge (and
    vertex 0 with it) the inset starts at the end of edge 0 (PRT on massing's H and L lots whose arms an
    offset closed), where it took edge 0 at the start of edge 1, and where holes grown into the outline
    cut the last edge off from the next one, at the end of the last edge (PRT on massing's holes.7039;
    a setback's remainder there keeps the first rule: H.7006); of an inset a hole parts in pieces, only
    the run along the last edge that ends nearest vertex 0 counts from the last, and the other pieces
    start where their first outer edge left ends (``_last_edge_ends``). PRT (measured through PyPRT on some 700
    pieces of convex and concave lots cut by ``split``) starts the outline of a piece on a side of the cut that holds the
    parent's vertex 0 or 1 (``part_with_start``) at its first place: vertex 0 itself, or the crossing
    where the boundary enters it; where the cut runs through a hole, with its first cut edge into the hole
    (measured through PyPRT on a lot whose hole massing's footprint split crosses). A piece on another side starts with its cut edge: at its last place
    on the parent's outer ring, the crossing where that ring leaves it. Holes start at their first
    place. Where ``start_edges`` (per parent vertex, empty for none) marks edges, an outer ring that runs
    along some of them starts at the first place among its vertices that do. ``moves`` (per parent
    vertex, empty for none known): how far each parent edge was moved in (``places``). Returns the
    coords (V, 2) with every ring turned.
    """
    out = np.empty_like(coords)
    material = material_sides(parent_coords, parent_rings, parent_offsets)
    # each vertex's key (its place) and the parent edge its outgoing edge runs along or came from
    keys = np.empty(len(coords))
    marked = np.zeros(len(coords), np.bool_)
    moved_from = np.full(len(coords), np.inf)
    ties = np.zeros(len(coords))
    moved_in = np.zeros(len(coords), np.bool_)
    at_vertex = np.zeros(len(coords), np.bool_)
    corner = np.full(len(coords), -1, np.int64)  # the parent vertex each lies at, -1 for none
    runs_along = np.full(len(coords), -1, np.int64)  # the parent edge its outgoing edge runs along, -1 for none
    for p in range(len(part_offsets) - 1):
        g = part_source[p]
        for r in range(part_offsets[p], part_offsets[p + 1]):
            r0, r1 = ring_offsets[r], ring_offsets[r + 1]
            n = r1 - r0
            for j in range(r0, r1):
                k = r0 + (j - r0 + 1) % n
                near, key, vertex_key, scale, edge, away, along = places(
                    coords[j, 0], coords[j, 1], coords[k, 0], coords[k, 1], g, parent_coords,
                    parent_rings, parent_offsets, material, moves)
                if cut:
                    edge = np.inf  # a cut's crossings keep their places: their chords run along no edge
                moved_from[j] = edge
                tolerance = 1e-6 * max(scale, 1.0) ** 0.5
                if np.isfinite(edge) and away <= tolerance and len(start_edges):
                    marked[j] = start_edges[parent_rings[parent_offsets[g]] + int(edge)]
                at_vertex[j] = near <= tolerance * tolerance and key == np.floor(key)
                if at_vertex[j]:
                    corner[j] = int(key)
                if np.isfinite(edge) and away <= tolerance:
                    runs_along[j] = int(edge)
                if np.isfinite(edge) and away > tolerance:
                    moved_in[j] = True
                    keys[j] = edge  # its outgoing edge was moved in from that edge (an offset, a setback)
                    # of two moved in from one edge (a hole across the strip parted it), the one that starts
                    # nearer the edge's start first
                    ties[j] = along
                elif near <= tolerance * tolerance:
                    keys[j] = key  # on the boundary: a kept vertex, a cut's crossing
                else:
                    keys[j] = vertex_key
            if not cut and not part_inset[p]:
                outer = parent_rings[parent_offsets[g] + 1] - parent_rings[parent_offsets[g]]
                _after_steps(keys, moved_from, moved_in, r0, r1, outer)
                _runs_into_kept_vertices(keys, corner, runs_along, moved_in, r0, r1, outer)
    last_end = _last_edge_ends(coords, ring_offsets, part_offsets, part_source, part_inset, moved_from,
                               parent_coords, parent_rings, parent_offsets)
    for p in range(len(part_offsets) - 1):
        g = part_source[p]
        outer = parent_rings[parent_offsets[g] + 1] - parent_rings[parent_offsets[g]]
        ring = parent_coords[parent_rings[parent_offsets[g]]:]  # (the parent's outer ring first)
        for r in range(part_offsets[p], part_offsets[p + 1]):
            r0, r1 = ring_offsets[r], ring_offsets[r + 1]
            n = r1 - r0
            best = _first(keys[r0:r1], ties[r0:r1])
            if r == part_offsets[p] and not cut and not part_inset[p] and moved_in[r0 + best]:
                # a moved edge whose strip stops short of the vertex it ends at (a step, a reflex corner):
                # the remainder starts at that vertex, which it keeps
                end = (keys[r0 + best] + 1.0) % outer
                for j in range(n):
                    if at_vertex[r0 + j] and keys[r0 + j] == end:
                        best = j
                        break
                # (a swept last edge first: PRT's start on the lot of both, massing.seoul.37's first tier)
                best = _past_a_swept_last_edge(best, corner[r0:r1], moved_from[r0:r1], moved_in[r0:r1],
                                               runs_along[r0:r1], outer, ring)
                best = _past_a_carried_edge(best, coords[r0:r1], moved_from[r0:r1], moved_in[r0:r1],
                                            runs_along[r0:r1], outer, ring)
                best = _past_a_kept_edge_s_reflex_end(best, coords[r0:r1], corner[r0:r1], moved_from[r0:r1],
                                                      moved_in[r0:r1], outer, ring)
            if r == part_offsets[p] and not cut and not part_inset[p]:
                best = _at_vertex_0(best, corner[r0:r1], runs_along[r0:r1], outer)
                best = _before_a_sweep(best, keys[r0:r1], moved_in[r0:r1], moved_from[r0:r1], runs_along[r0:r1],
                                       outer, ring)
                q1 = parent_rings[parent_offsets[g]] + 1
                best = _at_edge_1_s_step(best, keys[r0:r1], corner[r0:r1], moved_from[r0:r1], moved_in[r0:r1],
                                         runs_along[r0:r1], len(moves) > 0 and outer > 2 and moves[q1] > 0.0)
            if r == part_offsets[p] and part_inset[p]:
                # where the first outer edge left, counting from the last, ends: vertex 0's mitre when the
                # last edge and edge 0 are left; the end of the last edge's run nearest vertex 0 of all
                # the inset's pieces (``_last_edge_ends``) counts as the last one's end. Of an edge that a
                # grown hole parts in runs, the end of its last run counts: the edge's own end (PRT on a lot
                # whose last edge a hole takes and another parts edge 0: the inset starts at edge 0's end,
                # its mitre with edge 1, not where the first run ends at the hole; massing's holes.43599)
                rank = np.full(n, np.inf)
                for j in range(n):
                    incoming = moved_from[r0 + (j - 1) % n]
                    if incoming < outer and moved_from[r0 + j] != incoming:  # (the end of a run along it)
                        # (how far along the edge its last segment starts, in [0, 1], orders its runs)
                        rank[j] = incoming + 1 - 0.5 * ties[r0 + (j - 1) % n]
                        if incoming == outer - 1 and last_end[g] == r0 + j:
                            rank[j] = 0
                if np.isfinite(rank).any():
                    best = int(np.argmin(rank))
            if r == part_offsets[p] and marked[r0:r1].any():
                best = _first(np.where(marked[r0:r1], keys[r0:r1], np.inf), ties[r0:r1])
            if r == part_offsets[p] and not part_with_start[p]:
                # the last place on the parent's outer ring (a piece may run along its holes too)
                best = int(np.argmax(np.where(keys[r0:r1] < outer, keys[r0:r1], -1.0)))
            elif r == part_offsets[p] and cut:
                # a cut through a hole: the piece starts with the first cut edge that runs into the hole
                for j in range(n):
                    k = r0 + (best + j) % n
                    if keys[k] < outer and keys[r0 + (k - r0 + 1) % n] >= outer:
                        best = k - r0
                        break
            for j in range(n):
                k = r0 + (best + j) % n
                out[r0 + j, 0], out[r0 + j, 1] = coords[k, 0], coords[k, 1]
    return out


@njit(cache=True, nogil=True)
def _at_vertex_0(best, corner, along, outer):
    """The vertex (an index into one ring of a setback's remainder) where PRT starts a remainder that keeps
    the parent's vertex 0, ``best`` otherwise. ``corner`` (n,): the parent vertex each vertex of the ring
    lies at (-1 for none); ``along`` (n,): the parent edge its outgoing edge runs along (-1 for none).

    Where the kept last edge runs on past vertex 0 (a reflex vertex 0, edge 0's strip starting beside the
    last edge's line), the remainder starts at vertex 0 (measured through PyPRT on massing's second tiers
    over real lots: three of three); where edge 0's strip steps back to vertex 0 from the kept last edge
    (turned by under 15 degrees, or under 45 at a reflex vertex 0, ``geometry.setback_strips``), at the run along
    the last edge that ends at vertex 0, not at the step (sixteen of sixteen), also where that run is the
    last edge kept whole, from its kept start (measured through PyPRT: a 5 m last edge turned 10 or 14
    degrees from edge 0 at a convex vertex 0, 10 to 44 degrees at a reflex one, six of six; a 20 x 20 m lot
    whose 4 m last edge lies on edge 0's line, or turns from it by 10 degrees or by 0.02; massing's
    concave.43155, 20.7 degrees reflex, near_degenerate.50908, on edge 0's line, and convex.50756's second
    tier, whose 3 m last edge turns by 10)."""
    n = len(corner)
    for j in range(n):
        if corner[j] == 0 and along[j] == outer - 1:
            return j
    # (the run before the step lies along the last edge, or along edge 0's line where the two are one line;
    # it starts where a strip ends on it or at the last edge's kept start alike: PRT's second tiers on a lot
    # whose 4 m last edge runs from a kept corner on edge 0's line, and on massing.near_degenerate.43838's
    # 6.3 m one); the step's end, where edge 0's moved copy starts, ties with vertex 0 (both count as edge
    # 0's) and may come first in GEOS's ring
    step = best if corner[best] == 0 or corner[(best - 1) % n] != 0 else (best - 1) % n
    previous = (step - 1) % n
    if corner[step] == 0 and along[step] < 0 and (along[previous] == outer - 1 or along[previous] == 0):
        return previous
    return best


#: The cosine under which a lost edge faces the moved line that swept it (``_before_a_sweep``): parallel
#: (``Tol.parallel``).
_FACING = float(np.cos(np.radians(TOL.parallel)))
#: How much of the moved edge's length (``_before_a_sweep``) a facing edge must lie beside to be swept by its
#: strip: any of it but rounding.
_BESIDE = 1e-9


@njit(cache=True, nogil=True)
def _before_a_sweep(best, keys, moved_in, moved_from, along, outer, ring):
    """The vertex (an index into one ring of a setback's remainder) where PRT starts a remainder that has
    lost edge 0 to a moved line sweeping over it, ``best`` otherwise. ``keys`` (n,), ``moved_in`` (n,),
    ``moved_from`` (n,) and ``along`` (n,) as ``ring_starts`` finds them (the parent edge a vertex's outgoing
    edge runs along or was moved in from, inf for none; the one it runs along, -1 for none); ``ring`` (the
    parent's outer ring first, ``outer`` vertices).

    Where the first edge left is a moved line (``best``, edge k) that swept over a kept edge facing it
    (parallel, within 2 degrees, and beside some of edge k) among the edges lost from the run before it
    around to edge k (an arm narrower than the setback: its side and end go under edge k's strip), PRT
    starts the remainder at that run (or moved line), along the last edge left (measured through PyPRT on
    an L whose 3 m arm's long side, set back 4 m, covers the arm, its vertex 0 at the arm's end, the arm's
    inner side cut in one or two edges or vertex 0 between them, the inner side kept or set back 3 m:
    massing.L.50366's second tier, holes.44173's). A facing edge beside none of edge k (lost under another
    strip) is no sweep: PRT starts at the moved line (a 0.6 m jog set back 4 m whose facing 0.6 m edge lies
    4 m past its end, measured through PyPRT; massing.seoul.47's second tier). Nor is a moved line that
    passed a kept edge's far end (a chamfer between two moved edges, or beside a kept one: PRT starts at
    the moved line). Where edge 0 is lost otherwise and the kept last edge's run is left, the remainder
    starts where that run ends."""
    n = len(keys)
    if keys.min() < 1.0 or (moved_from == 0.0).any():  # (edge 0, or vertex 0, is left)
        return best
    k = keys[best]
    previous = (best - 1) % n
    p = moved_from[previous]  # (a kept run, or a moved line)
    if not moved_in[best] or k >= outer or not p > k or p >= outer:
        # edge 0 lost otherwise: the remainder starts where the kept last edge's run ends (PRT's on that
        # L numbered from the arm's far corner, the arm's end and side lost under the long side's line,
        # where a strip's side runs on from the last edge's run: massing.holes.50515's second tier)
        for j in range(n):
            if along[j] == outer - 1 and not moved_in[j]:
                return (j + 1) % n
        return best
    kx, ky = ring[(int(k) + 1) % outer, 0] - ring[int(k), 0], ring[(int(k) + 1) % outer, 1] - ring[int(k), 1]
    size = np.sqrt(kx * kx + ky * ky)
    if size == 0.0:
        return best
    i = (int(p) + 1) % outer
    while i != int(k):
        ex, ey = ring[(i + 1) % outer, 0] - ring[i, 0], ring[(i + 1) % outer, 1] - ring[i, 1]
        length = np.sqrt(ex * ex + ey * ey)
        # (how far along edge k each end of the edge lies: the strip sweeps it only where the two overlap)
        t0 = ((ring[i, 0] - ring[int(k), 0]) * kx + (ring[i, 1] - ring[int(k), 1]) * ky) / size
        t1 = t0 + (ex * kx + ey * ky) / size
        beside = min(t0, t1) < size - _BESIDE * size and max(t0, t1) > _BESIDE * size
        if length > 0.0 and (ex * kx + ey * ky) / (length * size) < -_FACING and beside:
            return previous
        i = (i + 1) % outer
    return best


@njit(cache=True, nogil=True)
def _at_edge_1_s_step(best, keys, corner, moved_from, moved_in, along, edge_1_moved):
    """The vertex (an index into one ring of a setback's remainder) where PRT starts a piece that edge 1's
    strip parted off, ``best`` otherwise. ``keys``, ``corner``, ``moved_from``, ``moved_in`` and ``along``
    (n,) as ``ring_starts`` finds them; ``edge_1_moved`` whether parent edge 1 moved in.

    A piece that holds nothing of edge 0 (nor vertex 0) nor edge 1's moved copy, where edge 1's strip
    ends in a step back to the kept vertex 2 that runs across the face and parts the remainder, starts
    where that step (along no parent edge) enters it, before vertex 2, as it comes after edge 1 in the
    remainder's order (measured through PyPRT: massing.hannam.48's second tier, its first tier's remainder
    parted by edge 1's step at a 39 degree reflex vertex 2, and that face as a designed lot; started at
    vertex 2, the terrace was off by 4.5 m^2)."""
    n = len(keys)
    if not edge_1_moved or keys.min() < 1.0 or (moved_from == 0.0).any() or (moved_from == 1.0).any():
        return best
    for j in range(n):
        if corner[j] < 0 and along[j] < 0 and not moved_in[j] and corner[(j + 1) % n] == 2:
            return j
    return best


#: The sine of the largest turn off square (degrees) between the kept last edge and edge 0 at which a
#: remainder that edge 0's moved line swept the last edge from starts before it (``_past_a_swept_last_edge``):
#: measured between 20 (starts before) and 30 (at edge 0's moved line).
_SWEPT_SQUARE = float(np.sin(np.radians(25.0)))


@njit(cache=True, nogil=True)
def _past_a_swept_last_edge(best, corner, moved_from, moved_in, along, outer, ring):
    """The vertex (an index into one ring of a setback's remainder) where PRT starts a remainder whose first
    edge (``best``) is edge 0's moved line that ran past the far end of the kept last edge (edge 0 the end of
    an arm, or the bottom of a notch, shorter than its setback: the remainder steps from the last edge's
    start, which it keeps, out to that line): the run along the edge before the last that ends there, where
    the last edge turns from edge 0 by a right angle, give or take ``_SWEPT_SQUARE`` (measured through
    PyPRT: a 1.4 m wide arm, 1.7 to 3.5 m long, whose end, edge 0, is set back 4 m, its top the last edge,
    turned 0, 10 or 20 degrees off square: PRT's second tier's edge 0 is that run; 30 and 45: edge 0's moved
    line; massing.H.51126's and seoul.37's second tiers); ``best`` otherwise. ``corner``, ``moved_from``,
    ``moved_in``, ``along`` (n,) as ``ring_starts`` finds them; ``ring`` the parent's outer ring first,
    ``outer`` vertices."""
    n = len(corner)
    step, run = (best - 1) % n, (best - 2) % n
    if not (moved_in[best] and moved_from[best] == 0.0 and outer >= 3 and corner[step] == outer - 1
            and not np.isfinite(moved_from[step]) and along[run] == outer - 2):
        return best
    lx, ly = ring[0, 0] - ring[outer - 1, 0], ring[0, 1] - ring[outer - 1, 1]
    ex, ey = ring[1, 0] - ring[0, 0], ring[1, 1] - ring[0, 1]
    sizes = np.sqrt((lx * lx + ly * ly) * (ex * ex + ey * ey))
    if sizes > 0.0 and abs(lx * ex + ly * ey) <= _SWEPT_SQUARE * sizes:
        return run
    return best


@njit(cache=True, nogil=True)
def _after_steps(keys, moved_from, moved_in, r0, r1, outer):
    """A setback's remainder whose edge moved in from parent edge i ends in a step (an edge along no
    parent edge, to the next parent edge's kept vertex or moved copy) counts that edge and the step after
    the next parent edge: PRT starts its tier there (massing's convex.33000, moved edge 0 stepping to kept
    edge 1 at 11 degrees: PRT's remainder starts at vertex 1; far.33307, edges set back 4 and 3 m
    stepping at 5 degrees). A moved last edge of the ``outer`` ring (``moved_in``) that steps to edge 0
    counts, with its step, after the last: the remainder starts at edge 0 (measured through PyPRT: a last
    edge moved 4 m stepping to a kept edge 0 at 12 degrees); a kept last edge's run before a moved edge 0's
    step stays where it is (``_at_vertex_0``: near_degenerate.43838). ``keys`` (V,) turned in place for
    the ring ``r0:r1``."""
    n = r1 - r0
    for j in range(r0, r1):
        k = r0 + (j - r0 + 1) % n
        m = r0 + (j - r0 + 2) % n
        i = moved_from[j]
        following = i + 1
        if i == outer - 1:
            following = 0.0 if moved_in[j] else np.inf
        if np.isfinite(i) and keys[j] == i and not np.isfinite(moved_from[k]) and (
                moved_from[m] == following or keys[m] == following):
            keys[j] = keys[k] = i + 1.5


@njit(cache=True, nogil=True)
def _edge_after(ring, i):
    """Parent edge i + 1 of ``ring``: its start, its vector and its length squared."""
    e = int(i) + 1
    ax, ay = ring[e, 0], ring[e, 1]
    bx, by = ring[e + 1, 0] - ax, ring[e + 1, 1] - ay
    return ax, ay, bx, by, bx * bx + by * by


@njit(cache=True, nogil=True)
def _past_a_carried_edge(best, coords, moved_from, moved_in, along, outer, ring):
    """The vertex (an index into one ring of a setback's remainder) where PRT starts a remainder whose first
    edge (``best``), moved in from parent edge i, runs on along the line of the kept edge i + 1 beside none
    of it to the edge moved in from edge i + 2 (a kept jog at a reflex vertex between two moved edges,
    carried along its own line as both its ends slide: its far end moved no less than its near one): that
    edge, ``best`` otherwise (measured through PyPRT: a 20 x 6 m block whose 0.5 to 0.8 m jog after edge 0
    is kept, edges 0 and 2 set back 4 m, or 4 and 3 m, edge 3 set back 4 m or kept: PRT's second tier's
    edge 0 is edge 2's moved line, seven of seven; massing.tartu.8's second tier, whose 0.64 m jog its
    first tier carries). Where the jog's far end moved less, the jog vanishes and the step left runs against
    its line: PRT starts at edge i's moved line (edges 0 and 2 set back 3 and 4 m, measured likewise).
    ``coords`` (n, 2) the ring, ``moved_from``, ``moved_in``, ``along`` (n,) as ``ring_starts`` finds them;
    ``ring`` the parent's outer ring first, ``outer`` vertices."""
    n = len(moved_from)
    k, m = (best + 1) % n, (best + 2) % n
    i = moved_from[best]
    if not (moved_in[best] and i + 2 < outer and along[k] == i + 1 and moved_in[m] and moved_from[m] == i + 2):
        return best
    ax, ay, bx, by, length2 = _edge_after(ring, i)
    if length2 == 0.0:
        return best
    # (where the run's ends lie along edge i + 1, in its lengths: beside none of it outside [0, 1])
    t0 = ((coords[k, 0] - ax) * bx + (coords[k, 1] - ay) * by) / length2
    t1 = ((coords[m, 0] - ax) * bx + (coords[m, 1] - ay) * by) / length2
    if max(t0, t1) < -_BESIDE or min(t0, t1) > 1.0 + _BESIDE:
        return m
    return best


@njit(cache=True, nogil=True)
def _past_a_kept_edge_s_reflex_end(best, coords, corner, moved_from, moved_in, outer, ring):
    """The vertex (an index into one ring of a setback's remainder) where PRT starts a remainder whose first
    edge (``best``), moved in from parent edge i, ends on the line of the kept edge i + 1 past its far end,
    a reflex vertex i + 2 that the remainder keeps, running back along that line to it: that vertex,
    ``best`` otherwise (measured through PyPRT: a 14 x 20 m block whose edge 0 is set back 4 m, past the
    3 m kept step after it, square or turned 18 degrees either way, edge 1 kept or set back as far (its
    strip folds, and it stays): four of four; set back 2 m, short of the step, it starts at edge 0's moved
    line; massing.kunming.47's second tier, on a piece of its shapeL footprint). ``coords`` (n, 2) the
    ring, ``corner``, ``moved_from``, ``moved_in`` (n,) as ``ring_starts`` finds them; ``ring`` the parent's
    outer ring first, ``outer`` vertices."""
    n = len(moved_from)
    k, m = (best + 1) % n, (best + 2) % n
    i = moved_from[best]
    if not (moved_in[best] and i + 2 < outer and corner[m] == i + 2):
        return best
    ax, ay, bx, by, length2 = _edge_after(ring, i)
    if length2 == 0.0:
        return best
    # (where the first edge ends along edge i + 1, in its lengths, and whether the run from there back to
    # vertex i + 2 lies along that edge's line, within ``Tol.parallel``: a swept front's run turns from
    # it by 0.4 degrees on kunming.47's piece)
    t = ((coords[k, 0] - ax) * bx + (coords[k, 1] - ay) * by) / length2
    cx, cy = coords[m, 0] - coords[k, 0], coords[m, 1] - coords[k, 1]
    back = -(cx * bx + cy * by) / np.sqrt((cx * cx + cy * cy) * length2 + 1e-300)
    if t > 1.0 + _BESIDE and back >= _FACING:
        return m
    return best


@njit(cache=True, nogil=True)
def _runs_into_kept_vertices(keys, corner, along, moved_in, r0, r1, outer):
    """A setback's remainder that reaches a kept vertex i along edge i's own line, from a point before it
    (where the strip of a moved edge i - 1 that covers an arm ends on that line), counts that run just
    before vertex i: PRT starts its tier there where vertex i is the first it keeps (measured through
    PyPRT: a 10 x 10 m block with a 1 m arm whose side, edge 1 or 2, is set back 3 m, the arm's strip ending
    on the next, kept, edge's line, square or turned 12.5 degrees; massing's holes.43991 and 50445, whose
    first tiers lose such an arm past edge 3). Not so after edge 0 nor the last edge: where the arm's side
    is edge 0 the remainder starts at vertex 1 (measured likewise; massing's U.43550, a shapeO frame whose
    0.27 m arm edge 0's strip takes), where it is the last edge, at vertex 0. ``corner``, ``along`` (V,):
    the parent vertex each vertex lies at and the parent edge its outgoing edge runs along (-1 for none);
    ``keys`` (V,) turned in place for the ring ``r0:r1`` of a parent with ``outer`` outer edges."""
    n = r1 - r0
    for j in range(r0, r1):
        i = along[j]
        if corner[j] < 0 and not moved_in[j] and 2 <= i < outer and corner[r0 + (j - r0 + 1) % n] == i:
            keys[j] = i - 0.5


@njit(cache=True, nogil=True)
def _first(keys, ties):
    """The index of the least key, of equal ones that of the least tie."""
    best = 0
    for j in range(1, len(keys)):
        if keys[j] < keys[best] or (keys[j] == keys[best] and ties[j] < ties[best]):
            best = j
    return best


@njit(cache=True, nogil=True)
def _last_edge_ends(coords, ring_offsets, part_offsets, part_source, part_inset, moved_from, parent_coords,
                    parent_rings, parent_offsets):
    """Per parent (G,): the vertex of its inset's outer rings (pieces ``part_inset``) where a run along its
    last outer edge ends nearest that edge's end (vertex 0), -1 for none. An inset counts from the last
    edge there alone: vertex 0's mitre, or where a hole grown over vertex 0 cuts the last edge off (PRT
    starts that piece there, holes.7039); a hole grown across the inset also ends runs along the last
    edge in pieces that lie before it, and PRT starts those at their first outer edge's end (massing's
    courtyards and holes.11067, whose inset falls apart)."""
    last = np.full(len(parent_offsets) - 1, -1, np.int64)
    reach = np.full(len(parent_offsets) - 1, -np.inf)
    for p in range(len(part_offsets) - 1):
        if not part_inset[p]:
            continue
        g = part_source[p]
        q0, q1 = parent_rings[parent_offsets[g]], parent_rings[parent_offsets[g] + 1]
        outer = q1 - q0
        ax, ay = parent_coords[q1 - 1, 0], parent_coords[q1 - 1, 1]
        bx, by = parent_coords[q0, 0] - ax, parent_coords[q0, 1] - ay
        r0, r1 = ring_offsets[part_offsets[p]], ring_offsets[part_offsets[p] + 1]
        n = r1 - r0
        for j in range(n):
            incoming = moved_from[r0 + (j - 1) % n]
            if incoming == outer - 1 and moved_from[r0 + j] != incoming:
                along = (coords[r0 + j, 0] - ax) * bx + (coords[r0 + j, 1] - ay) * by
                if along > reach[g]:
                    reach[g], last[g] = along, r0 + j
    return last


@njit(cache=True, nogil=True)
def material_sides(parent_coords, parent_rings, parent_offsets):
    """Per parent ring (R,): 1.0 where the polygon lies to the left of its edges, -1.0 where it lies to their
    right (an outer ring winding clockwise, a hole counter-clockwise)."""
    side = np.empty(len(parent_rings) - 1)
    for g in range(len(parent_offsets) - 1):
        for q in range(parent_offsets[g], parent_offsets[g + 1]):
            q0, q1 = parent_rings[q], parent_rings[q + 1]
            twice_area = 0.0
            for i in range(q0, q1):
                k = q0 + (i - q0 + 1) % (q1 - q0)
                twice_area += parent_coords[i, 0] * parent_coords[k, 1] - parent_coords[k, 0] * parent_coords[i, 1]
            counter_clockwise = twice_area > 0.0
            side[q] = 1.0 if counter_clockwise == (q == parent_offsets[g]) else -1.0
    return side


@njit(cache=True, nogil=True)
def places(px, py, qx, qy, g, parent_coords, parent_rings, parent_offsets, material, moves):
    """Where the point p and the edge (p, q) of a piece lie on polygon g: the squared distance to the
    nearest point of its boundary and that point's place (i + f a fraction f along the edge from vertex
    i to vertex i + 1, ring after ring), the place of the nearest vertex, the largest squared edge length
    (a scale for tolerances); and the place i of the edge (p, q) runs along or was moved in from
    (parallel to it to a millionth, as GEOS's mitres between near-collinear edges turn an inset's edges a
    little; in the same direction; on the polygon's side of it (``material`` (R,), ``material_sides``),
    as an offset or a setback moves edges in, so that a hole's edge beside an inset edge is not taken for
    its source: massing's holes.11067; where ``moves`` gives the distance each parent edge moved by (one
    per parent vertex; empty, or NaN, for none known: the nearest edge), only an edge at that distance (or
    along it), so that of an offset's sides the one moved in from the outline by the offset is not taken
    for a hole's, whose grown end stops short of it (massing's holes.33921); of collinear ones the one
    whose span is nearest the edge's: an H's inner sides; inf when there is none) with the distance
    between their lines, and how far along that edge p lies (a fraction in [0, 1])."""
    near, key = np.inf, np.inf
    near_vertex, vertex_key = np.inf, np.inf
    away, edge, gap, best, along = np.inf, np.inf, np.inf, np.inf, 0.0
    dx, dy = qx - px, qy - py
    length = np.sqrt(dx * dx + dy * dy)
    scale = 0.0
    base = 0
    for q in range(parent_offsets[g], parent_offsets[g + 1]):
        q0, q1 = parent_rings[q], parent_rings[q + 1]
        m = q1 - q0
        for i in range(m):
            ax, ay = parent_coords[q0 + i, 0], parent_coords[q0 + i, 1]
            bx, by = parent_coords[q0 + (i + 1) % m, 0] - ax, parent_coords[q0 + (i + 1) % m, 1] - ay
            length2 = bx * bx + by * by
            scale = max(scale, length2)
            f = 0.0 if length2 == 0.0 else min(max(((px - ax) * bx + (py - ay) * by) / length2, 0.0), 1.0)
            d = (px - ax - f * bx) ** 2 + (py - ay - f * by) ** 2
            position = base + i + f
            if f > 1.0 - 1e-9:
                position = base + (i + 1) % m  # the edge's end is the next vertex
            if d < near - 1e-18 or (d <= near + 1e-18 and position < key):
                near, key = d, position
            dv = (px - ax) ** 2 + (py - ay) ** 2  # to vertex i
            if dv < near_vertex:
                near_vertex, vertex_key = dv, base + i
            u = np.sqrt(length2)
            if u > 0.0 and length > 0.0 and abs(bx * dy - by * dx) <= 1e-6 * u * length and bx * dx + by * dy > 0.0:
                left = (bx * (py - ay) - by * (px - ax)) / u  # how far the edge lies left of the parent's
                if material[q] * left < -1e-9 * max(u, 1.0):
                    continue  # outside the polygon's side of it: not moved in from it
                distance = abs(left)
                # off the distance the parent edge moved by (0 where none is known: the nearest); an edge
                # at another distance than its own (and than 0: along it) was not moved in from it
                known = len(moves) > 0 and np.isfinite(moves[q0 + i])
                miss = abs(distance - (moves[q0 + i] if known else 0.0))
                if known and miss > 1e-6 * max(u, 1.0) and distance > 1e-6 * max(u, 1.0):
                    continue
                # how far the edge's span along the line lies from the parent edge's [0, u]
                low, high = ((px - ax) * bx + (py - ay) * by) / u, ((qx - ax) * bx + (qy - ay) * by) / u
                apart = max(0.0, low - u, -high)
                same = abs(miss - best) <= 1e-9 * max(u, 1.0)
                if (miss < best and not same) or (same and apart < gap):
                    away, edge, gap, best = distance, base + i, apart, miss
                    along = min(max(low / u, 0.0), 1.0)
        base += m
    return near, key, vertex_key, scale, edge, away, along
