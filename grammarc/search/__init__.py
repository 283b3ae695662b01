"""Derivation as search (GRAMATICA): a grammar's states, searched breadth-first, depth-first or by A*.

A grammar whose rules have sets of consequents (``choose(...)``, ``?`` alternatives) has a state space: a
state is a lot derived with some of its choices fixed (``states``), its consequents fix one more. The
strategies (``strategies``) find the states that are complete and meet the grammar's ``goal:``; ``run``
searches every lot and writes the solutions as records, ``tree`` the derivation graph.
"""

from grammarc.search.run import SearchResult, run_search, write_solutions
from grammarc.search.states import Deriving, States
from grammarc.search.strategies import STRATEGIES, SearchOptions

__all__ = ["STRATEGIES", "Deriving", "SearchOptions", "SearchResult", "States", "run_search", "write_solutions"]
