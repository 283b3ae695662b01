"""``grammarc view``: the page and a tileset served on localhost (and nothing outside them), a clear message
where the page is not built or the folder is no tileset, and the page in headless Chromium showing the
example city (where CI has installed Chromium and the viewer's packages)."""

from __future__ import annotations

import json
import shutil
import subprocess
import threading
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from grammarc.build import build
from grammarc.cli import main
from grammarc.render import view
from grammarc.render.view import address, page_missing, page_server

ROOT = Path(__file__).resolve().parents[2]
VIEWER = ROOT / "viewer"
CHROMIUM = Path("/usr/bin/chromium")
#: The page's background (index.html's scene): a screenshot of a city is mostly something else.
BACKGROUND = (223, 230, 238)


@pytest.fixture
def served(tmp_path):
    """A running server of the page and a folder holding ``tileset.json``; its address."""
    (tmp_path / "city.3dtiles").mkdir()
    (tmp_path / "city.3dtiles" / "tileset.json").write_text('{"asset": {"version": "1.1"}}')
    (tmp_path / "secret.txt").write_text("not served")
    with page_server(tmp_path / "city.3dtiles") as server:
        thread = threading.Thread(target=server.serve_forever, daemon=True)
        thread.start()
        yield address(server)
        server.shutdown()
        thread.join()


def fetch(url: str) -> tuple[int, bytes, str]:
    try:
        with urllib.request.urlopen(url) as response:
            return response.status, response.read(), response.headers["Content-Type"]
    except urllib.error.HTTPError as error:
        return error.code, b"", ""


def test_the_page_and_the_tileset_are_served_and_nothing_beside_them(served):
    status, body, kind = fetch(served)
    assert status == 200 and b'<canvas id="view">' in body and kind.startswith("text/html")
    status, body, kind = fetch(served + "tiles/tileset.json")
    assert (status, kind) == (200, "application/json") and json.loads(body)["asset"]["version"] == "1.1"
    assert fetch(served + "tiles/../../secret.txt")[0] == 404
    assert fetch(served + "tiles/%2e%2e/secret.txt")[0] == 404


def test_a_record_is_served_through_a_tileset_written_for_the_while(tmp_path, monkeypatch):
    (tmp_path / "g.cga").write_text("Lot --> extrude(9) Mass\nMass --> i(\"builtin:cube\")\n")
    build(tmp_path / "g.cga", tmp_path / "city.npz")
    served = []

    def serve(folder, **options):
        tileset = json.loads((folder / "tileset.json").read_text())
        served.append((folder, tileset["extras"]["symbols"], options["open_browser"]))

    monkeypatch.setattr(view, "_BUNDLE", Path(__file__))  # as if the page were built
    monkeypatch.setattr(view, "serve", serve)
    assert main(["view", str(tmp_path / "city.npz"), "--no-browser"]) == 0
    ((folder, symbols, open_browser),) = served
    assert folder.name == "city.3dtiles" and symbols == ["Lot", "Mass"] and not open_browser
    assert not folder.exists()  # the temporary tileset is gone with the server


def test_a_folder_without_a_tileset_is_refused(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(view, "_BUNDLE", Path(__file__))  # as if the page were built
    assert main(["view", str(tmp_path), "--no-browser"]) == 2
    assert "has no tileset.json" in capsys.readouterr().err


def test_a_page_not_built_says_what_to_run(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(view, "_BUNDLE", tmp_path / "viewer.js")
    assert "npm ci --prefix viewer && npm run build --prefix viewer" in page_missing()
    assert main(["view", str(tmp_path), "--no-browser"]) == 2
    assert "the viewer's page is not built" in capsys.readouterr().err


@pytest.mark.skipif(not CHROMIUM.is_file(), reason="Chromium is not installed (Debian: apt-get install chromium)")
@pytest.mark.skipif(shutil.which("node") is None or not (VIEWER / "node_modules" / "playwright-core").is_dir(),
                    reason="the viewer's packages are not installed: npm ci --prefix viewer")
@pytest.mark.skipif(page_missing() is not None, reason="the viewer's page is not built: npm run build --prefix viewer")
def test_headless_chromium_shows_the_example_city_and_a_click_shows_a_lot(tmp_path):
    build(ROOT / "examples" / "city" / "city.cga", tmp_path / "city.3dtiles")
    with page_server(tmp_path / "city.3dtiles") as server:
        thread = threading.Thread(target=server.serve_forever, daemon=True)
        thread.start()
        try:
            out = subprocess.run(["node", str(VIEWER / "scripts" / "snapshot.mjs"), address(server),
                                  str(tmp_path / "shot.png"), "1", "800x500"],
                                 capture_output=True, text=True, timeout=300, check=True).stdout
        finally:
            server.shutdown()
            thread.join()
    shown = json.loads(out)
    assert shown["error"] is None
    assert shown["tilesLoaded"] >= 1 and shown["tilesVisible"] >= 1
    assert shown["picked"] is not None and shown["picked"].startswith("lot\nid\t")
    pixels = np.asarray(Image.open(tmp_path / "shot.png").convert("RGB"), np.int16)
    city = np.abs(pixels - BACKGROUND).sum(axis=2) > 12
    assert city.mean() > 0.1, f"{city.mean():.1%} of the screenshot differs from the background"
