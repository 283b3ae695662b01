"""``grammarc render tree.json``: a search's derivation graph drawn, a thumbnail of each state's design.

The states of a tree (``search.tree``) are derived again, all at once, from the grammar and lots its
``meta`` names (``Deriving.derive`` with records): a complete state shows its design, a partial one the
leaves it made before the choice it stopped at, each on its lot's footprint (drawn pale, so that an empty
state is a lot still to divide). The states stand in rows by their number of choices, each row in the
order derived, a line from each to its consequents; a state's frame says its status: a solution green, a
design the goal rejects red, pruned grey, failed black, a state with consequents blue.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from grammarc.errors import UsageError
from grammarc.geometry.footprint import lot_scopes
from grammarc.ir.asset_names import LEAF_QUAD
from grammarc.model.records import world_columns
from grammarc.ragged import ragged_take
from grammarc.render.picture import render
from grammarc.search.states import Deriving, States

#: The most states a picture draws: a thumbnail each.
MAX_STATES = 400
#: The widest picture, in pixels: the thumbnails of a wide row shrink to fit it.
MAX_WIDTH = 8000
FRAME = {"goal": (40, 160, 60), "complete": (200, 50, 40), "pruned": (150, 150, 150), "failed": (0, 0, 0),
         "branch": (50, 90, 200)}
PAPER = (250, 250, 250)
LINE = (90, 90, 90)


def draw_tree(deriving: Deriving, nodes: list[dict], path: Path, *, thumb: int = 96) -> dict:
    """Draw the states ``nodes`` (a tree's ``"states"``) of ``deriving``'s grammar and lots at ``path``
    (a PNG); returns how many states and rows were drawn."""
    if len(nodes) > MAX_STATES:
        raise UsageError(f"a tree of {len(nodes):,} states is too many to draw (at most {MAX_STATES}): "
                         "search with a smaller --max-states")
    row_of = {str(i): k for k, i in enumerate(deriving.lots.ids.tolist())}
    missing = sorted({n["lot"] for n in nodes} - set(row_of))
    if missing:
        raise UsageError(f"the tree's lots {', '.join(missing)} are not among the lots of {deriving.lots.source}")
    states = _states(nodes, row_of)
    depth = states.length
    rows = [np.flatnonzero(depth == d) for d in range(int(depth.max(initial=0)) + 1)]
    widest = max(len(r) for r in rows)
    thumb = max(16, min(thumb, MAX_WIDTH // widest - 8))
    cell = thumb + 8
    image = Image.new("RGB", (widest * cell + 8, len(rows) * (cell + 24) + 8), PAPER)
    draw = ImageDraw.Draw(image)
    place = {}
    for d, members in enumerate(rows):
        left = (widest - len(members)) * cell // 2 + 8
        for k, row in enumerate(members):
            place[nodes[row]["id"]] = (left + k * cell, 8 + d * (cell + 24))
    for node in nodes:
        if node["parent"] in place:
            (px, py), (x, y) = place[node["parent"]], place[node["id"]]
            draw.line([(px + thumb // 2, py + thumb), (x + thumb // 2, y)], fill=LINE, width=1)
    with tempfile.TemporaryDirectory() as folder:
        for row, picture in enumerate(_thumbnails(deriving, states, thumb, Path(folder))):
            x, y = place[nodes[row]["id"]]
            image.paste(picture, (x, y))
            draw.rectangle([x - 2, y - 2, x + thumb + 1, y + thumb + 1], outline=FRAME[nodes[row]["status"]],
                           width=2)
    image.save(path)
    return {"states": len(nodes), "rows": len(rows)}


def _states(nodes: list[dict], row_of: dict[str, int]) -> States:
    """The tree's states as ``States`` to derive again."""
    width = max((len(n["path"]) for n in nodes), default=0)
    path = np.full((len(nodes), width), -1, dtype=np.int32)
    for k, node in enumerate(nodes):
        path[k, :len(node["path"])] = node["path"]
    n = len(nodes)
    return States(np.array([row_of[node["lot"]] for node in nodes], dtype=np.int64), path,
                  np.array([len(node["path"]) for node in nodes], dtype=np.int64), np.full(n, -1), np.full(n, -1),
                  np.zeros(n), np.zeros(n), np.zeros(n, bool))


def _thumbnails(deriving: Deriving, states: States, size: int, folder: Path):
    """A picture (PIL image) of each state's leaves on its lot's footprint, in order."""
    _, chunks = deriving.derive(states, records=True)
    grammar = deriving.plan.grammar
    quad = grammar.assets.index(LEAF_QUAD)
    symbols = [*deriving.plan.symbol_names, "(lot)"]
    footprints = _footprints(deriving, states)
    for records in chunks:
        yield from _chunk_thumbnails(records, grammar.assets, quad, symbols, footprints, size, folder)


def _chunk_thumbnails(records, assets, quad: int, symbols: list[str], footprints: np.ndarray, size: int,
                      folder: Path):
    """The thumbnails of the states of one chunk of records (its lots), in order."""
    record = {"xform": records.xform, "lot": records.lot, "lot_origin": records.origins.table(), "mesh": records.mesh}
    xform, vertices = world_columns(record)
    mesh = records.mesh
    for k in records.origins.lot.tolist():
        rows = np.flatnonzero(records.lot == k)
        faces = np.flatnonzero(mesh.lot == k)
        rings, face_offsets = ragged_take(mesh.face_offsets, faces)
        points, ring_offsets = ragged_take(mesh.ring_offsets, rings)
        state = {
            "assets": list(assets), "symbols": symbols,
            "asset": np.concatenate([[quad], records.asset[rows]]).astype(np.int32),
            "xform": np.concatenate([footprints[k:k + 1], xform[rows]]),
            "symbol": np.concatenate([[len(symbols) - 1], records.symbol[rows]]).astype(np.int32),
            "mesh_vertices": vertices[points], "mesh_ring_offsets": ring_offsets, "mesh_face_offsets": face_offsets,
            "mesh_lot": np.zeros(len(faces), np.int32), "mesh_symbol": mesh.symbol[faces],
        }
        out = folder / f"{k}.png"
        render(state, out, size=(size, size), view="top", color="symbol")
        with Image.open(out) as picture:
            yield picture.convert("RGB")


def _footprints(deriving: Deriving, states: States) -> np.ndarray:
    """(n, 3, 4): each state's lot's footprint rectangle as the transform of the unit quad, in world."""
    origin, axes, size, _ = lot_scopes(deriving.lots)
    lot = states.lot
    xform = np.zeros((len(lot), 3, 4))
    # the quad's columns are the scope's z and x axes for a footprint flat along y (``backend.terminals``)
    xform[:, :, 0] = axes[lot, 2] * size[lot, 2:3]
    xform[:, :, 1] = axes[lot, 0] * size[lot, 0:1]
    xform[:, :, 3] = origin[lot] - 0.01 * axes[lot, 1]  # just under the leaves
    return xform
