"""The rasterizer and the cameras: coverage, depth order, flat Lambert shading, the three ways an instance
is drawn, and framing."""

import numpy as np
import pytest

from grammarc.model.assets import builtin_mesh
from grammarc.render.camera import MARGIN, fit_camera
from grammarc.render.raster import draw_instances, draw_triangles, project

# An orthographic camera looking down -z onto the x-y plane, 1 pixel per unit, y up; sun along the eye.
LENS = np.array([1.0, 0.0, 10.0, 0.0])
LIGHT = np.array([0.0, 0.0, -1.0, 0.3, 0.6])


def canvas(h=10, w=10):
    return np.zeros((h, w, 3), np.uint8), np.full((h, w), -np.inf)


def triangles(points, faces, colors, light=LIGHT, image=None, depth=None):
    """Draw triangles given in camera space with the orthographic LENS; (image, depth)."""
    if image is None:
        image, depth = canvas()
    cam = np.asarray(points, float)
    screen = project(cam, LENS, False, np.empty_like(cam))
    draw_triangles(cam, screen, np.asarray(faces, np.int64), np.asarray(colors, np.uint8), 0.0, False, light,
                   image, depth)
    return image, depth


def test_triangle_covers_the_pixel_centres_inside_it():
    # The lower-left half of the square [0, 8]^2 (image rows grow downwards: y = 10 - row).
    image, _ = triangles([[0, 2, 5], [8, 2, 5], [0, 10, 5]], [[0, 1, 2]], [[100, 100, 100]])
    covered = image[:, :, 0] > 0
    rows, cols = np.mgrid[0:10, 0:10]
    x, y = cols + 0.5, 10 - (rows + 0.5)
    inside = (x <= 8) & (y >= 2) & (x + y <= 10)
    assert (covered == inside).all()


@pytest.mark.parametrize("order", ["near first", "far first", "equal depth"])
def test_nearer_triangle_wins_whatever_the_order_and_ties_keep_the_first(order):
    square = [[0, 0], [10, 0], [10, 10], [0, 10]]
    red = [[x, y, 1.0] for x, y in square]
    blue = [[x, y, 1.0 if order == "equal depth" else 2.0] for x, y in square]
    first, second = (blue, red) if order == "far first" else (red, blue)
    colors = [[200, 0, 0]] * 2 + [[0, 0, 200]] * 2
    if order == "far first":
        colors = colors[::-1]
    image, _ = triangles(first + second, [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]], colors)
    assert (image[:, :, 0] > 0).all() and (image[:, :, 2] == 0).all()


def test_flat_lambert_is_two_sided():
    facing_sun = [[0, 0, 1], [10, 0, 1], [0, 10, 1]]
    for faces in ([[0, 1, 2]], [[0, 2, 1]]):  # either winding faces the eye
        image, _ = triangles(facing_sun, faces, [[200, 100, 50]])
        np.testing.assert_array_equal(image[8, 1], np.round(np.array([200, 100, 50]) * 0.9))
    # Sun perpendicular to the face: ambient only.
    image, _ = triangles(facing_sun, [[0, 1, 2]], [[200, 100, 50]], light=np.array([1.0, 0, 0, 0.3, 0.6]))
    np.testing.assert_array_equal(image[8, 1], np.round(np.array([200, 100, 50]) * 0.3))


def instances(xforms, asset, detail_px, splat_px=2.0, size=(64, 64)):
    """Draw cubes (asset 0), a heavy cylinder (asset 1) and the box table entry, orthographically from the
    top (camera fitted to [0, 64]^2 on the x-z plane); returns (counts, image)."""
    meshes = [builtin_mesh("builtin:cube"), builtin_mesh("builtin:cylinder64"), builtin_mesh("builtin:cube")]
    vertex_offsets = np.cumsum([0] + [len(m.vertices) for m in meshes])
    face_offsets = np.cumsum([0] + [len(m.faces) for m in meshes])
    camera = fit_camera([0, 0, -64], [64, 64, 0], size, "top")
    image, depth = canvas(*size[::-1])
    counts = draw_instances(
        np.asarray(xforms, np.float32), np.full((len(xforms), 3), 255, np.uint8), np.asarray(asset, np.int32),
        vertex_offsets, face_offsets, np.concatenate([m.vertices for m in meshes]),
        np.concatenate([m.faces for m in meshes]), np.asarray(detail_px, float), splat_px, camera.view,
        camera.lens, camera.perspective, camera.light(), image, depth)
    return counts.tolist(), image


def cube_at(x, z, edge):
    return np.concatenate([np.eye(3) * edge, [[x], [0], [-z - edge]]], axis=1)


def test_instances_are_splats_boxes_or_meshes_by_size_on_screen():
    tiny, mid, large = cube_at(2, 2, 0.5), cube_at(10, 10, 20), cube_at(40, 40, 20)
    # The fitted top camera draws 64 m on 64 (1 - 2 MARGIN) pixels: 0.5 m is a splat, 20 m is not.
    assert instances([tiny, mid, large], [0, 0, 0], [0.0, 0.0])[0] == [1, 0, 2]
    # A heavy asset (the cylinder) is its box below its detail size, its own triangles above.
    assert instances([mid, large], [1, 1], [0.0, 10.0])[0] == [0, 0, 2]
    assert instances([mid, large], [1, 1], [0.0, 100.0])[0] == [0, 2, 0]


def test_a_cylinder_drawn_as_its_box_fills_the_box_corners():
    whole = cube_at(20, 20, 30)
    _, detailed = instances([whole], [1], [0.0, 0.0])
    _, boxed = instances([whole], [1], [0.0, 100.0])
    assert boxed[:, :, 0].astype(bool).sum() > detailed[:, :, 0].astype(bool).sum()


def test_a_subpixel_instance_still_leaves_one_pixel():
    counts, image = instances([cube_at(30.2, 30.2, 0.05)], [0], [0.0, 0.0])
    assert counts == [1, 0, 0] and image[:, :, 0].astype(bool).sum() == 1


@pytest.mark.parametrize("view", ["oblique", "top"])
@pytest.mark.parametrize("size", [(160, 100), (100, 160)])
def test_fit_keeps_the_box_inside_the_margins(view, size):
    low, high = np.array([-50.0, 0, -300]), np.array([400.0, 80, 20])
    camera = fit_camera(low, high, size, view)
    corners = np.array([[high[j] if k >> j & 1 else low[j] for j in range(3)] for k in range(8)])
    xy = camera.project(corners)[:, :2]
    width, height = size
    assert (xy[:, 0] >= width * MARGIN - 1e-6).all() and (xy[:, 0] <= width * (1 - MARGIN) + 1e-6).all()
    assert (xy[:, 1] >= height * MARGIN - 1e-6).all() and (xy[:, 1] <= height * (1 - MARGIN) + 1e-6).all()
    # As large as it fits: the projection touches the margins along one axis at least.
    spans = xy.max(axis=0) - xy.min(axis=0)
    assert np.isclose(spans[0], width * (1 - 2 * MARGIN)) or np.isclose(spans[1], height * (1 - 2 * MARGIN))
    assert (camera.to_camera(corners)[:, 2] > camera.lens[3]).all()


def test_top_view_has_north_up_and_east_right():
    camera = fit_camera([0, 0, -10], [10, 5, 0], (100, 100), "top")
    (west, south), (east, north) = camera.project([[0, 5, 0], [10, 5, -10]])[:, :2]
    assert north < south and west < east  # rows grow downwards
