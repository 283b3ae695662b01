"""The lots of a build, found and read in a thread of their own, which the command starts first of all.

A large lots file takes as long to read as the start-up takes (importing the derivation, compiling the
grammar), and most of the reading (Arrow's, the WKB kernel, numpy's and GEOS's work over whole columns,
numba's first kernel) runs outside the interpreter's lock, so the two overlap on a machine of two cores.
This module is light to import for that reason: ``grammarc build`` starts the reading before it imports the
derivation, and the thread imports the readers (``io.lots``) itself.
"""

from __future__ import annotations

import threading
from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from grammarc.io.lot_format import LotsOptions
    from grammarc.model.lots import Lots

__all__ = ["LotsReading", "find_lots", "load_lots"]


def find_lots(grammar_path: Path) -> Path | None:
    """The example's own lots: ``<grammar stem>.geojson`` or ``lots.geojson`` beside the grammar."""
    for name in (grammar_path.with_suffix(".geojson").name, "lots.geojson"):
        candidate = grammar_path.parent / name
        if candidate.is_file():
            return candidate
    return None


def load_lots(grammar_path: Path, lots_path: Path | None, options: LotsOptions | None = None) -> Lots:
    """The lots of ``lots_path``, else those beside the grammar (``find_lots``), else one 30 x 20 m lot."""
    from grammarc.io.lots import default_lot, read_lots

    path = lots_path or find_lots(grammar_path)
    return read_lots(path, options) if path is not None else default_lot()


_DONE = object()  # the end of ``LotsReading.result``'s steps


class LotsReading:
    """``load_lots`` in a thread of its own, started before the grammar is compiled (the module docstring).
    The lots, or the reading's error, are had from ``result()`` where they were read before, so a grammar's
    errors still come first; a build that fails before leaves the thread to end with the process (a
    daemon)."""

    def __init__(self, grammar_path: Path, lots_path: Path | None, options: LotsOptions | None):
        self._lots: Lots | None = None
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._read, args=(grammar_path, lots_path, options),
                                        name="grammarc lots", daemon=True)
        self._thread.start()

    def _read(self, grammar_path: Path, lots_path: Path | None, options: LotsOptions | None) -> None:
        try:
            self._lots = load_lots(grammar_path, lots_path, options)
        except BaseException as error:  # noqa: BLE001 - raised in the build's thread by result()
            self._error = error

    def result(self, meanwhile: Iterable = ()) -> Lots:
        """The lots, once read (the wait ends on a signal: Ctrl-C stops the build here as anywhere); the
        steps of ``meanwhile`` are taken while they are being read, none once they are."""
        steps = iter(meanwhile)
        while self._thread.is_alive() and next(steps, _DONE) is not _DONE:
            pass
        self._thread.join()
        if self._error is not None:
            raise self._error
        return self._lots
