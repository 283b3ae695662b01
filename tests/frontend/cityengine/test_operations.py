"""frontend/cityengine/operations.py: CityEngine's operations lowered to IR operations (scope operations,
split, comp, setback, roofs, set, report...), and the operations grammarc accepts without applying them or
does not implement (``unsupported: NAME`` at their span); a misspelt operation is unknown.
"""

from __future__ import annotations

import pytest

from grammarc.backend.plan import make_plan
from grammarc.compiler import compile_grammar
from grammarc.diagnostics import Diagnostics
from grammarc.frontend.cityengine.operations import (
    ALL_OPERATIONS,
    BODY_OPERATIONS,
    NOT_APPLIED,
    OPERATIONS,
    PART_OPERATIONS,
    UNSUPPORTED_OPS,
)
from grammarc.frontend.parse import parse_source
from grammarc.ir import nodes as ir
from grammarc.ir.printer import print_expr
from grammarc.ir.traverse import iter_ops

from .lowered import VERSION, assert_unsupported_at, body_of, compile_ir, errors, module_of


@pytest.mark.parametrize("body, printed", [
    ("extrude(10) Mass", "extrude(10) Mass"),
    ("extrude(h * 2)", "extrude((@h * 2))"),
    ("extrude(world.y, 10) A", "extrude(world.up, 10) A"),
    ("extrude(world.up.flatTop, -2)", "extrude(world.up.flatTop, -2)"),
    ("extrude(face.normal, 1) A", "extrude(1) A"),
    ("extrude(vertex.normal, 1) A", "extrude(vertex.normal, 1) A"),
    ("t(1, 2, 3) A", "T(1, 2, 3) A"),
    ("t('0.5, 0, '-1) A", "T((0.5 * Scope.sx), 0, (-1 * Scope.sz)) A"),
    ("s('1, '0.5, 2) A", "S(1r, 0.5r, 2) A"),
    ("s(scope.sx - 1, 3, '1) A", "S((Scope.sx - 1), 3, 1r) A"),
    ("r(0, 90, 0) A", "r(0, 90, 0) A"),
    ("r(scopeCenter, 0, 90, 0) A", "r(scopeCenter, 0, 90, 0) A"),
    ("r(scopeOrigin, 0, 90, 0) A", "r(0, 90, 0) A"),
    ("translate(rel, world, 0, h, 0) A", "translate(rel, world, 0, @h, 0) A"),
    ("translate(abs, pivot, 1, 2, 3) A", "translate(abs, pivot, 1, 2, 3) A"),
    ("rotate(abs, world, 0, 90, 0) A", "rotate(abs, world, 0, 90, 0) A"),
    ("rotate(rel, scope, h, 0, 0) A", "rotate(rel, scope, @h, 0, 0) A"),
    ("set(scope.tx, h) A", "translate(abs, pivot, @h, Scope.ty, Scope.tz) A"),
    ("set(scope.sy, 2) A", "S(Scope.sx, 2, Scope.sz) A"),
    ("set(scope.rz, 45) A", "rotate(abs, pivot, Scope.rx, Scope.ry, 45) A"),
    ("setPivot(yzx, 3) A", "setPivot(yzx, 3) A"),
    ('setPivot("zxy", h + 1) A', "setPivot(zxy, (@h + 1)) A"),
    ("[ t(0, 3, 0) A ] B", "[ T(0, 3, 0) A ] B"),
    ("NIL", "\u03b5"),
    ("A.", "A."),
    ("A. B", "A. B"),
    ('i("builtin:cube")', 'i("builtin:cube")'),
    ("primitiveCube()", 'i("builtin:cube")'),
    ('i("a.obj", yUp)', 'i("a.obj")'),
    ('i("a.obj", zUp, keepSizeAlignPosition, noCleanup)', 'i("a.obj", zUp, keepSizeAlignPosition)'),
    ('i("a.obj", "zUp", alignSizeAndPosition)', 'i("a.obj", zUp, alignSizeAndPosition)'),
    ("primitiveCube", 'i("builtin:cube")'),
    ("primitiveCube(1, 2, h)", "primitiveCube(1, 2, @h)"),
    ("primitiveQuad", "primitiveQuad()"),
    ("primitiveQuad(2, 3)", "primitiveQuad(2, 3)"),
    ("primitiveDisk(8, 2)", "primitiveDisk(8, 2)"),
    ("primitiveCylinder()", "primitiveCylinder(16)"),
    ("primitiveCylinder(8, 1, h)", "primitiveCylinder(8, 1, @h)"),
    ("primitiveSphere(8, 4)", "primitiveSphere(8, 4)"),
    ("primitiveCone(5, 1, 2)", "primitiveCone(5, 1, 2)"),
    ("center(xz) A", "center(xz) A"),
    ("center(x) A", "center(x) A"),
    ("alignScopeToAxes() A", "alignScopeToAxes() A"),
    ("alignScopeToAxes(world.xyz) A", "alignScopeToAxes() A"),
    ("alignScopeToAxes(y) A", "alignScopeToAxes(y) A"),
    ('alignScopeToAxes("y") A', "alignScopeToAxes(y) A"),
    ("alignScopeToAxes split(y){ 1 : A }", "alignScopeToAxes() split(y){ 1: A }"),
    ("alignScopeToAxes(world.z) A", "alignScopeToAxes(z) A"),
    ("alignScopeToAxes(x) A", "alignScopeToAxes(x) A"),
    ("alignScopeToGeometry(yUp, 2) A", "alignScopeToGeometry(yUp, 2, 0) A"),
    ("alignScopeToGeometry(zUp, -1, h + 1) A", "alignScopeToGeometry(zUp, -1, (@h + 1)) A"),
    ("alignScopeToGeometry(yUp, largest, longest) A", "alignScopeToGeometry(yUp, largest, longest) A"),
    ('alignScopeToGeometry("zUp", any, world.lowest) A', "alignScopeToGeometry(zUp, any, world.lowest) A"),
    ("alignScopeToGeometry(zUp, world.lowest, 1) A", "alignScopeToGeometry(zUp, world.lowest, 1) A"),
    ("rotateScope(0, 90, 0) A", "rotateScope(0, 90, 0) A"),
    ("alignScopeToGeometry(yUp, auto) A", "alignScopeToGeometry(yUp, largest, longest) A"),
    ('alignScopeToGeometry("zUp", "auto", 1) A', "alignScopeToGeometry(zUp, largest, 1) A"),
    ("set(h, h + 1) A", "set(h, (@h + 1)) A"),
    ('report("area", geometry.area) A', 'report("area", geometry.area()) A'),
    ('report("volume", geometry.volume()) A', 'report("volume", geometry.volume()) A'),
    ("split(z){ 1 : A | ~1 : B }", "split(z){ 1: A | ~1: B }"),
    ("split(z, adjust){ 1 : A | ~1 : B }", "split(z){ 1: A | ~1: B }"),
    ("split(x, noAdjust){ 1 : A | ~1 : B }*", "split(x, noAdjust){ 1: A | ~1: B }*"),
    ("comp(f){ front : A | side : B. | top : NIL }", "comp(f){ front: A | side: B. | top: \u03b5 }"),
    ("comp(f){ h + 1 : A | h = B | 2 : C }", "comp(f){ (@h + 1): A | @h: B | 2: C }"),
    ("comp(e){ eave : A | ridge : B | hip : C | valley : D }", "comp(e){ eave: A | ridge: B | hip: C | valley: D }"),
    ("comp(v){ h : A }", "comp(v){ @h: A }"),
    ("comp(e){ border : A | inside : B }", "comp(e){ border: A | inside: B }"),
    ("offset(-2) A", "offset(-2, all) A"),
    ("offset(-2, all) A", "offset(-2, all) A"),
    ("offset(h) comp(f){ border : B }", "offset(@h) comp(f){ border: B }"),
    ("setback(h) A", "offset(-@h, inside) A"),
    ('color("#ff0000") A', 'color("#ff0000") A'),
    ("color(1, 0.5, 0) A", "color(1, 0.5, 0) A"),
    ('texture("brick.jpg") A', 'set(material.colormap, "brick.jpg") A'),
    ("setupProjection(0, scope.xy, ~1.5, ~1) projectUV(0) A",
     "setupProjection(0, scope.xy, ~1.5, ~1, 0, 0) projectUV(0) A"),
    ("setupProjection(0, scope.xy, 1.5, 1, 1) A", "setupProjection(0, scope.xy, 1.5, 1, 0, 0) A"),
    ("setupProjection(1, world.zx, '1, 2, 0.5, h) deleteUV(1) A",
     "setupProjection(1, world.zx, 1r, 2, 0.5, @h) deleteUV(1) A"),
    ("setupProjection(0, scope.xz, '1, '20, 0, '8) A", "setupProjection(0, scope.xz, 1r, 20r, 0, 8r) A"),
    ("translateUV(0, 1, h) scaleUV(0, 2, 2) rotateUV(0, 90) A", "translateUV(0, 1, @h) scaleUV(0, 2, 2) rotateUV(0, 90) A"),
    ("tileUV(0, ~2, '1) normalizeUV(0, u, collectiveAllFaces) A", "tileUV(0, ~2, 1r) normalizeUV(0, u) A"),
    ("copyUV(0, 2) A", "copyUV(0, 2) A"),
    ("resetMaterial() resetMaterial(all) A", "resetMaterial() resetMaterial() A"),
    ("resetMaterial(geometry) A", "resetMaterial(geometry)(...) A"),
    ('setMaterial(["color.r", "1"]) A', 'setMaterial(["color.r", "1"]) A'),
    ('insertAlongUV(0, "rail.obj", h) A', 'insertAlongUV(0, "rail.obj", @h) A'),
    ('insertAlongUV(1, "a/" + "rail.obj", 2, vertex.normal, keepPosition) A',
     'insertAlongUV(1, ("a/" + "rail.obj"), 2, vertex.normal, keepPosition) A'),
    ("split(u, uvSpace, 0){ 1 : A | ~1 : B }*", "split(u, uvSpace, 0){ 1: A | ~1: B }*"),
    ("split(v, unitSpace, 1){ 1 : A | { 2 : B }* }", "split(v, unitSpace, 1){ 1: A | { 2: B }* }"),
    ('print("h = " + h) A', "print(...) A"),
    ("set(material.color.r, 1) A", "color(1, material.color.g, material.color.b) A"),
    ("set(material.opacity, h / 4) A", "set(material.opacity, (@h / 4)) A"),
    ("set(material.shininess, 2) A", "set(material.shininess)(...) A"),
    ("set(trim.vertical, false) A", "set(trim.vertical, false) A"),
    ("set(trim.horizontal, false) A", "set(trim.horizontal, false) A"),
    ("set(trim.horizontal, true) A", "set(trim.horizontal, true) A"),
    ("extrude(rint(scope.sx)) A", "extrude(round(Scope.sx)) A"),
    ("extrude(ln(scope.sx)) A", "extrude(log(Scope.sx)) A"),
    ("extrude(rand(2, 4)) A", "extrude(rand(2, 4)) A"),
    ("cleanupGeometry(all, 0.1) A", "cleanupGeometry(all, 0.1) A"),
    ("cleanupGeometry(faces, h / 10) A", "cleanupGeometry(faces, (@h / 10)) A"),
    ("deleteHoles() A", "deleteHoles() A"),
    ("trim() A", "trim() A"),
    ("reduceGeometry(0.8) A", "reduceGeometry(0.8) A"),
    ("mirrorScope(true, false, true) A", "mirrorScope(true, false, true) A"),
    ("trim A", "trim() A"),
    ("splitArea(x){ '0.25 : A | ~1 : B }", "splitArea(x){ 0.25r: A | ~1: B }"),
    ("splitArea(z, noAdjust){ 10 : A }*", "splitArea(z, noAdjust){ 10: A }*"),
    ("splitArea(x){ 5 : A | { ~2 : B }* }", "splitArea(x){ 5: A | { ~2: B }* }"),
    ('report("k", scope.sx > 1 && !(scope.sz < 2) || h == 3) A',
     'report("k", (((Scope.sx > 1) && !(Scope.sz < 2)) || (@h == 3))) A'),
])
def test_operations_lower(body, printed):
    assert body_of(f"{VERSION}attr h = 3\nLot --> {body}\n") == printed


