"""backend/arrays.py and the array expressions of backend/evaluate.py: CityEngine's arrays evaluated per
shape. The expected values are the examples of the CGA reference pages (array initialization, colon
operator, index operator, array types operators, size, nRows, nColumns, transpose, sortIndices,
sortRowIndices, findFirst)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_lots
from operations.derivations import per_lot, rect, run

from grammarc.backend import arrays
from grammarc.backend.arrays import Arrays
from grammarc.backend.attributes import attribute_columns
from grammarc.backend.derive import initial_chunk
from grammarc.backend.evaluate import Env
from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.errors import LotFailure


def rows_of(column, s: int, names: list[str] | None):
    """Shape ``s``'s value of an evaluated column: an array as a list of rows, or a scalar."""
    def plain(x):
        return names[int(x)] if names is not None else x.item()

    if not isinstance(column, Arrays):
        return plain(np.atleast_1d(column)[s])
    elements = [plain(x) for x in column.values[column.offsets[s]:column.offsets[s + 1]]]
    width = int(column.columns[s])
    return [elements[i:i + width] for i in range(0, len(elements), width)] if width else []


def values(write, text: str, lot_attrs=None, lots=("square", "rect_12x8")) -> list:
    """Per lot, the value of the attribute or constant ``v`` of ``text`` (CityEngine)."""
    grammar = compile_grammar(write("g.cga", 'version "2022.0"\n' + text + "\nLot --> X\n"))
    plan = make_plan(grammar)
    lots = make_lots(*lots, attrs=lot_attrs)
    chunk, shapes = initial_chunk(lots, seed=1)
    chunk.attrs = {}
    attribute_columns(grammar.module, Env(shapes, chunk, plan), lots.attrs, {}, plan.strings)
    kind = next(a.type for a in grammar.module.attrs if a.name == "v")
    names = list(plan.strings.ids) if kind.element.value == "str" else None
    return [rows_of(chunk.attrs["v"], s, names) for s in range(len(lots))]


def value(write, text: str):
    """The value of ``v`` (the same on every lot)."""
    first, *rest = values(write, text)
    assert all(r == first for r in rest)
    return first


A = "const a = [1, 2, 3, 4]\n"
A2 = "const a = [1, 2, 3 ; 4, 5, 6 ; 7, 8, 9]\n"


