"""model/grammar.py: the checked grammar reads its graph and assets from its module, and pickles."""

from __future__ import annotations

import pickle
from dataclasses import replace

from grammarc.compiler import compile_grammar
from grammarc.model import grammar as model
from grammarc.model.grammar import Grammar


def test_the_grammar_reads_what_the_passes_found_from_its_module(write):
    path = write("g.cga", 'lot ~> I("cylinder") facade\nfacade ~> I("win.obj")\n')
    grammar = compile_grammar(path)
    module = grammar.module
    assert Grammar is model.Grammar
    assert grammar.graph is module.graph and grammar.graph.terminals == ()
    assert grammar.assets is module.assets
    assert grammar.asset_ids == {"cylinder": 2, "win.obj": 3} and module.asset_ids == (("cylinder", 2),
                                                                                        ("win.obj", 3))
    assert grammar.asset_roots == (path.parent,) == module.roots
    # a cluster worker loads the assets from its own copy of them
    moved = replace(grammar, asset_roots=(path.parent / "copy",))
    assert moved.asset_roots == (path.parent / "copy",) and moved.module is module


def test_a_grammar_pickles_whole(write):
    grammar = compile_grammar(write("g.cga", 'attr h = 2\nlot ~> T(0, 0, h) I("cube") : 0.5 ~> ε : 0.5\n'))
    assert grammar.asset_ids == {"cube": 0}  # computed once: the cached dict must not get in the way
    again = pickle.loads(pickle.dumps(grammar))
    assert again == grammar and again.asset_ids == grammar.asset_ids and again.graph == grammar.graph