def test_operations_lower_to_their_nodes():
    module = module_of(VERSION + 'Lot --> extrude(3) center(x) alignScopeToAxes() i("builtin:cube") '
                       'color("#fff") set(h, 2) report("k", 1) comp(f){ all : A } \nattr h = 1\n')
    ops = list(iter_ops(module.rules[0].alternatives[0].body))
    assert [type(op) for op in ops] == [ir.Extrude, ir.Center, ir.AlignScope, ir.UseAsset, ir.SetColor,
                                        ir.SetAttr, ir.Report, ir.CompFaces, ir.Symbol]
    assert ops[7].selectors == ("all",)


def test_not_applied_operations_are_listed_for_the_meta(tmp_path):
    path = tmp_path / "g.cga"
    path.write_text(VERSION + 'Lot --> color(1, 0, 0) extrude(3) texture("a.jpg") tileUV(0, 1, 1) '
                    'print(scope.sx) set(material.shininess, 0.5) Mass.\n')
    assert make_plan(compile_grammar(path)).not_applied == ("print", "set(material.shininess)")


def test_tags_are_accepted_without_effect_and_what_reads_them_is_unsupported(tmp_path):
    """``tag``, ``deleteTags`` and ``setTagsFromEdgeAttrs`` name components for what reads the names; those
    readers (here ``geometry.hasTags``) are refused at their line, so no tag is dropped silently."""
    path = tmp_path / "g.cga"
    path.write_text(VERSION + 'Lot --> extrude(3) tag("mass") tag("walls", faces) comp(f){ side : deleteTags() '
                    "setTagsFromEdgeAttrs() W. }\n")
    assert make_plan(compile_grammar(path)).not_applied == ("deleteTags", "setTagsFromEdgeAttrs", "tag")
    line = 'Lot --> tag("mass") report("t", geometry.hasTags("mass"))'
    assert_unsupported_at(line, "geometry.hasTags()", "geometry")