@pytest.mark.parametrize("text, want", [
    # array initialization
    ("const v = [1, 2, 1]", [[1, 2, 1]]),
    ("const a = [1, 2, 1]\nconst v = [0, a, 0]", [[0, 1, 2, 1, 0]]),
    ('const a = ["B", "C", "D"]\nconst v = ["A", a, "E"]', [["A", "B", "C", "D", "E"]]),
    ("const v = [-1 ; -2]", [[-1], [-2]]),
    ("const v = [0:2 ; 3, 3, 3]", [[0, 1, 2], [3, 3, 3]]),
    ("const a = [-1 ; -2]\nconst b = [0:2 ; 3, 3, 3]\nconst v = [a, b ; b, a]",
     [[-1, 0, 1, 2], [-2, 3, 3, 3], [0, 1, 2, -1], [3, 3, 3, -2]]),
    ("const v = [true, false]", [[True, False]]),
    # colon operator
    ("const v = [2 : 4]", [[2, 3, 4]]),
    ("const v = [0.5 : 3]", [[0.5, 1.5, 2.5]]),
    ("const v = [4 : 2]", []),
    ("const v = [1 : 0.5 : 3]", [[1, 1.5, 2, 2.5, 3]]),
    ("const v = [4 : -1 : 2]", [[4, 3, 2]]),
    ("const v = [1 : -0.5 : 2]", []),
    ("const v = [1 : -0.5 : 1]", [[1]]),
    ("const v = [1 : 0 : 1]", []),
    ("const v = [1 : 2 : 5]", [[1, 3, 5]]),
    # index operator
    (A + "const v = a[0]", 1), (A + "const v = a[3]", 4),
    (A2 + "const v = a[1, 1]", 5),
    (A + "const v = a[[0, 2]]", [[1, 3]]), (A + "const v = a[[1, 1]]", [[2, 2]]),
    (A + "const v = a[3:-1:1]", [[4, 3, 2]]), (A + "const v = a[[0, 1 ; 2, 3]]", [[1, 2], [3, 4]]),
    (A2 + "const v = a[1, [0, 2]]", [[4, 6]]), (A2 + "const v = a[[0, 0, 1], 2]", [[3], [3], [6]]),
    (A2 + "const v = a[0:2, [0, 2]]", [[1, 3], [4, 6], [7, 9]]),
    (A + "const v = a[[true, false, true]]", [[1, 3]]), (A + "const v = a[a .> 2]", [[3, 4]]),
    (A + "const v = a[a .> 1 .&& a .<= 3]", [[2, 3]]), (A2 + "const v = a[[false, true, true], 0]", [[4], [7]]),
    (A + "const v = a[-1]", 0), (A + "const v = a[[false, false, true, true, true]]", [[3, 4, 0]]),
    (A2 + "const v = a[[2, 3], -1:1]", [[0, 7, 8], [0, 0, 0]]),
    (A2 + "const v = a[3]", 4), (A2 + "const v = a[[0 ; 3 ; 6]]", [[1], [4], [7]]),
    (A2 + "const v = a[0, [0, 1 ; 2, 3]]", [[1, 2, 3, 0]]), (A + "const v = a[[true, false ; true, false]]", [[1, 3]]),
    ('const v = ["a", "b"][5]', ""), ("const v = [true][1]", False),
    # size, nRows, nColumns
    ("const v = size([1:4])", 4), ("const v = size([1, 2 ; 3, 4])", 4),
    ("const v = nRows([1, 2, 3 ; 4, 5, 6])", 2), ("const v = nColumns([1, 2, 3 ; 4, 5, 6])", 3),
    ("const v = size([4 : 2])", 0),
    # transpose
    ('const v = transpose(["a", "b" ; "c", "d" ; "e", "f"])', [["a", "c", "e"], ["b", "d", "f"]]),
    ("const v = transpose([[1, 1, 1] ; [2, 2, 2]])", [[1, 2], [1, 2], [1, 2]]),
    # sortIndices, sortRowIndices
    ('const v = sortIndices(["c", "b", "d", "a"])', [[3, 1, 0, 2]]),
    ('const a = ["c", "b", "d", "a"]\nconst v = a[sortIndices(a)]', [["a", "b", "c", "d"]]),
    ("const v = sortIndices([2, 1, 3, 3, 1])", [[1, 4, 0, 2, 3]]),
    ('const v = sortIndices(["e", "c", "d" ; "b", "a", "c" ; "d", "a", "d"])', [[1, 2, 0], [4, 3, 5], [7, 6, 8]]),
    ("const v = sortRowIndices([4, 0, 1 ; 2, 1, 9 ; 1, 3, 0 ; 2, 1, 0])", [[2, 3, 1, 0]]),
    ("const a = [4, 0, 1 ; 2, 1, 9 ; 1, 3, 0 ; 2, 1, 0]\nconst v = a[sortRowIndices(a), 0:nColumns(a)-1]",
     [[1, 3, 0], [2, 1, 0], [2, 1, 9], [4, 0, 1]]),
    ("const a = [4, 0, 1 ; 2, 1, 9 ; 1, 3, 0 ; 2, 1, 0]\nconst v = "
     + "a[sortRowIndices(a[0:nRows(a)-1, [1, 0, 2]]), 0:nColumns(a)-1]",
     [[4, 0, 1], [2, 1, 0], [2, 1, 9], [1, 3, 0]]),
    ("const a = [1, 4, -1, 9]\nconst v = a[sortIndices(a)[0]]", -1),
    ("const a = [1, 4, -1, 9]\nconst v = a[sortIndices(a)[size(a) - 1]]", 9),
    # findFirst
    ("const v = findFirst([1, 2, 3, 4], 2, 0)", 1), ("const v = findFirst([1, 2, 3 ; 4, 5, 6], 4, 0)", 3),
    ("const v = findFirst([6, 8.1, 6, 8.1], 8, 0.5)", 1), ('const v = findFirst(["a", "b"], "c")', -1),
    ("const v = findFirst([false, true], true)", 1),
    # ce.lib's findFirst on strings: find(text, match, 0)
    ('const v = findFirst("ab;cd;", "cd")', 3), ('const v = findFirst("ab;cd;", "x")', -1),
    # equality of whole arrays
    ("const v = [1, 2] == [1, 2]", True), ('const v = ["a", "b"] == ["a" ; "b"]', False),
    ("const v = [true, false] == [true, true]", False), ("const v = [1, 2] != [1 ; 2]", True),
    ("const v = [true, true] != [true, true]", False),
    # element-wise operators
    ("const v = [1, 2] .+ 1", [[2, 3]]), ("const v = 1 .+ [1 ; 2]", [[2], [3]]),
    ("const v = [1, 2] .+ [2, 1]", [[3, 3]]), ("const v = .+[1, 2]", [[1, 2]]),
    ("const v = [1, 2 ; 3, 4] .- 1", [[0, 1], [2, 3]]), ("const v = 3 .- [1, 2]", [[2, 1]]),
    ("const v = .-[1 ; 2]", [[-1], [-2]]), ("const v = [4, 2] .* 2.5", [[10, 5]]),
    ("const v = -4 .* [0.25 ; -0.75 ; -1]", [[-1], [3], [4]]), ("const v = [1, 2 ; 3, 4] .* [4, 3 ; 2, 1]", [[4, 6], [6, 4]]),
    ("const v = [4 ; 3] ./ 2", [[2], [1.5]]), ("const v = 12 ./ [2, 3, 4]", [[6, 4, 3]]),
    ("const v = [1.6, 3.8] ./ [0.8, 1.9]", [[2, 2]]), ("const v = [8 ; -5 ; 0] .% 3", [[2], [-2], [0]]),
    ("const v = .![true, false]", [[False, True]]), ("const v = [true, false] .|| true", [[True, True]]),
    ("const v = false .|| [false ; true]", [[False], [True]]), ("const v = [false, true] .|| [false, false]", [[False, True]]),
    ("const v = [false ; true] .&& true", [[False], [True]]), ("const v = [true, false] .&& [false, true]", [[False, False]]),
    ("const v = 1 .== [1, 2]", [[True, False]]), ('const v = ["a", "b"] .== "b"', [[False, True]]),
    ("const v = [1, 1 ; 2, 2] .!= [1, 2 ; 1, 2]", [[False, True], [True, False]]), ("const v = false .!= [true]", [[True]]),
    ("const v = 1 .< [1, 2]", [[False, True]]), ('const v = ["a", "b"] .< "b"', [[True, False]]),
    ('const v = ["a" ; "b" ; "c"] .<= "b"', [[True], [True], [False]]), ('const v = ["a", "b"] .<= ["b", "a"]', [[True, False]]),
    ("const v = [1, 2 ; 3, 4] .> [1, 1 ; 3, 3]", [[False, True], [False, True]]), ('const v = ["a" ; "b"] .> "a"', [[False], [True]]),
    ("const v = [1 ; 2 ; 3] .>= [2 ; 2 ; 2]", [[False], [True], [True]]), ("const v = 2 .>= [1, 2, 3]", [[True, True, False]]),
    ('const v = ["a", "b"] .+ "c"', [["ac", "bc"]]), ('const v = "a" .+ [1, 2 ; 3, 4]', [["a1", "a2"], ["a3", "a4"]]),
    ('const v = [1 ; 2] .+ ["a" ; "b"]', [["1a"], ["2b"]]), ('const v = [true ; false] .+ "a"', [["truea"], ["falsea"]]),
    ('const v = ["a" ; "b"] .+ [false ; true]', [["afalse"], ["btrue"]]),
    # sum
    ("const v = sum([1, 2, 3])", 6), ("const v = sum([true, false, true])", 2),
    ('const v = sum(["a", "b", "c"])', "abc"), ('const v = sum(["a", "bc" ; "d", ""])', "abcd"),
    ("const v = sum([4 : 2])", 0), ('const v = sum(["a", "b"][[false, false]])', ""),
    # floatArray, boolArray, stringArray
    ("const v = floatArray([1, 0, 1.777, 20])", [[1, 0, 1.777, 20]]),
    ('const v = floatArray(["1.5", "-2", "0"])', [[1.5, -2, 0]]),
    ("const v = floatArray([true, false, true])", [[1, 0, 1]]), ("const v = floatArray()", []),
    ("const v = boolArray([1, 0, 1, 20])", [[True, False, True, True]]),
    ("const v = boolArray([true, false, true])", [[True, False, True]]),
    ("const v = stringArray([1, 0, 1.777, 20])", [["1", "0", "1.777", "20"]]),
    ("const v = stringArray([true, false ; true, true])", [["true", "false"], ["true", "true"]]),
    ('const v = stringArray(["true", "CityEngine", ""])', [["true", "CityEngine", ""]]),
    # print gives its value, whatever its type
    ("const v = print([1, 2])", [[1, 2]]), ('const v = print("a") + "b"', "ab"),
    # isinf (the math functions fold on constants; an attribute is evaluated per lot)
    ("attr x = 1e308\nconst v = isinf(x / 0)", True), ("attr x = 1e308\nconst v = isinf(x)", False),
    # a case expression of arrays
    ("attr n = 3\nconst v = case n > 2 : [1, 2] else : [3]", [[1, 2]]),
])
def test_reference_examples(write, text, want):
    assert value(write, text) == want


