"""Make the props' GLB assets: a wind turbine's tower, nacelle and rotor, two trees, a fence post and panel.

Each asset is a small trimesh scene written as binary glTF, deterministically (the same script writes the
same bytes), at its real size in metres: the grammar inserts some fitted to a scope and some at their own
size (``keepSizeAlignPosition``). glTF is y-up, and so are all of them but the rotor, which is written
z-up on purpose, as a CAD tool would export it: the grammar inserts it with ``i(..., zUp, ...)``. The
trees are two nodes each (trunk and crown placed by their node transforms), as exported models are.

    python make_assets.py [--out assets]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import trimesh
from trimesh.transformations import rotation_matrix, translation_matrix

SIDES = 10  # sections of the round parts of the turbine
#: Sections of the trees' round parts: a tree stays under 64 triangles, which ``render`` draws as meshes
#: however small (a heavier asset far away is drawn as its box)
TREE_SIDES = 6


def y_up(mesh: trimesh.Trimesh) -> trimesh.Trimesh:
    """trimesh's round primitives stand along z: turn them to stand along y (glTF's up)."""
    return mesh.apply_transform(rotation_matrix(-np.pi / 2, [1, 0, 0]))


def frustum(bottom: float, top: float, height: float, sides: int = SIDES) -> trimesh.Trimesh:
    """A capped cylinder of radius ``bottom`` at y = 0 narrowing to ``top`` at y = ``height``."""
    mesh = trimesh.creation.cylinder(radius=bottom, height=height, sections=sides)
    v = mesh.vertices.copy()
    upper = v[:, 2] > 0
    v[upper, :2] *= top / bottom
    v[:, 2] += height / 2
    return y_up(trimesh.Trimesh(v, mesh.faces, process=False))


def tower() -> trimesh.Scene:
    return trimesh.Scene(frustum(2.0, 1.2, 60.0))


def nacelle() -> trimesh.Scene:
    """A housing 3 x 3 x 8 m along z, its hub cone facing +z."""
    housing = trimesh.creation.box(extents=(3, 3, 8), transform=translation_matrix((0, 1.5, 0)))
    hub = trimesh.creation.cone(radius=1.3, height=2.0, sections=SIDES, transform=translation_matrix((0, 1.5, 4)))
    return trimesh.Scene([housing, hub])


def rotor() -> trimesh.Scene:
    """Three blades of 24 m in the x-z plane (z up), their faces towards -y: a z-up export."""
    blades = []
    for k in range(3):
        blade = trimesh.creation.box(extents=(1.6, 0.3, 24.0), transform=translation_matrix((0, 0, 12.5)))
        blades.append(blade.apply_transform(rotation_matrix(2 * np.pi * k / 3, [0, 1, 0])))
    hub = trimesh.creation.icosphere(subdivisions=1, radius=1.2)
    return trimesh.Scene([*blades, hub])


def broadleaf() -> trimesh.Scene:
    """A trunk and a round crown, each placed by its node."""
    scene = trimesh.Scene()
    scene.add_geometry(frustum(0.3, 0.2, 3.0, TREE_SIDES), node_name="trunk")
    crown = trimesh.creation.icosphere(subdivisions=0, radius=3.0)
    crown.apply_scale([1.0, 0.85, 1.0])
    scene.add_geometry(crown, node_name="crown", transform=translation_matrix((0, 5.5, 0)))
    return scene


def conifer() -> trimesh.Scene:
    """A trunk and two stacked cones."""
    scene = trimesh.Scene()
    scene.add_geometry(frustum(0.25, 0.15, 2.0, TREE_SIDES), node_name="trunk")
    for k, (radius, height, base) in enumerate(((2.2, 6.0, 1.5), (1.5, 5.0, 5.0))):
        cone = y_up(trimesh.creation.cone(radius=radius, height=height, sections=8))
        scene.add_geometry(cone, node_name=f"crown{k}", transform=translation_matrix((0, base, 0)))
    return scene


def post() -> trimesh.Scene:
    """A square post 0.12 x 1.3 m with a pyramid cap."""
    shaft = trimesh.creation.box(extents=(0.12, 1.2, 0.12), transform=translation_matrix((0, 0.6, 0)))
    cap = y_up(trimesh.creation.cone(radius=0.085, height=0.1, sections=4))
    cap.apply_transform(rotation_matrix(np.pi / 4, [0, 1, 0]))
    cap.apply_translation((0, 1.2, 0))
    return trimesh.Scene([shaft, cap])


def panel() -> trimesh.Scene:
    """Three rails 2.4 m long on a 1.1 m high panel."""
    return trimesh.Scene([trimesh.creation.box(extents=(2.4, 0.08, 0.04), transform=translation_matrix((0, y, 0)))
                          for y in (0.15, 0.6, 1.05)])


ASSETS = {
    "turbine/tower.glb": tower, "turbine/nacelle.glb": nacelle, "turbine/rotor.glb": rotor,
    "trees/broadleaf.glb": broadleaf, "trees/conifer.glb": conifer,
    "fence/post.glb": post, "fence/panel.glb": panel,
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "assets")
    args = parser.parse_args()
    for name, make in ASSETS.items():
        path = args.out / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(make().export(file_type="glb"))
        print(f"{path}: {path.stat().st_size:,} bytes")


if __name__ == "__main__":
    main()