# ------------------------------------------------------------------------------------- split and comp


def test_split_sizes_and_repeat_groups():
    text = VERSION + ("Floor --> split(x){ 0.5 : Wall | { ~3 : Tile | 1 : Pillar }* | '0.1 : Wall"
                      " | { ~2 : Tile }* | 0.5 : Wall }\n")
    op = module_of(text).rules[0].alternatives[0].body[0]
    assert isinstance(op, ir.GroupSplit) and op.axis == 0 and not op.repeat
    K = ir.SizeKind
    assert [(s.kind, print_expr(s.value)) for s in op.sizes] == [
        (K.ABSOLUTE, "0.5"), (K.FLOATING, "3"), (K.ABSOLUTE, "1"), (K.RELATIVE, "0.1"), (K.FLOATING, "2"),
        (K.ABSOLUTE, "0.5")]
    assert op.groups == (-1, 0, 0, -1, 1, -1)
    assert [[s.name for s in p] for p in op.parts] == [["Wall"], ["Tile"], ["Pillar"], ["Wall"], ["Tile"],
                                                       ["Wall"]]


def test_whole_split_repeat_and_nested_splits():
    op = module_of(VERSION + "Facade --> split(y){ ~3.5 : split(x){ { ~2 : Tile }* } | 0.2 : Ledge }*\n") \
        .rules[0].alternatives[0].body[0]
    assert op.axis == 1 and op.repeat and op.groups == (-1, -1)
    inner = op.parts[0][0]
    assert isinstance(inner, ir.GroupSplit) and inner.axis == 0 and inner.groups == (0,)