def test_floating_point_ranges_stop_before_their_limit(write):
    got = value(write, "const v = [0 : 0.15 : 0.5]")[0]
    assert len(got) == 4 and abs(got[3] - 0.45) < 1e-10
    assert value(write, "const v = 7 .% [2.7, -3]")[0] == pytest.approx([1.6, 1.0])
    assert value(write, "const v = [-5, 3.8] .% [-3, 0.7]")[0] == pytest.approx([-2.0, 0.3])


def test_arrays_differ_per_lot(write):
    """A range whose limit is a lot's attribute, and indices per lot: one array per lot."""
    got = values(write, "attr n = 2\nconst v = [0 : n] .* 10", lot_attrs={"n": np.array([1.0, 3.0])})
    assert got == [[[0, 10]], [[0, 10, 20, 30]]]
    got = values(write, "attr i = 0\nconst v = [5, 6, 7][i]", lot_attrs={"i": np.array([2.0, 9.0])})
    assert got == [7, 0]


def test_mismatched_dimensions_fail_the_lots_they_happen_on(write):
    text = "attr n = 2\nconst v = [[0 : n] ; [1, 2, 3]]"
    assert values(write, text, lot_attrs={"n": np.array([2.0, 2.0])}) == [[[0, 1, 2], [1, 2, 3]]] * 2
    with pytest.raises(LotFailure, match="the rows of an array differ in length") as failure:
        values(write, text, lot_attrs={"n": np.array([2.0, 5.0])})
    assert list(failure.value.lots) == [1]
    with pytest.raises(LotFailure, match="of different dimensions"):
        values(write, "attr n = 2\nconst v = [0 : n] .+ [1, 2]", lot_attrs={"n": np.array([1.0, 2.0])})
    with pytest.raises(LotFailure, match="more than 100000 elements"):
        values(write, "const v = [0 : 1e6]")
    # a count beyond any float (it was taken as none, silently) is more, too
    for text in ("const v = [0 : 1e-320 : 1]", "attr top = 1\nconst v = [0 : top * 1e308 * 10]"):
        with pytest.raises(LotFailure, match="more than 100000 elements"):
            values(write, text)


