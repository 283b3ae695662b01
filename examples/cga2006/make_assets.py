"""Make assets/*.obj: the terminal objects the paper's grammars insert, each in the unit box.

The paper names them (``win.obj``, ``door.obj``, ``wall.obj``, ``flatbrick.obj``, ``roundbrick.obj``,
``frontwall.obj``, ``fireescape.obj``) but does not ship them; these are simple stand-ins of a few
boxes each. Section 6's trees were Xfrog models; ours are a trunk and a crown.

    python make_assets.py          # writes assets/ beside this script; the same bytes every time
"""

from __future__ import annotations

import math
from pathlib import Path

ASSETS = Path(__file__).resolve().parent / "assets"


class Obj:
    """Vertices and faces of one OBJ file."""

    def __init__(self, comment: str) -> None:
        self.lines = [f"# {comment} (grammarc example asset, unit box)"]
        self.count = 0

    def face(self, points) -> None:
        for x, y, z in points:
            self.lines.append(f"v {x:.4g} {y:.4g} {z:.4g}")
        ids = range(self.count + 1, self.count + len(points) + 1)
        self.lines.append("f " + " ".join(map(str, ids)))
        self.count += len(points)

    def box(self, x0, y0, z0, x1, y1, z1) -> None:
        """An axis-aligned box, its faces wound outwards."""
        self.face([(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)])
        self.face([(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)])
        self.face([(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)])
        self.face([(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)])
        self.face([(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)])
        self.face([(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)])

    def text(self) -> str:
        return "\n".join(self.lines) + "\n"


def obj_files() -> dict[str, str]:
    """The text of every asset, by file name."""
    out = {}
    win = Obj("a window: frame, sill and a recessed pane")
    for box in ((0, 0, 0, 1, 0.1, 1), (0, 0.9, 0, 1, 1, 1), (0, 0, 0, 0.1, 1, 1), (0.9, 0, 0, 1, 1, 1),
                (0.1, 0.1, 0, 0.9, 0.9, 0.2), (-0.05, -0.05, 0, 1.05, 0.05, 1.3)):
        win.box(*box)
    out["win.obj"] = win
    door = Obj("a door: frame and a recessed leaf")
    for box in ((0, 0, 0, 0.08, 1, 1), (0.92, 0, 0, 1, 1, 1), (0, 0.94, 0, 1, 1, 1), (0.08, 0, 0, 0.92, 0.94, 0.3)):
        door.box(*box)
    out["door.obj"] = door
    wall = Obj("a wall panel: a quad")
    wall.face([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)])
    out["wall.obj"] = wall
    front = Obj("a front wall panel: a quad with a cornice strip")
    front.face([(0, 0, 0), (1, 0, 0), (1, 0.92, 0), (0, 0.92, 0)])
    front.box(0, 0.92, 0, 1, 1, 0.15)
    out["frontwall.obj"] = front
    flat = Obj("a flat roof brick")
    flat.box(0.02, 0, 0, 0.98, 1, 1)
    out["flatbrick.obj"] = flat
    round_ = Obj("a round ridge brick: half a tube along y")
    n = 6
    for k in range(n):
        a0, a1 = math.pi * k / n, math.pi * (k + 1) / n
        p0 = (0.5 - 0.5 * math.cos(a0), 0.5 * math.sin(a0) * 2)
        p1 = (0.5 - 0.5 * math.cos(a1), 0.5 * math.sin(a1) * 2)
        round_.face([(p0[0], 0, p0[1]), (p1[0], 0, p1[1]), (p1[0], 1, p1[1]), (p0[0], 1, p0[1])])
    out["roundbrick.obj"] = round_
    escape = Obj("one flight of a fire escape: landing, stair and railing")
    escape.box(0, 0, 0, 1, 0.05, 1)
    escape.box(0, 0.95, 0.9, 1, 1, 1)
    for k in range(8):
        escape.box(k / 8, k / 8, 0.1, (k + 1) / 8, (k + 1) / 8, 0.9)
    out["fireescape.obj"] = escape
    tree = Obj("a tree: trunk and crown")
    tree.box(0.45, 0, 0.45, 0.55, 0.45, 0.55)
    tree.box(0.1, 0.4, 0.1, 0.9, 0.9, 0.9)
    tree.box(0.25, 0.85, 0.25, 0.75, 1, 0.75)
    out["tree.obj"] = tree
    shrub = Obj("a shrub")
    shrub.box(0, 0, 0.1, 1, 0.7, 0.9)
    shrub.box(0.15, 0.6, 0.2, 0.85, 1, 0.8)
    out["shrub.obj"] = shrub
    return {name: obj.text() for name, obj in out.items()}


def main() -> None:
    ASSETS.mkdir(exist_ok=True)
    for name, text in obj_files().items():
        (ASSETS / name).write_text(text)
    print(f"{ASSETS}: {len(obj_files())} assets")


if __name__ == "__main__":
    main()