def test_split_parts_take_operation_sequences():
    assert body_of(VERSION + "Lot --> split(z){ 2 : t(0, 1, 0) s('1, 2, '1) A | ~1 : [ B ] C. }\n") \
        == "split(z){ 2: T(0, 1, 0) S(1r, 2, 1r) A | ~1: [ B ] C. }"


@pytest.mark.parametrize("selectors", [
    ("front", "back", "left", "right", "top", "bottom"),
    ("side", "top"),
    ("vertical", "horizontal"),
    ("aslant", "nutant", "all"),
])
def test_comp_faces_selectors(selectors):
    parts = " | ".join(f"{s} : {s.capitalize()}" for s in selectors)
    op = module_of(f"{VERSION}Mass --> comp(f){{ {parts} }}\n").rules[0].alternatives[0].body[0]
    assert isinstance(op, ir.CompFaces)
    assert op.selectors == selectors
    assert [p[0].name for p in op.parts] == [s.capitalize() for s in selectors]


def test_comp_index_expressions_are_picks_beside_the_named_selectors():
    """``comp(f){ n + 1 : A | n : B | top : C }``: an index given by an expression, a constant or an
    attribute is the selector ``#k`` of the k-th expression of ``picks``."""
    op = module_of(f"{VERSION}const n = 2\nMass --> comp(f){{ n + 1 : A | n = B | top : C }}\n"
                   ).rules[0].alternatives[0].body[0]
    assert op.selectors == ("#0", "#1", "top")
    assert [print_expr(e) for e in op.picks] == ["(@n + 1)", "@n"]


def test_shape_u_moves_front_right_and_left_edges_into_its_shape_part():
    op = module_of(f"{VERSION}Lot --> shapeU(5, 3, 11){{ shape : A | remainder = B }}\n"
                   ).rules[0].alternatives[0].body[0]
    assert isinstance(op, ir.Setback)
    assert [s for s, _ in op.distances] == ["front", "right", "left"]
    assert [d.value for _, d in op.distances] == [5, 3, 11]
    assert op.selectors == ("all", "remainder")


def test_setback_moves_the_edges_its_parts_select():
    op = module_of(f"{VERSION}Lot --> setback(4){{ front : A | left : B | remainder : C }}\n"
                   ).rules[0].alternatives[0].body[0]
    assert [s for s, _ in op.distances] == ["front", "left"]
    assert op.selectors == ("front", "left", "remainder")


@pytest.mark.parametrize("body, printed", [
    # the reference's shortcut: setback(comp(fe){ all : d })
    ("setbackPerEdge(ds[comp.index]){ front : A | remainder : B }",
     "setback(comp(fe){ all=@ds[comp.index] }){ front: A | remainder: B }"),
    ("setbackPerEdge(2, 0){ all = A }", "setback(comp(fe){ all=2 }){ all: A }"),
    ("setbackToArea(100){ all : NIL | remainder : B }", "setbackToArea(100){ all: ε | remainder: B }"),
    # a number after the lists is uvSet; an array gives edge comp.index its element
    ("setbackToArea(100, ds, 0){ all : A }", "setbackToArea(100, comp(fe){ all=@ds[comp.index] }){ all: A }"),
    ("setbackToArea(100, comp(fe){ front : 2 | all : 0 }, ds){ front : A | remainder : B }",
     ("setbackToArea(100, comp(fe){ front=2, all=0 }, comp(fe){ all=((comp.index < size(@ds)) ? "
      "@ds[comp.index] : inf) }){ front: A | remainder: B }")),
])
def test_setback_per_edge_and_to_area_lower_to_setbacks_of_distances_per_edge(body, printed):
    assert body_of(f"{VERSION}const ds = [1, 2]\nLot --> {body}\n") == printed


