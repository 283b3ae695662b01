"""Cameras that frame a city's bounding box: an oblique perspective view (the default) and a top view.

World is y-up with map north at -z (README, "The record"). The oblique camera looks at the
box's centre from the south-south-east, down at ``OBLIQUE_ELEVATION``: the south and east walls face it,
and the sun (``SUN``, from the south-west) lights the south walls and leaves the east ones in shade, so
roofs, south and east walls take three different shades. The top camera is orthographic, looking down,
with north up in the picture.

Fitting: the eye stands back along its viewing direction until the box's eight corners are inside a
``FOV``-degree frustum, which sets how strong the perspective is; then the focal length and the principal
point are chosen so that the corners' projections span the picture less ``MARGIN`` on each side, centred.
The whole box is in the picture, as large as it fits.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from grammarc.render.raster import project

__all__ = ["MARGIN", "VIEWS", "Camera", "fit_camera"]

#: The views ``fit_camera`` makes.
VIEWS = ("oblique", "top")
#: Part of the picture's width and height left free on each side of the city.
MARGIN = 0.04
#: Oblique view: the eye looks north turned this many degrees to the west, down at ``OBLIQUE_ELEVATION``
#: degrees, with a frustum of ``FOV`` degrees across the shorter side before fitting.
OBLIQUE_AZIMUTH = 30.0
OBLIQUE_ELEVATION = 35.0
FOV = 30.0
#: Direction towards the sun (world, not normalized): from the south-west, high.
SUN = (-0.45, 0.75, 0.5)
#: Shade of a face turned away from the sun, and the part added by full sun (Lambert).
AMBIENT = 0.45
DIFFUSE = 0.55


@dataclass(frozen=True, eq=False)
class Camera:
    """A fitted camera, as the arrays the rasterizer takes (see ``raster``'s module docstring).

    Attributes
    ----------
    view : (3, 4) float64
        World to camera coordinates (x right, y up, z forward): ``c = view[:, :3] @ p + view[:, 3]``.
    lens : (4,) float64
        Focal length (pixels), principal point x and y (pixels), near distance.
    perspective : bool
        Perspective (oblique view) or orthographic (top view).
    size : (int, int)
        The picture's width and height in pixels.
    """

    view: np.ndarray
    lens: np.ndarray
    perspective: bool
    size: tuple[int, int]

    def to_camera(self, points) -> np.ndarray:
        """Camera coordinates (n, 3) float64 of world ``points`` (n, 3)."""
        points = np.asarray(points, np.float64).reshape(-1, 3)
        return points @ self.view[:, :3].T + self.view[:, 3]

    def project(self, points) -> np.ndarray:
        """(n, 3) float64: pixel x (column), pixel y (row) and nearness of world ``points`` (n, 3).

        Pixel (i, j) covers [i, i + 1) x [j, j + 1); nearness is larger for points closer to the eye.
        """
        cam = self.to_camera(points)
        return project(cam, self.lens, self.perspective, np.empty_like(cam))

    def light(self) -> np.ndarray:
        """(5,) float64: the unit direction towards ``SUN`` in camera coordinates, then ``AMBIENT`` and
        ``DIFFUSE``."""
        sun = np.asarray(SUN, np.float64)
        sun = self.view[:, :3] @ (sun / np.linalg.norm(sun))
        return np.array([*sun, AMBIENT, DIFFUSE])


def fit_camera(low, high, size: tuple[int, int], view: str = "oblique") -> Camera:
    """The camera of ``view`` that shows the box [low, high] whole and as large as it fits.

    Parameters
    ----------
    low, high : (3,) float
        Corners of the world bounding box; a box of no extent along an axis is fine (a flat city), and a
        point becomes a unit box around it.
    size : (int, int)
        Width and height of the picture in pixels.
    view : str
        ``"oblique"`` (perspective from above at an angle) or ``"top"`` (orthographic, north up).

    Examples
    --------
    >>> camera = fit_camera([0, 0, -10], [10, 0, 0], (100, 100), "top")
    >>> camera.project([[0, 0, 0], [10, 0, -10]])[:, :2].round(3).tolist()
    [[4.0, 96.0], [96.0, 4.0]]
    """
    if view not in VIEWS:
        raise ValueError(f"view must be one of {', '.join(VIEWS)}, got {view!r}")
    low, high = np.asarray(low, np.float64), np.asarray(high, np.float64)
    centre = 0.5 * (low + high)
    radius = 0.5 * float(np.linalg.norm(high - low))
    if radius == 0.0:
        low, high, radius = centre - 0.5, centre + 0.5, 0.5 * np.sqrt(3.0)
    corners = np.array([[high[j] if k >> j & 1 else low[j] for j in range(3)] for k in range(8)]) - centre
    if view == "top":
        # Rows: right = east, up = north, forward = down.
        rotation = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, -1.0, 0.0]])
        distance = 2.0 * radius  # orthographic: the distance only puts the eye above the city
    else:
        azimuth, elevation = np.radians(OBLIQUE_AZIMUTH), np.radians(OBLIQUE_ELEVATION)
        level = np.array([-np.sin(azimuth), 0.0, -np.cos(azimuth)])  # north, turned west
        forward = np.cos(elevation) * level + np.array([0.0, -np.sin(elevation), 0.0])
        right = np.cross(forward, [0.0, 1.0, 0.0])
        right /= np.linalg.norm(right)
        rotation = np.stack([right, np.cross(right, forward), forward])
        # Back off until every corner is inside the frustum: |x| <= z tan(FOV / 2), the same for y, so
        # z = distance + corner . forward must reach |x| / tan; and keep the nearest corner well in front.
        local = corners @ rotation.T
        tangent = np.tan(np.radians(FOV) / 2)
        needed = np.maximum(np.abs(local[:, 0]), np.abs(local[:, 1])) / tangent - local[:, 2]
        distance = max(float(needed.max()), float((radius - local[:, 2]).max()))
    eye = centre - distance * rotation[2]
    view_matrix = np.concatenate([rotation, (-rotation @ eye)[:, None]], axis=1)
    local = corners @ rotation.T + [0.0, 0.0, distance]
    perspective = view == "oblique"
    # The corners on the image plane at unit focal length; focal and principal point fit them to the frame.
    plane = local[:, :2] / local[:, 2:] if perspective else local[:, :2]
    span = np.maximum(plane.max(axis=0) - plane.min(axis=0), 1e-12 * radius)
    width, height = size
    focal = float(min(width * (1 - 2 * MARGIN) / span[0], height * (1 - 2 * MARGIN) / span[1]))
    mid = 0.5 * (plane.max(axis=0) + plane.min(axis=0))
    near = 1e-3 * distance
    lens = np.array([focal, 0.5 * width - focal * mid[0], 0.5 * height + focal * mid[1], near])
    return Camera(view=view_matrix, lens=lens, perspective=perspective, size=(int(width), int(height)))
