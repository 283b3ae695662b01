"""The strip each moved edge of a setback sweeps (``geometry.setback``), before the strips are united.

A strip is the quad between the edge and its moved copy, its ends at the mitre points where the moved lines
of its neighbours meet (``mitres``), or stepped where the boundary turns little between different
distances; a quad that folds over itself is cut to a triangle (``quad_strips``), or its edge does not move
(``unfolded``); a strip past a kept edge's reflex end stops at the bisector ray there
(``short_of_reflex_ends``). Each rule and its threshold were measured through PyPRT; the docstrings say
on which lots.
"""

from __future__ import annotations

import numpy as np
import shapely

from grammarc.constants import TOL
from grammarc.geometry.polygon_edges import Edges, cosines

#: A mitre longer than this many setback distances (a near-reversal of the boundary) is cut to the
#: edge's rectangle.
_MITRE_LIMIT = 10.0
#: The turn (degrees) of the boundary below which edges moved by different distances step (``mitres``)
#: at a convex vertex, and at a reflex one: measured through PyPRT, 14.99 steps and 15.01 meets at a convex
#: vertex; 44.5 and 45 step and 45.5 meets at a reflex one, whatever the distances (2, 4 and 8 m).
STEP_TURN = 15.0
_REFLEX_STEP_TURN = 45.0
#: The turn (degrees) from a kept edge's line past its reflex end under which the bisector ray there cuts no
#: strip short (``short_of_reflex_ends``): measured through PyPRT, 0.249 cuts nothing and 0.2505 cuts,
#: beside parallel edges and beside edges turned 14 degrees from each other alike.
_RAY_TURN = 0.25