@pytest.mark.parametrize("body, printed", [
    ("taper(h * 2) A", "taper((@h * 2)) A"),
    ("resetGeometry() A", "resetGeometry() A"),
    ("footprint() extrude(2) A", "footprint() extrude(2) A"),
    ("rectify(h) A", "rectify(@h) A"),
    ("alignScopeToGeometryBBox(zx) A", "alignScopeToGeometryBBox(zx) A"),
    ('alignScopeToGeometryBBox("xy") A', "alignScopeToGeometryBBox(xy) A"),
])
def test_taper_reset_geometry_footprint_and_align_scope_to_geometry_bbox_lower_to_their_nodes(body, printed):
    assert body_of(f"{VERSION}attr h = 2\nLot --> {body}\n") == printed


@pytest.mark.parametrize("line, at, message", [
    ("Lot --> setbackToArea(1, [1], [2], [3]){ all : A }", "setbackToArea",
     "`setbackToArea` takes 1 or 2 or 3 arguments, got 4"),
    ("Lot --> setbackPerEdge(1){ side : A | frnt : B }", "frnt",
     "unsupported: setbackPerEdge selector `frnt` (setbackPerEdge selects "),
    ("Lot --> alignScopeToGeometryBBox(xx) A", "xx",
     "unsupported: alignScopeToGeometryBBox with these axes (alignAxes is one of xy, yx, xz, zx, yz, zy)"),
    ("Lot --> resetGeometry(1) A", "resetGeometry", "`resetGeometry` takes 0 arguments, got 1"),
])
def test_new_operations_name_a_wrong_argument_count_or_selector(line, at, message):
    (found,) = errors(VERSION + line + "\n")
    assert found[:2] == (2, line.index(at) + 1) and found[2].startswith(message), found


@pytest.mark.parametrize("line, at, message", [
    ("Lot --> cleanupGeometry(vertex, 0) A", "vertex",
     "`cleanupGeometry` cleans up all, edges, faces, vertices, got `vertex` (did you mean `vertices`?)"),
    ('Lot --> cleanupGeometry("all", 0) A', '"all"',
     "`cleanupGeometry` cleans up all, edges, faces, vertices, got a string"),
    ("Lot --> cleanupGeometry(all) A", "cleanupGeometry", "`cleanupGeometry` takes 2 arguments, got 1"),
    ("Lot --> cleanupGeometry(all, 0, 1) A", "cleanupGeometry", "`cleanupGeometry` takes 2 arguments, got 3"),
])
def test_cleanup_geometry_names_a_wrong_component_or_argument_count_at_its_line(line, at, message):
    assert errors(VERSION + line + "\n") == [(2, line.index(at) + 1, message)]


@pytest.mark.parametrize("line, at, noun", [
    ("Mass --> comp(f){ side= Wall }", "side", "faces"),
    ("Mass --> comp(f){ top : Roof | all= Rest }", "all=", "faces"),
    ("Mass --> comp(e){ eave = Gutter }", "eave", "edges"),
])
def test_merged_selector_is_derived_face_by_face_with_a_warning(line, at, noun):
    module, diags = compile_ir(VERSION + line + "\n")
    assert not diags.has_errors
    assert [(d.code, d.span.line, d.span.col) for d in diags] == [("merged", 2, line.index(at) + 1),
                                                                  ("start-rule", 2, 1)]
    assert f"for all its {noun}" in next(iter(diags)).message
    assert isinstance(module.rules[0].alternatives[0].body[0], ir.CompFaces)



@pytest.mark.parametrize("call, kind, by_height, indexed", [
    ("roofGable(30, 1, 0.5, false, 2)", "roofGable", False, True),
    ("roofGable(30, 1, 1, true, 0)", "roofGable", False, True),  # with an index, even is ignored
    ("roofGable(30, 1, 0.5)", "roofGable", False, False),
    ("roofRidge(byHeight, 0.4)", "roofRidge", True, False),
    ("roofRidge(byAngle, 30)", "roofRidge", False, False),
])
def test_roof_gable_with_an_edge_index_and_roof_ridge_lower_to_roofs(call, kind, by_height, indexed):
    module = module_of(VERSION + f"Lot --> {call} Roof\nRoof --> X.\n")
    (roof,) = [op for op in iter_ops(module) if isinstance(op, ir.Roof)]
    assert (roof.kind, roof.by_height, roof.indexed) == (kind, by_height, indexed)
    if indexed:
        assert roof.index.value in (2, 0)


