"""The checked grammar: what ``compiler.compile_grammar`` hands to the derivation and the writers.

Its module is the checked IR, which carries what the passes found (the rule graph, the assets); the
grammar adds where it came from (path, digest, the source texts to show diagnostics in) and its warnings.
It pickles (a cluster build sends it to its workers).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

from grammarc.diagnostics import Diagnostic
from grammarc.ir import nodes as ir


@dataclass(frozen=True)
class Grammar:
    #: The file as diagnostics name it (a rule file inside a package: ``candler.rpk/rules/x.cga``).
    path: str
    #: SHA-256 of the grammar's text, for the record's meta.
    digest: str
    #: The checked module, with its rule graph and assets.
    module: ir.Module
    warnings: tuple[Diagnostic, ...]
    #: File name -> text of the grammar and of the files it imports.
    sources: dict[str, str]
    #: Folders the assets are loaded from: those the compiler resolved them in (``Module.roots``), or the
    #: copy of them a cluster worker is given. A field, not the module's: it changes when the grammar moves.
    asset_roots: tuple[Path, ...] = ()

    @property
    def graph(self) -> ir.RuleGraph:
        return self.module.graph

    @property
    def assets(self) -> tuple[str, ...]:
        """Canonical asset names; an asset's index is its id in the record."""
        return self.module.assets

    @cached_property
    def asset_ids(self) -> dict[str, int]:
        """``I()`` name as written -> asset id."""
        return dict(self.module.asset_ids)