# ------------------------------------------------------------------------------------------------ kernels


def ragged(*rows_per_shape) -> Arrays:
    """Arrays from per-shape lists of rows."""
    flat = [x for rows in rows_per_shape for row in rows for x in row]
    sizes = [sum(len(r) for r in rows) for rows in rows_per_shape]
    return Arrays(np.array(flat, dtype=np.float64), np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
                  np.array([len(rows[0]) if rows else 0 for rows in rows_per_shape], dtype=np.int64))


def test_take_gathers_whole_arrays_in_order():
    a = ragged([[1, 2]], [], [[3], [4], [5]])
    b = a.take(np.array([2, 0, 2, 1]))
    assert [rows_of(b, s, None) for s in range(4)] == [[[3], [4], [5]], [[1, 2]], [[3], [4], [5]], []]
    assert b.rows.tolist() == [3, 1, 3, 0]


def test_concatenation_and_stacking_leave_empty_arrays_out():
    a, e = ragged([[1], [2]], [[7, 8]]), ragged([], [])
    row, bad = arrays.concatenate_row([e, a, a])
    assert not bad.any()
    assert [rows_of(row, s, None) for s in range(2)] == [[[1, 1], [2, 2]], [[7, 8, 7, 8]]]
    stacked, bad = arrays.stack_rows([a, e, a])
    assert not bad.any()
    assert [rows_of(stacked, s, None) for s in range(2)] == [[[1], [2], [1], [2]], [[7, 8], [7, 8]]]
    stacked, bad = arrays.stack_rows([ragged([[1, 2]], [[3]]), ragged([[4, 5]], [[6, 7]])])
    assert bad.tolist() == [False, True]
    assert rows_of(stacked, 0, None) == [[1, 2], [4, 5]]