@pytest.mark.parametrize("call, even", [
    ("roofHip(30, 1, true)", True), ("roofHip(byHeight, 3, 1, level)", "level"),
    ("roofGable(30, 1, 1, true)", True), ("roofHip(30, 1, false)", None), ("roofGable(30, 1, 1, true, 2)", None),
])
def test_even_ridges_lower_to_the_roofs_even_expression(call, even):
    module = module_of(VERSION + f"attr level = true\nLot --> {call} Roof\nRoof --> X.\n")
    (roof,) = [op for op in iter_ops(module) if isinstance(op, ir.Roof)]
    if even is None:
        assert roof.even is None
    elif even is True:
        assert roof.even == ir.Bool(True, roof.even.span)
    else:
        assert roof.even.name == even



# ------------------------------------------------------------------------------------ the unsupported


@pytest.mark.parametrize("line, name, at", [
    ("Lot --> offset(-2, outside) Inner", "offset with these arguments", "offset"),
    ("Lot --> setback(3){ street.top : Garden | remainder : Building }", "setback selector `street.top`",
     "street"),
    ("Lot --> shapeL(3, 2) Garden", "shapeL without selector parts", "shapeL"),
    ("Lot --> setback(3){ 2 : Garden }", "this setback selector", "2"),
    ("Lot --> envelope(normal, 10, 45) Roof", "envelope with 3 arguments", "envelope"),
    ("Lot --> envelope(normal, 10, [1, 2], [45, 30]) Roof", "envelope with arrays per edge", "envelope"),
    ("Lot --> shapeL(4, 4){ front : A | remainder : NIL }", "shapeL selector `front`", "front"),
    ("Lot --> innerRectangle(world){ shape : A | remainder : NIL }", "innerRectangle with these arguments",
     "innerRectangle"),
    ("Lot --> innerRectangle(scope){ front : A | remainder : NIL }", "innerRectangle selector `front`",
     "front"),
    ("Lot --> modify(4) A", "modify", "modify"),
    ("Lot --> comp(x){ all : A }", "comp(x)", "comp"),
    ("Lot --> comp(f){ street.top : A }", "comp(f) selector `street.top`", "street"),
    ("Lot --> comp(f){ fornt : A }", "comp(f) selector `fornt`", "fornt"),
    ("Lot --> comp(e){ front : A }", "comp(e) selector `front`", "front"),
    ("Lot --> comp(e){ eavs : A }", "comp(e) selector `eavs`", "eavs"),
    ("Lot --> comp(f){ ridge : A }", "comp(f) selector `ridge`", "ridge"),
    ("Lot --> comp(f){ 1.5 : A }", "this comp selector", "1.5"),
    ("Lot --> comp(f){ { front : A }* }", "repeat group in comp", "{ front"),
    ("Lot --> comp(f){ front : A }*", "`*` after comp", "*"),
    ("Lot --> split(x){ 1 = A }", "`=` in split", "1 = A"),
    ("Lot --> split(x){ { 1 : A | { 2 : B }* }* }", "nested repeat groups", "{ 2"),
    ("Lot --> extrude(world.z, 10)", "extrude with this direction", "world.z"),
    ("Lot --> extrude(world.up, 10, 2)", "extrude with 3 arguments", "extrude"),
    ("Lot --> i(\"a.obj\", yUp, \"fitScope\")", "i with this selector", "\"fitScope"),
    ("Lot --> i(\"a.obj\", yUp, keepSizeAndPosition, noCleanup, 1)", "i with 5 arguments", "i("),
    ("Lot --> alignScopeToAxes(object.x) A", "alignScopeToAxes with this axis", "alignScopeToAxes"),
    ("Lot --> alignScopeToGeometry(xUp, 0) A", "alignScopeToGeometry with these arguments",
     "alignScopeToGeometry"),
    ("Lot --> alignScopeToGeometry(yUp, smallest) A", "alignScopeToGeometry with face smallest", "smallest"),
    ("Lot --> alignScopeToGeometry(yUp, 0, shortest) A", "alignScopeToGeometry with edge shortest",
     "shortest"),
    ("Lot --> split(v, 0){ 1 : A | ~1 : B }", "split(v) with these arguments", "split"),
    ("Lot --> split(u, uvSpace, 10){ 1 : A | ~1 : B }", "split with this uvSet", "10"),
    ("Lot --> setupProjection(0, scope.xx, 1, 1) A", "setupProjection axes", "scope.xx"),
    ("Lot --> projectUV(uvSet) A", "projectUV with this uvSet", "uvSet"),
    ("Lot --> normalizeUV(0, w, collectiveAllFaces) A", "normalizeUV with these selectors", "normalizeUV"),
    ("Lot --> copyUV(0, 12) A", "copyUV with this uvSet", "12"),
    ("Lot --> resetMaterial(object) A", "resetMaterial with these arguments", "resetMaterial"),
    ('Lot --> insertAlongUV(0, "a.obj", 1, world.up, alignPosition) A', "insertAlongUV with these selectors",
     "insertAlongUV"),
    ("Lot --> r(scopeMiddle, 0, 45, 0) A", "r with 4 arguments", "r("),
])
def test_unsupported_operation_is_named_at_its_span(line, name, at):
    assert_unsupported_at(line, name, at)


