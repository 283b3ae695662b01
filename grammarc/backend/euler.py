"""CGA's Euler angles: the rotation that angles describe, and the angles of a rotation.

A rotation here is a matrix whose rows are the new axes in the coordinates of the old ones, as the rows of
a scope frame are its axes in world. CityEngine reports an orientation as three angles in degrees about the
old (fixed) axes x, then y, then z (``scope.rx``, ``convert(..., orient, ...)``): ``orientation`` makes
that rotation and ``angles`` reads it back. The reference's ``convert`` example shows this order: after
``r(-10, 70, 0)`` on a lot turned about the vertical, the scope's orientation in world is (-10, 70 plus
the lot's turn, 0).

``rotation`` is what the paper's ``R`` applies: about x, then the new y, then the new z. It is the same
rotation as ``orientation`` when one angle only is not 0, and the other order when more are; CityEngine's
``r`` and ``rotateScope`` turn by ``orientation``.
"""

from __future__ import annotations

import numpy as np

from grammarc.backend.functions.math import elementwise


def rotation(ax: np.ndarray, ay: np.ndarray, az: np.ndarray) -> np.ndarray:
    """(n, 3, 3) matrices M with new axes = M @ axes: about x, then the new y, then the new z.

    Parameters
    ----------
    ax, ay, az : (n,) float64
        The angles in degrees.
    """
    n = len(ax)
    out = np.empty((n, 3, 3))
    cx, sx = _cos_sin(ax)
    cy, sy = _cos_sin(ay)
    cz, sz = _cos_sin(az)
    one, zero = np.ones(n), np.zeros(n)
    mx = np.stack([np.stack([one, zero, zero], 1), np.stack([zero, cx, sx], 1),
                   np.stack([zero, -sx, cx], 1)], 1)
    my = np.stack([np.stack([cy, zero, -sy], 1), np.stack([zero, one, zero], 1),
                   np.stack([sy, zero, cy], 1)], 1)
    mz = np.stack([np.stack([cz, sz, zero], 1), np.stack([-sz, cz, zero], 1),
                   np.stack([zero, zero, one], 1)], 1)
    np.matmul(mz, np.matmul(my, mx), out=out)
    return out


def orientation(ax: np.ndarray, ay: np.ndarray, az: np.ndarray) -> np.ndarray:
    """(n, 3, 3) matrices M with new axes = M @ axes: about the old x, then y, then z (degrees, (n,) each).

    They are ``angles``' inverse: the rotations whose angles CityEngine reports as (ax, ay, az).
    """
    # about the fixed x, y, z is about z, the new y, the new x: Mx @ My @ Mz, ``rotation``'s reversed order,
    # which is the transpose of the rotation by the opposite angles
    return np.swapaxes(rotation(-np.asarray(ax), -np.asarray(ay), -np.asarray(az)), 1, 2)


def angles(matrices: np.ndarray) -> np.ndarray:
    """The angles (n, 3) in degrees about x, then y, then z of rotations (n, 3, 3): ``orientation``'s inverse.

    Where the y angle is +-90 degrees (gimbal lock), the x angle takes what x and z cannot tell apart.
    """
    # matrices = Mx @ My @ Mz with the factors of ``rotation``; read the angles off its entries
    ry = np.degrees(np.arcsin(np.clip(-matrices[:, 0, 2], -1.0, 1.0)))
    rx = np.degrees(np.arctan2(matrices[:, 1, 2], matrices[:, 2, 2]))
    rz = np.degrees(np.arctan2(matrices[:, 0, 1], matrices[:, 0, 0]))
    return np.stack([rx, ry, rz], axis=1)


def _cos_sin(degrees: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    d = np.ascontiguousarray(degrees, dtype=np.float64)
    return elementwise(1, d), elementwise(0, d)
