"""backend/functions/lists.py: CityEngine's string lists, on one list (the values of the reference's own
examples, lists that are not clean, indices out of range), in a derivation, on a batch of distinct lists,
and ``listRandom``'s draws."""

from __future__ import annotations

from collections import Counter
from types import SimpleNamespace

import numpy as np
import pytest
from reported import errors, reported

from grammarc.backend.functions import FUNCTIONS, lists
from grammarc.backend.plan import Strings
from grammarc.backend.random import uniform

RULES = "rule;your;designs;and;your;cities;"
TEXTURES = "texture_1;texture_2;texture_3;texture_4;texture_5;texture_6;"


@pytest.mark.parametrize("function, args, want", [
    (lists.add, ("rule;your;", "city"), "rule;your;city;"),
    (lists.add, ("rule;your;", "city;"), "rule;your;city;"),
    (lists.clean, (";;;;;my;city;rules;;your;;city;;",), "my;city;rules;your;city;"),
    (lists.clean, (";;cityengine;;;rules",), "cityengine;rules;"),
    (lists.count_matches, ("rule;your;city;", "city"), 1),
    (lists.count_matches, ("city;cityengine;city;", "city"), 2),
    (lists.count_matches, ("rule;your;city;", "*y*"), 2),
    (lists.count_matches, ("rule;your;city;", "*y"), 1),
    (lists.first, ("rule;your;city;",), "rule"),
    (lists.index_of, ("rule;your;city;", "city"), 2),
    (lists.index_of, ("rule;your;city;", "*y"), 2),
    (lists.index_of, ("rule;your;city;", "*y*"), 1),
    (lists.item, ("rule;your;city;", 2), "city"),
    (lists.item, ("texture_1.jpg;texture_2.jpg;texture_3.jpg;", 0), "texture_1.jpg"),
    (lists.last, ("rule;your;city;",), "city"),
    (lists.items_range, ("rule;your;city;with;cityengine;", 0, 3), "rule;your;city;"),
    # the reference writes "texture_3"; the list it returns ends with ";" as every list of listRange does
    (lists.items_range, (TEXTURES, 2, 3), "texture_3;"),
    (lists.remove, ("rule;your;city;", "your"), "rule;city;"),
    (lists.remove, ("rule;your;city;", "*u*"), "your;city;"),
    (lists.remove, ("floor_1;floor_2;floor_3;", "*_2"), "floor_1;floor_3;"),
    (lists.remove_all, (RULES, "your"), "rule;designs;and;cities;"),
    (lists.remove_all, (RULES, "*u*"), "designs;and;cities;"),
    (lists.retain_all, (RULES, "*s"), "designs;cities;"),
    (lists.retain_all, ("floor;floor_1;floor_2;", "*_*"), "floor_1;floor_2;"),
    (lists.size, ("cityengine;rules;",), 2),
    (lists.terminate, ("rule;your;city",), "rule;your;city;"),
    (lists.terminate, ("rule;your;city;",), "rule;your;city;"),
])
def test_reference_examples(function, args, want):
    assert function(*args) == want


@pytest.mark.parametrize("function, args, want", [
    # the last item needs no ";"; "" has no item; an empty item counts
    (lists.size, ("a;b",), 2),
    (lists.size, ("",), 0),
    (lists.size, ("a;;b;",), 3),
    (lists.item, ("a;;b;", 1), ""),
    (lists.item, ("a;;b;", 2), "b"),
    (lists.item, ("a;b", 1), "b"),
    (lists.last, ("a;b",), "b"),
    (lists.first, ("abc",), "abc"),
    (lists.terminate, ("",), ""),
    (lists.clean, (";;",), ""),
    # an index is truncated toward zero
    (lists.item, ("a;b;c;", 1.5), "b"),
    (lists.item, ("a;b;c;", -0.5), "a"),
    # out of range: nothing
    (lists.item, ("a;b;", 2), ""),
    (lists.item, ("a;b;", -1), ""),
    (lists.item, ("", 0), ""),
    (lists.last, ("",), ""),
    (lists.items_range, ("a;b;c;", -5, 2), "a;b;"),
    (lists.items_range, ("a;b;c", 1, 99), "b;c;"),
    (lists.items_range, ("a;b;c;", 2, 1), ""),
    (lists.items_range, ("a;b;c;", 3, 4), ""),
    # a search: whole items, or with * the start, the end or any part of an item
    (lists.index_of, ("city;cityengine;", "engine"), -1),
    (lists.index_of, ("city;cityengine;", "*engine"), 1),
    (lists.index_of, ("a;b;", "x"), -1),
    (lists.index_of, ("", "*"), -1),
    (lists.count_matches, ("a;b;c;", "*"), 3),
    (lists.count_matches, ("", ""), 0),
    (lists.remove, ("a;b;", "x"), "a;b;"),
    (lists.remove, ("a;b", "a"), "b;"),
    (lists.add, ("", "a"), "a;"),
])
def test_lists_that_are_not_clean_and_indices_out_of_range(function, args, want):
    assert function(*args) == want


# ------------------------------------------------------------------------------------------- in derivations


