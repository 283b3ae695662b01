"""Conformance with Esri's Procedural Runtime (PRT): grammarc's geometry measured against PRT's.

Two ways in. ``grammarc conform`` (``runner``) builds a kit rule package on a kit footprint and compares it
with the kit's stored reference records (``kit``, ``measure``). ``python -m grammarc.conform --fuzz N``
(``fuzz``) is the differential harness: it generates footprints of many classes (``footprints``), samples
each package's attributes from their annotated ranges (``cases``), runs PRT on them in its side environment
(``prt_batch``, a script that needs only PyPRT) and grammarc on the same lots, and tabulates the mismatches
per package and footprint class, saving each as a case file that reproduces it.
"""

from grammarc.conform.kit import (
    find_record,
    footprint_geojson,
    footprint_path,
    kit_dir,
    load_reference,
    prt_python,
)
from grammarc.conform.measure import Verdict, compare, compare_reports, measure, surface_distance
from grammarc.conform.runner import TOLERANCES, Conformance, run_conformance

__all__ = [
    "TOLERANCES", "Conformance", "Verdict", "compare", "compare_reports", "find_record", "footprint_geojson",
    "footprint_path", "kit_dir", "load_reference", "measure", "prt_python", "run_conformance", "surface_distance",
]
