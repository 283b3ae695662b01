"""grammarc's geometry measured as PRT's records are, and the two compared.

The checks follow the kit's README, in its order:

1. bounding box (``bbox_min``, ``bbox_max``), to ~1e-4 m;
2. surface area (``surface_area``, the sum of PRT's triangle areas, holes handled), to a relative 1e-4;
3. face counts (``n_faces``, polygons as PRT's encoder returns them, a hole ring counting as a face;
   ``n_triangles``), reported, and checked only when asked: grammarc's assets and splits need not
   cut faces as PRT does;
4. reports, key by key (``compare_reports``).

``measure`` takes a baked mesh (``grammarc.io.bake.bake``), whose ``metadata`` carries the polygon
counts; ``surface_distance`` compares two meshes point by point (a PRT export, or the triangles the
differential harness gets from PRT).

Example, from the repository root::

    reference = load_reference()
    expected = find_record(reference, "extrude_color", "rect_30x20", {})
    verdict = compare(measure(bake(record)), expected)
    print(verdict.summary)
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from grammarc.errors import UsageError

__all__ = ["Verdict", "compare", "compare_reports", "measure", "surface_distance"]

#: The README's tolerances: coordinates to 0.1 mm, areas to a relative 1e-4.
BBOX_TOL = 1e-4
AREA_REL_TOL = 1e-4
#: Nearest sample sites whose triangles ``surface_distance`` tries per point. With 8, a point near the
#: diagonal of a large quad sometimes had only sites of the quad's other triangle (a 1e-5 m mean error
#: on a 10 m cube); 16 was exact there.
_CANDIDATES = 16
#: Record fields of a report that are compared: numbers to a relative 1e-9, the rest exactly.
_REPORT_REL_TOL = 1e-9


def measure(mesh, polygons: int | None = None) -> dict:
    """The reference fields of a mesh: bounding box, surface area, triangle and polygon counts.

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Triangles (a baked record, or a PRT export loaded with trimesh).
    polygons : int, optional
        The number of polygons the triangles came from, counted as PRT counts faces; by default
        ``mesh.metadata["n_polygons"]`` (set by ``bake``), else None.

    Returns
    -------
    dict
        ``bbox_min``, ``bbox_max``, ``bbox_size`` (lists of 3 floats; NaN for a mesh without
        triangles), ``surface_area`` (float), ``n_triangles`` (int), ``n_faces`` (int or None) and
        ``face_sizes`` (dict: vertex count -> polygons, from ``bake``'s metadata, or None).
    """
    metadata = getattr(mesh, "metadata", None) or {}
    if polygons is None:
        polygons = metadata.get("n_polygons")
    faces = np.asarray(mesh.faces)
    if len(faces):
        used = np.zeros(len(mesh.vertices), bool)
        used[faces.ravel()] = True  # vertices no triangle uses do not count
        corners = np.asarray(mesh.vertices)[used]
        low, high = corners.min(axis=0), corners.max(axis=0)
    else:
        low = high = np.full(3, np.nan)
    face_sizes = metadata.get("face_sizes")
    return {
        "bbox_min": [float(x) for x in low],
        "bbox_max": [float(x) for x in high],
        "bbox_size": [float(x) for x in high - low],
        "surface_area": float(mesh.area) if len(faces) else 0.0,
        "n_triangles": len(faces),
        "n_faces": None if polygons is None else int(polygons),
        "face_sizes": None if face_sizes is None else {int(k): int(v) for k, v in face_sizes.items()},
    }


@dataclass(frozen=True)
class Verdict:
    """The outcome of ``compare``: each check's deviation and whether it passed.

    Attributes
    ----------
    bbox_deviation : float
        Largest absolute difference of the six bounding box coordinates, metres (NaN: no geometry).
    area_rel_error : float
        ``|measured - expected| / expected`` surface area (inf if only one of them is 0).
    face_difference : int or None
        Measured minus expected ``n_faces``; None if either is unknown.
    triangle_difference : int or None
        Measured minus expected ``n_triangles``; None if either is unknown.
    bbox_ok, area_ok : bool
        Within ``bbox_tol`` and ``area_rel_tol``.
    faces_ok : bool or None
        ``|face_difference| <= faces_tol``; None when face counts were not checked.
    passed : bool
        Every check made passed.
    summary : str
        One line: PASS or FAIL and each figure.
    """

    bbox_deviation: float
    area_rel_error: float
    face_difference: int | None
    triangle_difference: int | None
    bbox_ok: bool
    area_ok: bool
    faces_ok: bool | None
    passed: bool
    summary: str

    def __bool__(self) -> bool:
        return self.passed

    def __str__(self) -> str:
        return self.summary


def compare(
    measured: Mapping,
    expected: Mapping,
    *,
    bbox_tol: float = BBOX_TOL,
    area_rel_tol: float = AREA_REL_TOL,
    faces_tol: int | None = None,
) -> Verdict:
    """Compare measured fields (``measure``) with a reference record (``find_record``).

    Parameters
    ----------
    measured, expected : mapping
        ``bbox_min``, ``bbox_max``, ``surface_area``, and optionally ``n_faces``, ``n_triangles``.
    bbox_tol : float
        Largest allowed deviation of a bounding box coordinate, metres.
    area_rel_tol : float
        Largest allowed relative error of the surface area.
    faces_tol : int, optional
        Largest allowed difference of ``n_faces``; face counts are reported but not checked when None.

    Returns
    -------
    Verdict

    Examples
    --------
    >>> expected = {"bbox_min": [0, 0, 0], "bbox_max": [30, 5, 20], "surface_area": 1700.0,
    ...             "n_faces": 6, "n_triangles": 12}
    >>> measured = {"bbox_min": [0, 0, 0], "bbox_max": [30, 5.00002, 20], "surface_area": 1700.01,
    ...             "n_faces": 6, "n_triangles": 12}
    >>> compare(measured, expected).summary
    'PASS bbox 2e-05 m, area 1700.01 / 1700 m2 (rel 5.9e-06), faces 6 / 6 (+0), triangles 12 / 12 (+0)'
    >>> compare(measured, expected, bbox_tol=1e-6).summary.split(",")[0]
    'FAIL bbox 2e-05 m > 1e-06'
    """
    deviation = float(np.max(np.abs(np.concatenate([
        np.asarray(measured["bbox_min"], float) - np.asarray(expected["bbox_min"], float),
        np.asarray(measured["bbox_max"], float) - np.asarray(expected["bbox_max"], float),
    ]))))  # fmt: skip
    area, reference_area = float(measured["surface_area"]), float(expected["surface_area"])
    if reference_area != 0:
        rel = abs(area - reference_area) / abs(reference_area)
    else:
        rel = 0.0 if area == 0 else math.inf
    face_difference = _difference(measured, expected, "n_faces")
    triangle_difference = _difference(measured, expected, "n_triangles")
    bbox_ok = bool(deviation <= bbox_tol)  # False for NaN: no geometry
    area_ok = bool(rel <= area_rel_tol)
    faces_ok = None
    if faces_tol is not None:
        faces_ok = face_difference is not None and abs(face_difference) <= faces_tol
    passed = bbox_ok and area_ok and faces_ok is not False
    # A failed check shows its tolerance: "bbox 0.5 m > 0.0001".
    parts = [
        f"bbox {deviation:.3g} m" + ("" if bbox_ok else f" > {bbox_tol:g}"),
        f"area {area:.6g} / {reference_area:.6g} m2 (rel {rel:.2g}"
        + (")" if area_ok else f" > {area_rel_tol:g})"),
    ]
    if face_difference is not None:
        parts.append(f"faces {measured['n_faces']} / {expected['n_faces']} ({face_difference:+d}"
                     + (f" > {faces_tol})" if faces_ok is False else ")"))
    if triangle_difference is not None:
        parts.append(f"triangles {measured['n_triangles']} / {expected['n_triangles']} "
                     f"({triangle_difference:+d})")
    summary = ("PASS " if passed else "FAIL ") + ", ".join(parts)
    return Verdict(deviation, rel, face_difference, triangle_difference, bbox_ok, area_ok, faces_ok, passed,
                   summary)


def _difference(measured: Mapping, expected: Mapping, key: str) -> int | None:
    a, b = measured.get(key), expected.get(key)
    return None if a is None or b is None else int(a) - int(b)


def surface_distance(mesh_a, mesh_b, n: int = 20000, seed: int = 0) -> float:
    """Symmetric mean distance between two surfaces, from points sampled on each.

    ``n`` points are sampled on each mesh (area-weighted, seeded); each point's distance to the other
    surface is the exact distance to the nearest of a few candidate triangles, the triangles of its 16
    nearest sites among ``4 n`` points sampled on the other mesh and the centroids of its triangles
    (scipy's cKDTree). The result is the mean of the two directions' means. It is an upper bound of the
    exact figure, equal to it where each point's nearest triangle is among its candidates (almost
    everywhere: the candidates surround the point). Elsewhere, close to the edge between two triangles,
    the excess is at most the point's distance to its nearest site, below the spacing of the sites, and
    in practice far less (a 10 m cube against itself gives ~1e-6 m).

    Parameters
    ----------
    mesh_a, mesh_b : trimesh.Trimesh or trimesh.Scene
        Triangle meshes with some area (a scene is merged into one mesh).
    n : int
        Points sampled on each mesh.
    seed : int
        Seed of the sampling.

    Returns
    -------
    float
        Metres (the meshes' unit).

    Raises
    ------
    ValueError
        If a mesh has no area.
    UsageError
        If scipy is missing.
    """
    try:
        from scipy.spatial import cKDTree
    except ImportError as error:
        raise UsageError("surface_distance needs scipy: pip install scipy") from error
    import trimesh

    a, b = _as_mesh(mesh_a), _as_mesh(mesh_b)
    for name, mesh in (("mesh_a", a), ("mesh_b", b)):
        if len(mesh.faces) == 0 or not mesh.area > 0:
            raise ValueError(f"surface_distance: {name} has no area")
    points_a, _ = trimesh.sample.sample_surface(a, n, seed=seed)
    points_b, _ = trimesh.sample.sample_surface(b, n, seed=seed + 1)
    to_b = _distances(np.asarray(points_a), b, 4 * n, seed + 2, cKDTree)
    to_a = _distances(np.asarray(points_b), a, 4 * n, seed + 3, cKDTree)
    return float((to_b.mean() + to_a.mean()) / 2)


def _distances(points: np.ndarray, mesh, n_sites: int, seed: int, tree_class) -> np.ndarray:
    """(n,) distance of each of ``points`` (n, 3) to ``mesh``'s surface (see ``surface_distance``)."""
    import trimesh

    triangles = np.asarray(mesh.triangles)  # (t, 3, 3)
    samples, sample_face = trimesh.sample.sample_surface(mesh, n_sites, seed=seed)
    sites = np.concatenate([np.asarray(samples), triangles.mean(axis=1)])
    site_face = np.concatenate([np.asarray(sample_face), np.arange(len(triangles))])
    k = min(_CANDIDATES, len(sites))
    site_distance, nearest = tree_class(sites).query(points, k=k)
    site_distance = np.asarray(site_distance).reshape(len(points), k)
    candidates = site_face[np.asarray(nearest).reshape(len(points), k)]  # (n, k) triangle ids
    repeated = np.repeat(points, k, axis=0)
    closest = trimesh.triangles.closest_point(triangles[candidates.ravel()], repeated)
    exact = np.linalg.norm(closest - repeated, axis=1).reshape(len(points), k)
    # A degenerate triangle may give NaN; a site's own distance is an upper bound either way.
    exact = np.where(np.isfinite(exact), exact, np.inf)
    return np.minimum(exact.min(axis=1), site_distance.min(axis=1))


def _as_mesh(mesh):
    """A Trimesh from a Trimesh, a Scene (merged), or a path trimesh can load."""
    import trimesh

    if isinstance(mesh, (str, os.PathLike)):
        mesh = trimesh.load(mesh, force="mesh", process=False)
    if isinstance(mesh, trimesh.Scene):
        mesh = mesh.to_mesh()
    return mesh



def compare_reports(ours: Mapping, theirs: Mapping) -> tuple[bool, tuple[str, ...]]:
    """PRT's flat report (``key_n``, ``key_sum``...) against grammarc's totals for the same model."""
    differences = []
    for key in sorted(set(ours) | set(theirs)):
        a, b = ours.get(key), theirs.get(key)
        if a is None or b is None:
            differences.append(f"{key}: {'missing' if a is None else a} vs {'missing' if b is None else b}")
        elif isinstance(b, (int, float)) and not isinstance(b, bool) and not isinstance(a, (bool, str)):
            if not math.isclose(float(a), float(b), rel_tol=_REPORT_REL_TOL, abs_tol=1e-12):
                differences.append(f"{key}: {a} vs {b}")
        elif a != b:
            differences.append(f"{key}: {a} vs {b}")
    return not differences, tuple(differences)