def test_each_function_in_a_derivation(write):
    got, = reported(write, (
        'Lot --> report("add", listAdd("rule;your;", "city")) report("clean", listClean(";;cityengine;;;rules"))\n'
        '    report("count", listCount("rule;your;city;", "*y*")) report("first", listFirst("rule;your;city;"))\n'
        '    report("index", listIndex("rule;your;city;", "*y")) report("item", listItem("rule;your;city;", 2))\n'
        '    report("last", listLast("rule;your;city;")) report("range", listRange("a;b;c;d;", 1, 3))\n'
        '    report("remove", listRemove("floor_1;floor_2;floor_3;", "*_2"))\n'
        f'    report("all", listRemoveAll("{RULES}", "your")) report("retain", listRetainAll("{RULES}", "*s"))\n'
        '    report("size", listSize("cityengine;rules;")) report("end", listTerminate("a;b"))\n'
        '    report("random", listRandom("rule;your;city;")) X.\n'))
    assert got == {"add": "rule;your;city;", "clean": "cityengine;rules;", "count": 2, "first": "rule",
                   "index": 2, "item": "city", "last": "city", "range": "b;c;", "remove": "floor_1;floor_3;",
                   "all": "rule;designs;and;cities;", "retain": "designs;cities;", "size": 2, "end": "a;b;",
                   "random": got["random"]}
    assert got["random"] in ("rule", "your", "city")


def test_a_batch_of_distinct_lists_gives_what_each_gives_alone(write):
    rng = np.random.default_rng(3)
    texts = [";".join(rng.choice(["ab", "b", "", "ca"], size=rng.integers(0, 6))) + rng.choice(["", ";"])
             for _ in range(80)]
    index = rng.integers(-1, 6, size=80).astype(float)
    got = reported(write, (
        'attr items = ""\nattr k = 0\n'
        'Lot --> report("size", listSize(items)) report("item", listItem(items, k)) report("last", listLast(items))\n'
        '    report("range", listRange(items, k, k + 2)) report("index", listIndex(items, "*b"))\n'
        '    report("count", listCount(items, "*a*")) report("clean", listClean(items))\n'
        '    report("without", listRemoveAll(items, "b")) report("add", listAdd(items, "z")) X.\n'),
        lots=80, attrs={"items": texts, "k": index})
    for lot, (text, k) in enumerate(zip(texts, index)):
        want = {"size": lists.size(text), "item": lists.item(text, k), "last": lists.last(text),
                "range": lists.items_range(text, k, k + 2), "index": lists.index_of(text, "*b"),
                "count": lists.count_matches(text, "*a*"), "clean": lists.clean(text),
                "without": lists.remove_all(text, "b"), "add": lists.add(text, "z")}
        assert got[lot] == want, (lot, text, k)


def test_list_random_draws_every_item_per_shape_and_again_the_same(write):
    text = 'attr items = "a;b;c;"\nLot --> report("r", listRandom(items)) report("s", listRandom(items)) X.\n'
    lots = 300
    attrs = {"items": ["a;b;c;"] * 200 + ["x;y"] * 99 + [""]}
    got = reported(write, text, lots=lots, attrs=attrs)
    drawn = Counter(g["r"] for g in got[:200])
    assert set(drawn) == {"a", "b", "c"} and min(drawn.values()) > 40
    assert {g["r"] for g in got[200:299]} == {"x", "y"} and got[299]["r"] == ""
    # each call site draws on its own; the draws depend on the lot, not on the batch it was derived in
    assert sum(g["r"] != g["s"] for g in got) > 100
    assert reported(write, text, lots=lots, attrs=attrs, chunk_size=7) == got
    assert reported(write, text, lots=lots, attrs=attrs, seed=1) != got


def test_list_random_is_the_item_at_the_drawn_index_shape_by_shape():
    strings = Strings()
    texts = ["a;b;c;", "", "x;;y", "solo", ";"]
    ids = np.array([strings.intern(t) for t in texts], dtype=np.int32)
    rng = np.random.default_rng(5)
    key = rng.integers(0, 2**63, 500, dtype=np.uint64)
    which = rng.integers(0, len(texts), 500)
    env = SimpleNamespace(shapes=SimpleNamespace(key=key), plan=SimpleNamespace(strings=strings, sequential_random=False))
    got = FUNCTIONS["listRandom"](SimpleNamespace(site=9, func="listRandom"), [ids[which]], env)
    u = uniform(key, 9)
    names = list(strings.ids)
    want = [lists.item(texts[w], np.floor(x * (lists.size(texts[w]) - lists.SHY))) for w, x in zip(which, u)]
    assert [names[g] for g in got] == want


def test_list_functions_take_strings(write):
    assert errors(write, 'Lot --> report("n", listSize(3)) X.\n') == [
        (2, 30, "an argument of `listSize` must be a str, got a num")]
    assert errors(write, 'Lot --> report("i", listItem("a;b;", "1")) X.\n') == [
        (2, 38, "an argument of `listItem` must be a num, got a str")]
    assert errors(write, 'Lot --> report("r", listRandom()) X.\n') == [
        (2, 21, "`listRandom` takes 1 argument, got 0")]