def mitres(edges: Edges, d: np.ndarray, reflex_steps: bool = True) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(E, 2) twice: where the strip of each edge starts and where its previous edge's strip ends, relative
    to the vertex they share: where their moved lines meet (the edge's own move where they do not meet
    near it); and (E,) whether they do.

    Where the two distances differ (one edge stays, or both move by different distances) and the
    boundary turns there by less than ``STEP_TURN`` (at a convex vertex; ``_REFLEX_STEP_TURN`` at a reflex
    one, ``_stepping``), PRT steps instead of running the moved lines out to where they meet: each strip
    ends at the mitre point of its own distance on both edges, and the remainder steps across between them
    (measured through PyPRT on massing's tiers: a kept edge then a moved one, turned by 14.99 degrees
    steps, by 15.01 meets; edges set back 4 and 3 m turned by 7 degrees step by 1 m on convex.11084; at a
    reflex vertex, a kept edge then one moved 2, 4 or 8 m, or edges moved 4 and 3 or 4 and 1 m, turned by
    5 to 45 degrees step, by 45.5 to 89 meet: massing.concave.43421's first tier, 30 degrees)."""
    a, b = edges.inward[edges.prev], edges.inward
    da, db = d[edges.prev], d
    det = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    safe = np.where(np.abs(det) > 1e-9, det, 1.0)
    corner = np.stack([(da * b[:, 1] - db * a[:, 1]) / safe, (a[:, 0] * db - b[:, 0] * da) / safe], axis=1)
    straight = b * db[:, None]
    reach = np.hypot(corner[:, 0], corner[:, 1])
    far = np.maximum(da, db)
    cosine = np.einsum("ij,ij->i", a, b)
    step = (np.abs(da - db) > TOL.zero) & (_stepping(edges.end - edges.start, a, cosine) if reflex_steps else
                                            cosine > np.cos(np.radians(STEP_TURN)))
    too_far = ~step & ((np.abs(det) <= 1e-9) | (reach > _MITRE_LIMIT * np.maximum(far, TOL.zero)))
    corner = np.where(too_far[:, None], straight, corner)
    ends = corner.copy()
    bisector = (a[step] + b[step]) / (1.0 + cosine[step])[:, None]
    corner[step], ends[step] = bisector * db[step, None], bisector * da[step, None]
    return corner, ends, ~too_far


def _stepping(tangent: np.ndarray, previous_inward: np.ndarray, cosine: np.ndarray) -> np.ndarray:
    """(k,) whether the boundary turns by little enough at the vertices where edges (their ``tangent`` (k, 2))
    leave their previous edges (``previous_inward`` (k, 2) normals; ``cosine`` (k,) of the turn) that
    edges moved by different distances step there: under ``STEP_TURN`` where the edge turns into the
    polygon (a convex vertex), up to ``_REFLEX_STEP_TURN`` where it turns away (a reflex one)."""
    reflex = np.einsum("ij,ij->i", tangent, previous_inward) < 0
    return np.where(reflex, cosine >= np.cos(np.radians(_REFLEX_STEP_TURN)) - 1e-12,
                    cosine > np.cos(np.radians(STEP_TURN)))


def mitred_quads(edges: Edges, d: np.ndarray, reflex_steps: bool = True):
    """The quads of the edges moved by ``d`` (E,): (E, 2) where each edge's strip starts and where its
    previous edge's ends (``mitres``, stepping at reflex vertices too or not), and (E, 2) where its own
    strip ends, relative to its vertices; the moved edges (k,) and their quads (k, 4, 2): start, end, moved
    end, moved start."""
    corner, ends, mitred = mitres(edges, d, reflex_steps)
    # a strip ends at its next edge's mitre (its own, where the two step); where the two do not meet in
    # one (a straight vertex, as between the collinear edges a setback leaves, or a spike), at its own
    # moved end
    end_corner = np.where(mitred[edges.next][:, None], ends[edges.next], edges.inward * d[:, None])
    idx = np.flatnonzero(d > TOL.zero)
    quads = np.stack([edges.start[idx], edges.end[idx], edges.end[idx] + end_corner[idx],
                      edges.start[idx] + corner[idx]], axis=1)
    return corner, ends, end_corner, idx, quads


def _folds(edges: Edges, d: np.ndarray) -> np.ndarray:
    """The moved edges (indices) whose quads fold over themselves (a distance longer than the edge allows)."""
    _, _, _, idx, quads = mitred_quads(edges, d, reflex_steps=False)
    return idx[~shapely.is_valid(shapely.polygons(quads))] if len(idx) else idx


def quad_strips(quads: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The strips (k,) of quads (k, 4, 2): each quad, or where it folds over itself (k,) its triangle
    (``_folded_strips``)."""
    strips = shapely.polygons(quads) if len(quads) else np.empty(0, dtype=object)
    folded = ~shapely.is_valid(strips)
    if folded.any():
        strips[folded] = _folded_strips(quads[folded])
    return strips, folded


def _folded_strips(quads: np.ndarray) -> np.ndarray:
    """The strips (k,) of edges whose quads (k, 4, 2) (start, end, moved end, moved start) fold over
    themselves: their end lines cross before the moved line (a distance longer than the edge allows). The
    strip is then the triangle of the edge and that crossing, where its neighbours' strips take over,
    as a straight skeleton's face of the edge ends (PRT's terraces on massing's narrow shapeL arms: the
    end's strip reaches the kept edge beside it)."""
    start, end, moved_end, moved_start = quads.transpose(1, 0, 2)
    a, b = moved_start - start, moved_end - end
    det = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    gap = end - start
    t = (gap[:, 0] * b[:, 1] - gap[:, 1] * b[:, 0]) / np.where(np.abs(det) > 1e-300, det, 1.0)
    return shapely.polygons(np.stack([start, end, start + t[:, None] * a], axis=1))


def unfolded(edges: Edges, d: np.ndarray) -> np.ndarray:
    """The distances (E,) with that of one edge of each face whose quad folds between two parallel
    neighbours (turned by under ``Tol.parallel`` from each other, facing or not), one moved and one kept, set
    to 0 where then no strip of the face folds: such an edge (a short end moved further than its length)
    does not move in PRT, and its neighbours' strips end at its line (measured through PyPRT on massing's
    tiers over real lots: tartu.0, a 2 m edge moved 4 m between a kept edge and a moved one parallel to
    it, where PRT's front runs on past the kept edge's line and ends at the short edge's line, and the swept
    wavefront left 62.6 m^2 of that terrace out; seoul.31; hiroshima.111, whose second tier, a 1.8 x 2.6 m face with sides moved 3 and 4 m,
    keeps the 1.8 m side and the other's strip covers the face; the random lots' narrow arms,
    massing.H.15118 and an L's 3 m end moved 4 m, as the wavefront had them). A face whose strips would
    still fold is swept as it is (``setback._swept``), the edge moving (massing.L.46072's 0.07 m wide shapeU frame,
    bergen.44's 0.5 m wide one: PRT's terraces), and so is one whose folded edges lie between neighbours
    that are not parallel, or both moved (a channel's end that closes: holes.33921's second tier), or whose
    moved neighbour steps from the edge beyond it (nearly collinear, moved by another distance: a part of a
    kept edge's line that moves, as near_degenerate.44048's 0.67 m step, where PRT's terrace runs on along
    the bar as the wavefront's; a moved line that runs on, as hiroshima.136's, is a side). Of two such
    edges (an arm's end and a jog beside it, both moved 4 m), the jog, whose neighbours run the same way,
    stays, whichever is shorter, and then the shortest (measured through PyPRT on fifteen designed lots,
    the jog 3.1 to 3.95 m long after the end or 3.5 m before it, the end 2.5 to 3.8 m: PRT's strip beside
    the jog runs on past the kept edge to the jog's line; massing.utrecht.8's first tier, whose 3.03 m end
    stayed and left 1.7 m^2 of that terrace out). A jog between neighbours moved by different distances (3
    and 4 m, massing's shapeR second tier) stays too, even where a strip still folds beside it (PRT's second
    tier on utrecht.8, a 0.57 m jog, and on seventeen designed lots whose jogs run 0.05 to 0.9 m: the
    strips end at its line; moved, it let the 3 m strip run past it under the 4 m one)."""
    tangent = edges.end - edges.start
    length = np.hypot(tangent[:, 0], tangent[:, 1])
    moved = d > TOL.zero
    parallel = np.abs(cosines(tangent[edges.prev], tangent[edges.next])) > np.cos(np.radians(TOL.parallel))
    # the moved neighbour (``side``) and the edge beyond it step as in ``mitres``
    side = np.where(moved[edges.prev], edges.prev, edges.next)
    beyond = np.where(moved[edges.prev], edges.prev[side], edges.next[side])
    steps = (cosines(tangent[side], tangent[beyond]) > np.cos(np.radians(STEP_TURN))) & (
        np.abs(d[side] - d[beyond]) > TOL.zero)
    facing = np.einsum("ij,ij->i", tangent[edges.prev], tangent[edges.next]) < 0
    apart = moved[edges.prev] & moved[edges.next] & (np.abs(d[edges.prev] - d[edges.next]) > TOL.zero) & ~facing
    between = parallel & ((moved[edges.prev] != moved[edges.next]) | apart) & ~steps
    if not (between & moved).any():  # no edge to keep (most faces): the quads need no test of their own
        return d
    folded = _folds(edges, d)
    folded = folded[between[folded]]
    if not len(folded):
        return d
    # (a jog first, whose neighbours run the same way, then the shortest)
    order = np.lexsort((length[folded], facing[folded], edges.poly[folded]))
    first = folded[order][np.r_[True, np.diff(edges.poly[folded][order]) != 0]]
    unfolded = d.copy()
    unfolded[first] = 0.0
    # a face where strips still fold is swept as it was (massing.L.46072: its end stays moved)
    folding = np.zeros(int(edges.poly.max(initial=-1)) + 1, dtype=bool)
    folding[edges.poly[_folds(edges, unfolded)]] = True
    folding[edges.poly[first[apart[first]]]] = False  # (a jog between distances stays even so: utrecht.8)
    return np.where(folding[edges.poly], d, unfolded)


def reflex_strips(edges: Edges, swept: np.ndarray, strips: np.ndarray, idx: np.ndarray, quads: np.ndarray,
                   stepped: np.ndarray, stepped_strips: np.ndarray) -> np.ndarray:
    """The strips (k,) of the moved edges ``idx`` (k,), those of the faces not ``swept`` (m,) the
    ``stepped_strips`` (k,) of the quads ``stepped`` (k, 4, 2) that step at reflex vertices too
    (``_stepping``) where they differ from ``quads`` (k, 4, 2), which step at convex ones alone."""
    changed = ~swept[edges.poly[idx]] & np.any(stepped != quads, axis=(1, 2))
    return np.where(changed, stepped_strips, strips)


def chosen_quads(edges: Edges, swept: np.ndarray, idx: np.ndarray, quads: np.ndarray,
                  stepped: np.ndarray) -> np.ndarray:
    """The quads (k, 4, 2) of the strips ``reflex_strips`` chose: ``stepped`` but in the faces ``swept``."""
    return np.where(swept[edges.poly[idx]][:, None, None], quads, stepped)


def short_of_reflex_ends(edges: Edges, d: np.ndarray, strips: np.ndarray, idx: np.ndarray,
                          quads: np.ndarray) -> np.ndarray:
    """The strips (k,) of the moved edges ``idx`` (k,), their quads (k, 4, 2), each cut short where its side
    along a kept neighbour's line runs past that neighbour's far end, a reflex vertex whose other edge moves:
    there the strip stops at the ray from that vertex along the bisector of its own edge and the edge beyond
    (the sum of their inward normals, whatever their distances), and the triangle between the ray and the
    kept edge's line is the remainder's, reaching the outline at the vertex: the two strips, which touched
    along the kept edge's line, are two faces. Measured through PyPRT on massing's tiers and shapeL: an edge
    set back 7.5 m whose kept neighbour's line, turned 79 degrees at the reflex vertex, it passes by 2.5 m
    loses that triangle, 0.625 m^2 beside an edge parallel to it, and its ray turns 7 degrees with an edge
    beyond turned 14 from it, set back 5 or 7.5 m; a ray turned from the line by ``_RAY_TURN`` or less (or
    to the other side, at a turn of 90 degrees or more) cuts nothing, whatever the distances (6 to 14 m).
    Only where the two edges, met at one vertex, would turn from each other by under ``STEP_TURN`` into the
    face, as two edges step there (``mitres``; 14.98 degrees cuts and 15.04 does not, whether the strip's
    edge is parallel to the kept edge's neighbour or turned 14 degrees from it), or turn away from it (15
    to 57 degrees cut, measured likewise).
    Real lots: massing.brno.44's shapeU, a 1.3 m kept edge between two arms set back 1.5 m, whose ray
    turns 1.4 degrees from it: PRT's faces of 27.43 and 8.69 m^2; kunming.47's shapeL, three faces."""
    moved = d > TOL.zero
    tangent = edges.end - edges.start
    unit = tangent / np.maximum(np.hypot(tangent[:, 0], tangent[:, 1]), TOL.zero)[:, None]
    slack = TOL.zero * np.maximum(np.abs(edges.start).max(axis=1, initial=0.0), 1.0)
    out = strips
    # the strip's start side, along its previous edge (``kept``), whose start is the vertex; its end side,
    # along its next edge, whose end is the vertex
    for kept, corner, ahead in ((edges.prev[idx], quads[:, 3], False), (edges.next[idx], quads[:, 2], True)):
        beyond = edges.next[kept] if ahead else edges.prev[kept]
        vertex = edges.end[kept] if ahead else edges.start[kept]
        reflex = np.einsum("ij,ij->i", unit[beyond] if ahead else unit[kept],
                           edges.inward[kept] if ahead else edges.inward[beyond]) < 0
        along = np.einsum("ij,ij->i", corner - vertex, unit[kept])
        past = along > slack[kept] if ahead else along < -slack[kept]
        ray = edges.inward[idx] + edges.inward[beyond]
        reach = np.hypot(ray[:, 0], ray[:, 1])
        into = np.einsum("ij,ij->i", ray, edges.inward[kept]) > np.sin(np.radians(_RAY_TURN)) * reach
        # where the ray meets the strip's moved line: (vertex + s ray - start) . inward = d
        toward = np.einsum("ij,ij->i", ray, edges.inward[idx])
        s = (d[idx] - np.einsum("ij,ij->i", vertex - edges.start[idx], edges.inward[idx])) / np.where(
            toward > 0, toward, 1.0)
        # (the edge beyond turned from the strip's edge by under ``STEP_TURN`` where, met at one vertex, the
        # two would make a convex corner, by any angle where a reflex one)
        away = np.einsum("ij,ij->i", tangent[beyond] if ahead else tangent[idx],
                         edges.inward[idx] if ahead else edges.inward[beyond]) < 0
        stepping = away | (cosines(tangent[idx], tangent[beyond]) > np.cos(np.radians(STEP_TURN)))
        rows = np.flatnonzero(~moved[kept] & ~edges.hole[kept] & moved[beyond] & (beyond != idx) & reflex
                              & past & into & stepping & (toward > 0) & (s > 0))
        if len(rows):
            triangles = shapely.polygons(np.stack([vertex[rows], corner[rows],
                                                   vertex[rows] + s[rows, None] * ray[rows]], axis=1))
            out = out.copy() if out is strips else out
            out[rows] = shapely.difference(out[rows], triangles)
    return out
