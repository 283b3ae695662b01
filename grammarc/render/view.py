"""``grammarc view``: a city in a browser. A 3D Tiles folder is served on localhost together with the page
that shows it (the command writes an .npz record as one first, ``io.tiles3d.write_record``).

The page (``render/viewer/``: ``index.html`` and ``viewer.js``) is three.js with 3d-tiles-renderer, bundled
into one file from the repository's ``viewer/`` (``npm ci && npm run build`` there) so that it works
offline; the server serves the page at ``/`` and the tileset at ``/tiles/``, from this machine only
(127.0.0.1), until Ctrl-C.
"""

from __future__ import annotations

import webbrowser
from collections.abc import Callable
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import ClassVar
from urllib.parse import urlsplit

from grammarc.errors import UsageError

__all__ = ["PAGE", "address", "page_missing", "page_server", "serve"]

#: The page's folder, in the package.
PAGE = Path(__file__).with_name("viewer")
#: The bundle the page loads, built from the repository's ``viewer/``.
_BUNDLE = PAGE / "viewer.js"


def page_missing() -> str | None:
    """What to run when the page's bundle is not built (a source checkout before its build), else None."""
    if _BUNDLE.is_file():
        return None
    return ("the viewer's page is not built: in grammarc's source folder run `npm ci --prefix viewer && "
            "npm run build --prefix viewer` (Node.js 18 or later), which writes grammarc/render/viewer/viewer.js")


class _Handler(SimpleHTTPRequestHandler):
    """The page's files at ``/``, the tileset's at ``/tiles/``; quiet."""

    extensions_map: ClassVar[dict[str, str]] = {
        **SimpleHTTPRequestHandler.extensions_map, ".glb": "model/gltf-binary", ".js": "text/javascript",
        ".json": "application/json"}

    def __init__(self, *args, tiles: Path, **kwargs):
        self.tiles = tiles
        super().__init__(*args, directory=str(PAGE), **kwargs)

    def translate_path(self, path: str) -> str:
        route = urlsplit(path).path
        if route.startswith("/tiles/"):
            self.directory = str(self.tiles)  # the base class resolves the rest inside it (no `..`)
            return super().translate_path(route[len("/tiles"):])
        return super().translate_path(path)

    def log_message(self, format, *args) -> None:
        pass


def page_server(tileset: Path, port: int = 0) -> ThreadingHTTPServer:
    """A server of the page and ``tileset`` on 127.0.0.1 (``port`` 0: a free one), not yet serving; its page
    is at ``address(server)``."""
    return ThreadingHTTPServer(("127.0.0.1", port), partial(_Handler, tiles=Path(tileset).resolve()))


def address(server: ThreadingHTTPServer) -> str:
    """The page's address on ``server``."""
    return f"http://127.0.0.1:{server.server_port}/"


def serve(tileset: Path, *, port: int = 0, open_browser: bool = True,
          ready: Callable[[str], None] = print) -> None:
    """Serve the page and ``tileset`` until interrupted; ``ready`` is told the page's address once it is
    served, and a browser opens it unless ``open_browser`` is false."""
    problem = page_missing()
    if problem is not None:
        raise UsageError(problem)
    with page_server(tileset, port) as server:
        ready(address(server))
        if open_browser:
            webbrowser.open(address(server))
        server.serve_forever()
