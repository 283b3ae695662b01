"""backend/functions/images.py: an image's resolution, and images chosen by their proportions.

Values from the CGA reference's ``imageInfo`` page (a 512 x 1024 texture) and the ``ce.lib`` definitions
of ``imageBestRatio`` and ``imageApproxRatio``. A lot w x h has the scope w x 0 x h: ``xz`` compares an
image's width / height with w / h.
"""

from __future__ import annotations

import io

import pytest
from function_derivations import derived, rectangles, reported, write_files
from PIL import Image

from grammarc.backend.functions import images


def png(width: int, height: int) -> bytes:
    out = io.BytesIO()
    Image.new("RGB", (width, height)).save(out, format="PNG")
    return out.getvalue()


#: Images of width / height 1, 2 and 4.
WIDE = {"tex/square.png": png(16, 16), "tex/two.png": png(32, 16), "tex/four.png": png(64, 16)}


def test_image_info_is_the_resolution_in_pixels(tmp_path):
    write_files(tmp_path, {"myTexture.jpg": png(512, 1024), "broken.png": b"not an image"})
    r = derived(tmp_path, 'Lot --> report("sx", imageInfo("myTexture.jpg", sx)) report("sy", imageInfo("myTexture.jpg", sy))'
                          ' report("q", imageInfo("myTexture.jpg", "sy")) report("none", imageInfo("gone.png", sx))'
                          ' report("bad", imageInfo("broken.png", sx))', rectangles((1, 1)))
    assert (reported(r, "sx"), reported(r, "sy"), reported(r, "q")) == ([512], [1024], [1024])
    assert (reported(r, "none"), reported(r, "bad")) == ([0], [0])


def test_only_the_header_is_read_and_once_per_file(tmp_path, monkeypatch):
    write_files(tmp_path, {"t.png": png(8, 4)})
    opened = []
    original = Image.open
    monkeypatch.setattr(Image, "open", lambda *a, **k: opened.append(a) or original(*a, **k))
    images._header_size.cache_clear()
    r = derived(tmp_path, 'Lot --> report("w", imageInfo("t.png", sx))', rectangles(*[(1, 1)] * 20))
    assert reported(r, "w") == [8] * 20 and len(opened) == 1


def test_images_sort_ratio_orders_by_proportions(tmp_path):
    write_files(tmp_path, WIDE)
    r = derived(tmp_path, 'Lot --> report("xz", imagesSortRatio(fileSearch("tex/*"), xz)) '
                          'report("zx", imagesSortRatio(fileSearch("tex/*"), zx))', rectangles((4, 1)))
    assert reported(r, "xz") == ["tex/four.png;tex/two.png;tex/square.png;"]
    assert reported(r, "zx") == ["tex/square.png;tex/two.png;tex/four.png;"]  # 1 / 4: the narrowest first


@pytest.mark.parametrize("lot, best", [((1, 1), "tex/square.png"), ((2, 1), "tex/two.png"), ((8, 2), "tex/four.png")])
def test_image_best_ratio(tmp_path, lot, best):
    write_files(tmp_path, WIDE)
    r = derived(tmp_path, 'Lot --> report("b", imageBestRatio("tex/*.png", "xz")) '
                          'report("one", imageApproxRatio("tex/*.png", "xz", 1))', rectangles(lot))
    assert reported(r, "b") == [best] and reported(r, "one") == [best]


def test_image_approx_ratio_draws_among_the_n_best_or_all(tmp_path):
    write_files(tmp_path, WIDE)
    r = derived(tmp_path, 'Lot --> report("two", imageApproxRatio("tex/*.png", "xz", 2)) '
                          'report("all", imageApproxRatio("tex/*.png", "xz", 0))', rectangles(*[(2.5, 1)] * 40))
    assert set(reported(r, "two")) == {"tex/two.png", "tex/four.png"}  # 2.5 is nearer 2 and 4 than 1
    assert set(reported(r, "all")) == set(WIDE)