@pytest.mark.parametrize("body, printed", [
    ("scatter(surface, 100, uniform) { Leaf }", "scatter(surface, 100, uniform){ Leaf }"),
    ("scatter(surface, 100, gaussian) { Leaf }", "scatter(surface, 100, gaussian, center, 0.16r){ Leaf }"),
    ("scatter(surface, 100, gaussian, left, '0.1) { Leaf }", "scatter(surface, 100, gaussian, left, 0.1r){ Leaf }"),
    ("scatter(volume, geometry.area / 10, gaussian, top, 2) { s(1, 1, 1) A } NIL",
     "scatter(volume, (geometry.area() / 10), gaussian, top, 2){ S(1, 1, 1) A } \u03b5"),
    ("scatter(scope, 3, uniform)", "scatter(scope, 3, uniform){ \u03b5 }"),
])
def test_scatter_lowers_its_forms_with_the_references_defaults(body, printed):
    assert body_of(VERSION + f"Lot --> {body}\n") == printed


@pytest.mark.parametrize("line, name, at", [
    ("Lot --> scatter(edges, 10, uniform) { A }", "scatter domain `edges`", "edges"),
    ("Lot --> scatter(surface, 10, poisson) { A }", "scatter distribution `poisson`", "poisson"),
    ("Lot --> scatter(surface, 10, gaussian, middle, 1) { A }", "scatter mean `middle`", "middle"),
    ("Lot --> scatter(surface, 10, uniform, center) { A }", "scatter uniform with a mean", "center"),
])
def test_scatter_with_an_unknown_selector_is_unsupported_at_it(line, name, at):
    assert_unsupported_at(line, name, at)


def test_scatter_with_a_wrong_argument_count_is_an_arity_error():
    assert errors(VERSION + "Lot --> scatter(surface, 10) { A }\n") == [
        (2, 9, "`scatter` takes 3 to 5 arguments, got 2")]


# ---------------------------------------------------------------------------------------------- the tables


def test_each_operation_name_is_in_one_table():
    """The lowering asks the tables in turn: a name in two would be lowered by the first alone (an
    operation added to ``OPERATIONS`` leaves ``UNSUPPORTED_OPS``)."""
    names = [*OPERATIONS, *PART_OPERATIONS, *BODY_OPERATIONS, *NOT_APPLIED, *UNSUPPORTED_OPS]
    assert len(names) == len(set(names))


@pytest.mark.parametrize("line, message", [
    ("Lot --> mirror(true, false) A", "`mirror` takes 3 arguments, got 2"),
    ('Lot --> report("k") A', "`report` takes 2 arguments, got 1"),
    ("Lot --> t(1, 2, 3, 4) A", "`t` takes 3 arguments, got 4"),
    ("Lot --> deleteHoles(1) A", "`deleteHoles` takes 0 arguments, got 1"),
    ("Lot --> translate(rel, 1, 2, 3) A", "`translate` takes 5 arguments, got 4"),
    ("Lot --> rotate(rel, world, 1, 2, 3, 4) A", "`rotate` takes 5 arguments, got 6"),
    ("Lot --> translate(by, world, 1, 2, 3) A", "`translate` expects rel or abs first"),
    ("Lot --> rotate(abs, lot, 1, 2, 3) A",
     "`rotate` expects a coordinate system scope, pivot, object or world second"),
    ("Lot --> setback(1, 2){ front : A | remainder : B }", "`setback` takes 1 arguments, got 2"),
    ("Lot --> primitiveCube(1, 2) A", "`primitiveCube` takes 0 or 3 arguments, got 2"),
    ("Lot --> setPivot(xyz) A", "`setPivot` takes 2 arguments, got 1"),
    ("Lot --> setPivot(xzy, 0) A", "`setPivot` expects an axis map xyz, yzx or zxy first"),
    ("Lot --> primitiveCylinder(8, 1) A", "`primitiveCylinder` takes 0 or 1 or 3 arguments, got 2"),
    ("Lot --> primitiveSphere(8) A", "`primitiveSphere` takes 0 or 2 or 3 arguments, got 1"),
    ('Lot --> insertAlongUV(0, "a.obj") A', "`insertAlongUV` takes 3 or 5 arguments, got 2"),
])
def test_a_wrong_argument_count_is_an_arity_error_at_the_operation(line, message):
    assert errors(VERSION + line + "\n") == [(2, 9, message)]


def test_the_arguments_of_a_direct_operation_are_its_fields_in_order():
    body = module_of(VERSION + 'Lot --> mirror(true, false, true) report("k", 2) A\n').rules[0].alternatives[0].body
    mirror, report = body[0], body[1]
    assert isinstance(mirror, ir.Mirror) and [print_expr(a) for a in mirror.axes] == ["true", "false", "true"]
    assert isinstance(report, ir.Report) and (print_expr(report.key), print_expr(report.value)) == ('"k"', "2")


