"""The derivation graph of a search: which state each state is a consequent of, by which choice.

GRAMATICA enriches each state with the state and the operator that made it, so that the path to a goal
can be read back; ``--tree`` writes that graph. States are numbered in the order derived (every
state gets its number, so that the consequents can name their parent); with ``record`` the tree keeps,
per batch, the columns of what each state is, and ``write`` turns them into JSON: a node per state with
its parent, its path, the rule and option that made it (the choice its parent stopped at), its cost and
heuristic, how many consequents it has (0: complete), and its status (``branch``, ``goal``,
``complete`` (a design the goal rejects), ``pruned``, ``failed``), and its solution number.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from grammarc.atomic import replacing
from grammarc.ir import nodes as ir
from grammarc.ir.printer import print_expr, print_op
from grammarc.ir.traverse import all_exprs
from grammarc.search.states import Outcome, States


def choice_sites(module: ir.Module) -> dict[int, dict]:
    """What each choice of the grammar is, by its site: its rule, where it is, and its options' text."""
    sites = {}
    for rule in module.rules:
        where = {"rule": rule.symbol}
        if rule.alternatives[0].choice:
            sites[rule.site] = {**where, "at": f"{rule.span.line}:{rule.span.col}", "choice": "?",
                                "options": [" ".join(print_op(op) for op in alt.body) or "ε"
                                            for alt in rule.alternatives]}
        for expr in all_exprs(rule):
            if isinstance(expr, ir.Choose):
                sites[expr.site] = {**where, "at": f"{expr.span.line}:{expr.span.col}",
                                    "choice": print_expr(expr), "options": [print_expr(o) for o in expr.options]}
    return sites


class Tree:
    """Numbers the states derived, and with ``record`` keeps what each is for ``write``."""

    def __init__(self, record: bool) -> None:
        self.record = record
        self.count = 0
        self.batches: list[tuple[States, np.ndarray, Outcome]] = []
        self.solution: dict[int, int] = {}

    def add(self, states: States, outcome: Outcome) -> np.ndarray:
        """Number the newly derived ``states``; returns their ids."""
        ids = np.arange(self.count, self.count + len(states))
        self.count += len(states)
        if self.record:
            self.batches.append((states, ids, outcome))
        return ids

    def solved(self, ids: np.ndarray) -> None:
        """States ``ids`` are the next solutions, in order."""
        for state in ids.tolist():
            self.solution[state] = len(self.solution)

    def nodes(self, sites: dict[int, dict], lot_ids) -> list[dict]:
        """A JSON-ready node per recorded state, by id."""
        stopped_at: dict[int, int] = {}
        nodes = []
        for states, ids, outcome in self.batches:
            status = np.where(outcome.failed, "failed", np.where(outcome.solution, "goal", np.where(
                outcome.complete, "complete", np.where(outcome.pruned, "pruned", "branch"))))
            heuristic = outcome.heuristic
            for row, state in enumerate(ids.tolist()):
                stopped_at[state] = int(outcome.site[row])
                length = int(states.length[row])
                parent = int(states.parent[row])
                site = sites.get(stopped_at.get(parent, -1))
                made_by = None if site is None else {
                    "rule": site["rule"], "at": site["at"], "choice": site["choice"],
                    "option": int(states.path[row, length - 1]),
                    "value": site["options"][int(states.path[row, length - 1])]}
                node = {"id": state, "parent": parent if parent >= 0 else None,
                        "lot": str(lot_ids[states.lot[row]]), "path": states.path[row, :length].tolist(),
                        "made_by": made_by, "cost": float(outcome.cost[row]),
                        "heuristic": None if heuristic is None else float(heuristic[row]),
                        "consequents": int(outcome.options[row]), "status": str(status[row]),
                        "solution": self.solution.get(state)}
                if outcome.failed[row]:
                    node["reason"] = outcome.reasons.get(row, "")
                nodes.append(node)
        return nodes

    def write(self, path: Path, module: ir.Module, lot_ids, meta: dict) -> None:
        """The graph as JSON at ``path`` (atomically)."""
        document = {**meta, "states": self.nodes(choice_sites(module), lot_ids)}
        with replacing(Path(path)) as tmp:
            tmp.write_text(json.dumps(document, indent=None, separators=(",", ":")) + "\n", encoding="utf-8")
