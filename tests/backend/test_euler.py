"""backend/euler.py: CGA's Euler angles, the rotation they describe and back."""

from __future__ import annotations

import numpy as np
import pytest

from grammarc.backend import euler


def test_angles_read_back_an_orientation():
    angles = np.array([[10.0, 20.0, 30.0], [-10.0, 70.0, 0.0], [0.0, 0.0, 45.0], [170.0, -80.0, -120.0]])
    np.testing.assert_allclose(euler.angles(euler.orientation(*angles.T)), angles, atol=1e-9)


def test_an_orientation_turns_about_the_fixed_axes_in_order():
    """About the old x, then y: the y turn is about the old y, so the x axis ends in the old xz plane."""
    x_axis = euler.orientation(np.array([90.0]), np.array([90.0]), np.array([0.0]))[0, 0]
    np.testing.assert_allclose(x_axis, [0.0, 0.0, -1.0], atol=1e-12)


@pytest.mark.parametrize("axis", range(3))
def test_about_one_axis_rotation_and_orientation_agree(axis):
    angles = np.zeros((3, 2))
    angles[axis] = [35.0, -120.0]
    np.testing.assert_allclose(euler.rotation(*angles), euler.orientation(*angles), atol=1e-12)
    for m in euler.rotation(*angles):
        np.testing.assert_allclose(m @ m.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(m) == pytest.approx(1.0)