def test_sort_row_indices_is_stable_for_equal_rows():
    a = ragged([[1, 2], [0, 5], [1, 2], [0, 5]])
    assert rows_of(arrays.sort_row_indices(a, None), 0, None) == [[1, 3, 0, 2]]


# ----------------------------------------------------------------------------------------- in a real build


def test_a_grammar_with_arrays_builds_deterministically(write):
    text = ('attr floorHeights = [4, 3, 3]\n'
            'const colors = ["#ff0000", "#00ff00", "#0000ff"]\n'
            'Lot --> extrude(sum3(floorHeights)) report("floors", size(floorHeights)) '
            'report("tallest", floorHeights[sortIndices(floorHeights)[size(floorHeights) - 1]]) '
            'color(colors[findFirst(floorHeights, 3, 0)]) Mass.\n'
            'sum3(a) = a[0] + a[1] + a[2]\n')
    lots = [rect(10, 10), rect(8, 6), rect(5, 5)]
    heights = np.empty(3, dtype=object)
    heights[:] = ["[5, 3, 2]", None, "[1, 2, 3]"]
    first = run(write, text, lots, lot_attrs={"floorHeights": heights})
    again = run(write, text, lots, lot_attrs={"floorHeights": heights})
    np.testing.assert_array_equal(first["xform"], again["xform"])
    assert not first["bad"]
    np.testing.assert_allclose(first["xform"][:, 1, 1], [10, 10, 6])
    reports = per_lot(first)
    assert [reports[k]["tallest_sum"] for k in sorted(reports)] == [5, 4, 3]
    assert [reports[k]["floors_sum"] for k in sorted(reports)] == [3, 3, 3]