# ------------------------------------------------------------------------------------- the unknown


@pytest.mark.parametrize("line, message, at", [
    ("Lot --> spilt(y){ 3 : Floor }*", "unknown operation `spilt` (did you mean `split`?)", "spilt"),
    ("Lot --> setbak(2){ front : A | remainder : B }", "unknown operation `setbak` (did you mean `setback`?)",
     "setbak"),
    ("Lot --> extrdue(10) Mass", "unknown operation `extrdue` (did you mean `extrude`?)", "extrdue"),
    ("Lot --> Mass colour(1, 0, 0)", "unknown operation `colour` (did you mean `color`?)", "colour"),
    ("Lot --> qq(x){ 3 : A }", "unknown operation `qq`", "qq"),
])
def test_a_misspelt_operation_is_unknown_with_a_suggestion(line, message, at):
    assert errors(VERSION + line + "\n") == [(2, line.index(at) + 1, message)]


def test_a_rule_named_like_a_misspelt_operation_is_called():
    module = module_of(VERSION + "@StartRule\nLot --> extrude(10) spilt(3)\nspilt(n) --> split(y){ ~n : A }*\n")
    assert [op.name for op in module.rules[0].alternatives[0].body if isinstance(op, ir.Symbol)] == ["spilt"]


def test_a_call_of_no_rule_that_is_no_typo_stays_a_leaf_with_a_warning():
    module, diags = compile_ir(VERSION + "@StartRule\nLot --> extrude(10) Facade(3)\n")
    assert [(d.code, d.severity.value) for d in diags] == [("terminal-args", "warning")]
    assert module.graph.terminals == ("Facade",)


#: Every operation of CityEngine's CGA reference (2019-2025), geometry, texturing, scope and tags.
REFERENCE_OPERATIONS = (
    "alignScopeToAxes", "alignScopeToGeometry", "alignScopeToGeometryBBox", "center", "cleanupGeometry",
    "color", "comp", "convexify", "copyUV", "deleteHoles", "deleteTags", "deleteUV", "envelope", "extrude",
    "footprint", "i", "inline", "innerRectangle", "insertAlongUV", "label", "mirror", "mirrorScope",
    "modify", "NIL", "normalizeUV", "offset", "primitiveCone", "primitiveCube", "primitiveCylinder",
    "primitiveDisk", "primitiveQuad", "primitiveSphere", "print", "projectUV", "r", "rectify",
    "reduceGeometry", "report", "resetGeometry", "resetMaterial", "reverseNormals", "roofGable", "roofHip",
    "roofPyramid", "roofRidge", "roofShed", "rotate", "rotateScope", "rotateUV", "s", "scaleUV", "scatter",
    "set", "setback", "setbackPerEdge", "setbackToArea", "setMaterial", "setNormals", "setPivot",
    "setTagsFromEdgeAttrs", "setupProjection", "shapeL", "shapeU", "shapeO", "softenNormals", "split",
    "splitAndSetbackPerimeter", "splitArea", "t", "tag", "taper", "texture", "tileUV", "translate",
    "translateUV", "trim", "union", "subtract", "intersect",
)


def test_every_operation_of_the_reference_is_known():
    assert set(REFERENCE_OPERATIONS) - ALL_OPERATIONS == set()


def test_a_capitalised_call_of_no_rule_is_a_rule_call_not_a_misspelt_operation():
    _, diags = compile_ir(VERSION + "@StartRule\nLot --> Envelope(10) Extrude(3)\n")
    assert [(d.code, d.severity.value) for d in diags] == [("terminal-args", "warning")] * 2


def test_a_rule_of_a_file_imported_without_prefix_is_called(tmp_path):
    (tmp_path / "envelope.cga").write_text(VERSION + "envelop(h) --> extrude(h) X\n")
    main = tmp_path / "main.cga"
    main.write_text(VERSION + 'import "envelope.cga"\n@StartRule\nLot --> envelop(10)\n')
    diags = Diagnostics()
    parse_source(main.read_text(), str(main), diags, path=main)
    assert not diags.has_errors, diags


def test_a_label_is_any_string_expression():
    """``label(name)`` takes a string, constant or computed (``label(occlusionLabel)``, an attribute)."""
    assert body_of(VERSION + 'attr mark = "kiosk"\nLot --> label(mark) label("k" + mark) A\n') == \
        'label(@mark) label(("k" + @mark)) A'
    assert errors(VERSION + "Lot --> label(3) A\n") == [(2, 15, "a label must be a str, got a num")]


def test_an_operation_of_an_older_cga_version_is_todays():
    """ESRI.lib's 2014.0 files write ``offsetUV``, today's ``translateUV``."""
    assert body_of(VERSION + "Lot --> offsetUV(0, 0.5, 0) A\n") == body_of(VERSION + "Lot --> translateUV(0, 0.5, 0) A\n")
