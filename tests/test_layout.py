"""The house's floors (docs/architecture.md): imports go down, never up, never sideways, never round.

Every ``grammarc`` module's imports are read with ``ast`` (those inside functions too: a lazy import that
dodges a circle is still a circle), and checked against ``FLOORS``: a module may import its own package and
the floors below its own, nothing else.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "grammarc"

#: From the ground up; the packages (or top-level modules) of one floor do not import each other.
FLOORS = (
    ("grammarc", "constants", "diagnostics", "ragged", "atomic", "releases"),
    ("errors",),
    ("ir",),
    ("model",),
    ("frontend", "geometry"),
    ("compiler", "backend"),
    ("io", "render"),
    ("workers", "server"),
    ("build", "search"),
    ("cluster", "conform"),
    ("commands",),
    ("cli",),
    ("client",),
)
FLOOR = {room: level for level, rooms in enumerate(FLOORS) for room in rooms}


def _modules() -> dict[str, Path]:
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return found


def _imports(modules: dict[str, Path]) -> dict[str, set[str]]:
    """Module -> the grammarc modules it imports (``from a import b`` is ``a.b`` when that is a module)."""
    edges: dict[str, set[str]] = defaultdict(set)
    for name, path in modules.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                targets = [node.module, *(f"{node.module}.{alias.name}" for alias in node.names)]
            else:
                continue
            edges[name].update(t for t in targets if t in modules and t != name)
    return edges


def _room(module: str) -> str:
    """The package of a module (``grammarc.io.npz`` -> ``io``), or the top-level module's name."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else parts[0]


def test_every_room_has_a_floor():
    assert {_room(m) for m in _modules()} <= set(FLOOR)


def upward(edges: dict[str, set[str]]) -> list[str]:
    """The imports that go up a floor, or sideways to another package of the same floor."""
    return sorted(f"{a} imports {b}" for a, targets in edges.items() for b in targets
                  if _room(a) != _room(b) and FLOOR[_room(b)] >= FLOOR[_room(a)])


def circles(edges: dict[str, set[str]]) -> list[list[str]]:
    """Import circles, each as the path that closes it."""
    state: dict[str, int] = {}  # 1 on the path, 2 done
    found = []

    def visit(module: str, path: list[str]) -> None:
        state[module] = 1
        for target in sorted(edges.get(module, ())):
            if state.get(target) == 1:
                found.append(path[path.index(target):] + [target])
            elif target not in state:
                visit(target, [*path, target])
        state[module] = 2

    for module in sorted(edges):
        if module not in state:
            visit(module, [module])
    return found


def test_imports_go_down_or_stay_in_their_package():
    assert upward(_imports(_modules())) == []


def test_no_import_circle():
    assert circles(_imports(_modules())) == []


def test_the_checks_catch_what_they_claim_to():
    assert upward({"grammarc.model.lots": {"grammarc.io.npz"}}) == ["grammarc.model.lots imports grammarc.io.npz"]
    assert upward({"grammarc.io.npz": {"grammarc.render.raster"}}) != []  # sideways, one floor
    assert upward({"grammarc.io.npz": {"grammarc.io.obj", "grammarc.model.records"}}) == []
    assert circles({"grammarc.a": {"grammarc.b"}, "grammarc.b": {"grammarc.c"}, "grammarc.c": {"grammarc.a"}}) \
        == [["grammarc.a", "grammarc.b", "grammarc.c", "grammarc.a"]]
