"""``grammarc conform``: a kit rule package derived by grammarc on a kit footprint, against PRT's record."""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from grammarc.conform.kit import find_record, footprint_path, load_reference
from grammarc.conform.measure import AREA_REL_TOL, BBOX_TOL, Verdict, compare, compare_reports, measure

__all__ = ["TOLERANCES", "Conformance", "run_conformance"]

#: The issue's targets: rule packages with simple geometry must match to the README's tolerances; the
#: large facade packages to 2 cm and 1 % of the area.
TOLERANCES = {"candler": (0.02, 0.01), "complexpatterns": (0.02, 0.01)}


@dataclass(frozen=True)
class Conformance:
    """grammarc against PRT on one (rule package, footprint, attributes): geometry and reports."""

    rpk: str
    footprint: str
    attrs: dict
    verdict: Verdict | None
    reports_ok: bool | None
    report_differences: tuple[str, ...]
    error: str = ""

    @property
    def passed(self) -> bool:
        return self.verdict is not None and self.verdict.passed and self.reports_ok is not False

    @property
    def summary(self) -> str:
        if self.error:
            return f"ERROR {self.error}"
        text = self.verdict.summary if self.verdict is not None else "no reference record"
        if self.reports_ok is not None:
            text += ", reports " + ("equal" if self.reports_ok else
                                    "differ: " + "; ".join(self.report_differences[:3]))
        return text



def run_conformance(rpk: str | os.PathLike, footprint: str, attrs: Mapping | None = None, *,
                    seed: int = 0, reference: Mapping | None = None) -> Conformance:
    """Derive ``rpk`` on a kit footprint with grammarc, bake it, and compare with PRT's record."""
    from grammarc.build import BuildOptions, derive, grammar_source
    from grammarc.compiler import compile_grammar
    from grammarc.errors import GrammarcError
    from grammarc.io.bake import bake
    from grammarc.io.lots import read_lots

    rpk = Path(rpk)
    attrs = dict(attrs or {})
    reference = reference if reference is not None else load_reference()
    expected = find_record(reference, rpk.stem, footprint, attrs, seed=seed)
    options = BuildOptions(seed=seed, attrs={k: float(v) if isinstance(v, int) else v
                                             for k, v in attrs.items()})
    try:
        with grammar_source(rpk, options) as (source, display, resolved):
            grammar = compile_grammar(source, start=resolved.start, asset_roots=resolved.asset_roots,
                                      display=display)
            record = derive(grammar, read_lots(footprint_path(footprint)), resolved)
            mesh = bake(record, resolved.asset_roots)
    except GrammarcError as error:
        diagnostics = [d for d in getattr(error, "diagnostics", ()) if d.is_error]
        first = f"{diagnostics[0].span}: {diagnostics[0].message}" if diagnostics else str(error)
        return Conformance(rpk.stem, footprint, attrs, None, None, (), error=first.splitlines()[0])
    if record["bad"]:
        return Conformance(rpk.stem, footprint, attrs, None, None, (),
                           error=f"lot skipped: {record['bad'][0].reason}")
    if expected is None:
        return Conformance(rpk.stem, footprint, attrs, None, None, ())
    bbox_tol, area_tol = TOLERANCES.get(rpk.stem, (BBOX_TOL, AREA_REL_TOL))
    verdict = compare(measure(mesh), expected, bbox_tol=bbox_tol, area_rel_tol=area_tol)
    reports_ok, differences = None, ()
    if expected.get("report") or record["reports"]:
        ours = record["reports"].table(record["reports"].totals())
        reports_ok, differences = compare_reports(ours, expected.get("report") or {})
    return Conformance(rpk.stem, footprint, attrs, verdict, reports_ok, differences)
