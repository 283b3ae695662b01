"""The operations of CityEngine CGA lowered to IR operations (``split``, ``comp``, ``setback``, roofs,
scope operations, ``set``, ``report``...): ``OperationLowering`` is the mixin of ``lowering.Lowering`` with a
handler per operation that needs one; ``OPERATIONS``, ``PART_OPERATIONS`` (calls with parts
``{ sel : A | ... }``) and ``BODY_OPERATIONS`` (``scatter``, whose braces hold operations) map names to
handlers, or to ``direct`` where the arguments are the IR node's fields; the other tables name the
selectors and roof arguments calls are checked against, and the operations that are accepted but not
applied or not implemented. An operation or construct grammarc does
not implement is an error ``unsupported: NAME`` at its span; a name that is no operation of CityEngine's
reference where only an operation can be (``spilt(y){ ... }``, or a typo of one called where no rule has
the name) is ``unknown operation NAME`` (``check_calls``).
"""

from __future__ import annotations

from dataclasses import fields, replace
from functools import cache

from grammarc.diagnostics import Diagnostics, Typos, suggest, typo_of
from grammarc.frontend.cityengine.nodes import EdgeDistances, Group, Part, PendingOffset, Sized
from grammarc.frontend.direct import direct
from grammarc.ir import nodes as ir
from grammarc.ir.traverse import rewrite_ops


class OperationLowering:
    """The operation handlers of ``Lowering`` (which provides ``expr``, ``arity``, ``unsupported``,
    ``diags``, ``site``...)."""

    def op_roof(self, op, args, span):
        """``roofHip``, ``roofGable``, ``roofShed``, ``roofPyramid``, ``roofRidge``: by angle, or with a
        leading ``byAngle``/``byHeight`` selector. The arguments after the value, in CityEngine's order:
        hip (overhang, even), gable (overhangX, overhangY, even, index), shed (index), pyramid and ridge
        none. ``even`` levels the ridges (``geometry.roofs``); with an edge index a gable's ``even`` is
        ignored, as the reference says."""
        by_height = False
        if args and isinstance(args[0], ir.Name) and args[0].name in ("byAngle", "byHeight"):
            by_height = args[0].name == "byHeight"
            args = args[1:]
        names = ROOF_ARGUMENTS[op] + (("index",) if op == "roofGable" and not by_height else ())
        if not 1 <= len(args) <= 1 + len(names):
            self.diags.error("arity", f"`{op}` takes 1 to {1 + len(names)} arguments after the "
                             f"byAngle/byHeight selector, got {len(args)}", span)
            return ir.Empty(span)
        given = dict(zip(names, (self.expr(a) for a in args[1:])))
        even = given.get("even")
        indexed = op == "roofGable" and "index" in given
        if indexed or (isinstance(even, ir.Bool) and not even.value):
            even = None
        zero = ir.Num(0.0, span)
        overhang = given.get("overhang", given.get("overhangX", zero))
        index = given.get("index", zero) if op == "roofShed" or indexed else zero
        return ir.Roof(op, self.expr(args[0]), by_height, overhang, given.get("overhangY"), index, span,
                       indexed=indexed, even=even)

    def op_envelope(self, op, args, span):
        """``envelope(normal|world.up, maxHeight, baseHeight, angle, ...)``: one (baseHeight, angle) pair
        all round, or the pairs for front and back, front, back and sides, or front, back, right and left
        (``operations.roofing.envelope_edges``)."""
        if len(args) not in (4, 6, 8, 10):
            return self.unsupported(f"envelope with {len(args)} arguments", span,
                                    "envelope(direction, maxHeight, baseHeight, angle, ...) with 1 to 4 sides")
        if not isinstance(args[0], ir.Name) or args[0].name not in ("normal", "world.up", "face.normal"):
            return self.unsupported("envelope with this direction", span, "normal or world.up")
        pairs = [(self.expr(args[k]), self.expr(args[k + 1])) for k in range(2, len(args), 2)]
        if any(isinstance(e, ir.ArrayLit) for pair in pairs for e in pair):
            return self.unsupported("envelope with arrays per edge", span,
                                    "a base height and an angle per side: front, back, sides or right and left")
        (base, angle), others = pairs[0], tuple(pairs[1:])
        zero = ir.Num(0.0, span)
        return ir.Roof("envelope", angle, False, base, None, zero, span, cap=self.expr(args[1]), sides=others)

    def op_extrude(self, op, args, span):
        """``extrude(h)`` or ``extrude(direction, h)``, the direction one of ``ir.EXTRUDE_DIRECTIONS``
        (``world.y`` read as ``world.up``)."""
        if len(args) == 1:
            return ir.Extrude(self.expr(args[0]), span)
        if len(args) != 2:
            return self.unsupported(f"extrude with {len(args)} arguments", span,
                                    "extrude(height) and extrude(direction, height)")
        name = args[0].name if isinstance(args[0], ir.Name) else None
        direction = "world.up" if name == "world.y" else name
        if direction not in ir.EXTRUDE_DIRECTIONS:
            return self.unsupported("extrude with this direction", getattr(args[0], "span", span),
                                    ", ".join(sorted(ir.EXTRUDE_DIRECTIONS)))
        return ir.Extrude(self.expr(args[1]), span, direction)

    def op_translate(self, op, args, span):
        if not self.arity(op, args, (3,), span):
            return ir.Empty(span)
        return ir.Translate(tuple(self.scoped(a, axis) for axis, a in enumerate(args)), span)

    def scoped(self, arg, axis: int) -> ir.Expr:
        """``'v`` in ``t``: v times the scope size on that axis."""
        if isinstance(arg, Sized) and arg.kind is ir.SizeKind.RELATIVE:
            return ir.Binary("*", arg.value, ir.ScopeRef("s" + "xyz"[axis], arg.span), arg.span)
        return self.expr(arg)

    def op_scale(self, op, args, span):
        if not self.arity(op, args, (3,), span):
            return ir.Empty(span)
        sizes = []
        for a in args:
            if isinstance(a, Sized) and a.kind is ir.SizeKind.RELATIVE:
                sizes.append(ir.Size(ir.SizeKind.RELATIVE, a.value, a.span))
            else:
                value = self.expr(a)
                sizes.append(ir.Size(ir.SizeKind.ABSOLUTE, value, getattr(value, "span", span)))
        return ir.Scale(tuple(sizes), span, mirrors=True)

    def op_rotate(self, op, args, span):
        """``r(x, y, z)`` and ``r(scopeOrigin|scopeCenter, x, y, z)``: the same turn, around the scope's
        origin or centre (the reference spells the default ``scopeOrgin`` too).

        The reference's ``r`` adds the angles to ``scope.r``, the scope's angles about its pivot's x, then
        y, then z: ``fixed``, which the derivation applies in the pivot's frame where the grammar keeps
        pivots (``backend.pivot``: a grammar with an ``r`` of several angles does). Elsewhere it turns about
        the scope's x, then y, then z as they were, the same where the scope is aligned with its pivot (on a
        lot, after a ``comp``)."""
        center = False
        if len(args) == 4 and isinstance(args[0], ir.Name) \
                and args[0].name in ("scopeOrigin", "scopeOrgin", "scopeCenter"):
            center = args[0].name == "scopeCenter"
            args = args[1:]
        if len(args) != 3:
            return self.unsupported(f"r with {len(args)} arguments", span,
                                    "r(x, y, z) and r(scopeOrigin|scopeCenter, x, y, z)")
        return ir.Rotate(tuple(self.expr(a) for a in args), span, center=center, fixed=True)

    def op_transform(self, op, args, span):
        """``translate|rotate(rel|abs, scope|pivot|object|world, x, y, z)``."""
        if not self.arity(op, args, (5,), span):
            return ir.Empty(span)
        mode, system = args[0], args[1]
        if not isinstance(mode, ir.Name) or mode.name not in ("rel", "abs"):
            self.diags.error("selector", f"`{op}` expects rel or abs first", span)
            return ir.Empty(span)
        if not isinstance(system, ir.Name) or system.name not in ir.COORDINATE_SYSTEMS:
            self.diags.error("selector", f"`{op}` expects a coordinate system scope, pivot, object or world "
                             "second", span)
            return ir.Empty(span)
        return ir.Transform(op, mode.name == "rel", system.name, tuple(self.expr(a) for a in args[2:]), span)

    def op_set_pivot(self, op, args, span):
        """``setPivot(xyz|yzx|zxy, cornerIndex)``; older rule files quote the axis map (``"yzx"``)."""
        if not self.arity(op, args, (2,), span):
            return ir.Empty(span)
        axes = _selector(args[0])
        if axes not in PIVOT_AXES:
            self.diags.error("selector", f"`{op}` expects an axis map xyz, yzx or zxy first", span)
            return ir.Empty(span)
        return ir.SetPivot(axes, self.expr(args[1]), span)

    def op_color(self, op, args, span):
        if len(args) not in (1, 3, 4):
            return self.unsupported(f"color with {len(args)} arguments", span,
                                    'color(r, g, b) or color("#rrggbb")')
        return ir.SetColor(tuple(self.expr(a) for a in args[:3]), span)

    def op_offset(self, op, args, span):
        """``offset(d)`` (a ``comp(f){ inside | border }`` after it takes its faces: ``fuse_offsets``),
        ``offset(d, inside|border|all)``."""
        if len(args) == 1:
            return PendingOffset(self.expr(args[0]), span)
        if len(args) == 2 and isinstance(args[1], ir.Name) and args[1].name in ir.OFFSET_SELECTORS:
            return ir.Offset(self.expr(args[0]), args[1].name, span)
        return self.unsupported("offset with these arguments", span,
                                "offset(d), offset(d, inside), offset(d, border), offset(d, all)")

    def op_align(self, op, args, span):
        axis = _selector(args[0]) if len(args) == 1 else None
        if not args or axis == "world.xyz":
            return ir.AlignScope("world", None, span)
        if axis is not None and axis.removeprefix("world.") in ("x", "y", "z"):
            return ir.AlignScope(axis.removeprefix("world."), None, span)
        return self.unsupported("alignScopeToAxes with this axis", span,
                                "alignScopeToAxes(), alignScopeToAxes(world.xyz) and alignScopeToAxes(x|y|z)")

    def op_align_geometry(self, op, args, span):
        """``alignScopeToGeometry(upAxis, face[, edge])``. Older rule files write the face ``auto``, which
        the reference no longer lists: grammarc reads it as ``largest``, and without an edge as the
        largest face's ``longest`` edge, the scope a footprint's or a roof floor's main direction gives."""
        up = _selector(args[0]) if args else None
        if len(args) not in (2, 3) or up not in ("yUp", "zUp"):
            return self.unsupported("alignScopeToGeometry with these arguments", span,
                                    "alignScopeToGeometry(yUp|zUp, face[, edge])")
        face, edge = _selector(args[1]), _selector(args[2]) if len(args) == 3 else None
        if face == "auto":
            face, edge = "largest", edge or ("longest" if len(args) == 2 else None)
        if face is not None and face not in ALIGN_FACES:
            return self.unsupported(f"alignScopeToGeometry with face {face}", getattr(args[1], "span", span))
        if edge is not None and edge not in ALIGN_EDGES:
            return self.unsupported(f"alignScopeToGeometry with edge {edge}", getattr(args[2], "span", span))
        face_index = None if face is not None else self.expr(args[1])
        edge_index = None if edge is not None else self.expr(args[2]) if len(args) == 3 else ir.Num(0.0, span)
        return ir.AlignToGeometry(up, face or "index", edge or "index", face_index, edge_index, span)

    def op_rotate_scope(self, op, args, span):
        if len(args) != 3:
            return self.unsupported(f"rotateScope with {len(args)} arguments", span)
        return ir.AlignScope("rotate", tuple(self.expr(a) for a in args), span)

    def op_center(self, op, args, span):
        axes = self.axis_argument(op, args, span)
        return ir.Center(axes, span) if axes else ir.Empty(span)

    def axis_argument(self, op, args, span) -> tuple[int, ...]:
        if len(args) == 1 and isinstance(args[0], ir.Name) and args[0].name in AXIS_NAMES:
            return AXIS_NAMES[args[0].name]
        self.diags.error("axis", f"`{op}` expects an axis selector (x, y, z, xy, xz, yz, xyz)", span)
        return ()

    def op_insert(self, op, args, span):
        """``i(asset[, yUp|zUp[, insertMode[, cleanupMode]]])``; a selector may be written as a string
        (``"zUp"``), as older rule files do, or computed: any other expression, a string per shape (the
        reference's ``i(geometryPath, upAxisOfGeometry, insertMode)`` takes strings; ce.lib's static
        model computes its up axis). The cleanup mode changes nothing here: grammarc does not clean up an
        inserted asset's geometry."""
        if not 1 <= len(args) <= 4:
            return self.unsupported(f"i with {len(args)} arguments", span,
                                    "i(asset[, upAxis[, insertMode[, cleanupMode]]])")
        choices = (ir.UP_AXES, ir.INSERT_MODES, ("numericalCleanup", "noCleanup"))
        chosen: list = [c[0] for c in choices]  # the defaults
        for k, (arg, allowed) in enumerate(zip(args[1:], choices)):
            written = arg.name if isinstance(arg, ir.Name) else arg.value if isinstance(arg, ir.Str) else None
            if written in allowed:
                chosen[k] = written
            elif isinstance(arg, ir.Str):
                return self.unsupported("i with this selector", arg.span, f"one of {', '.join(allowed)}")
            else:  # computed: checked per shape
                chosen[k] = self.expr(arg)
        (up, up_by), (mode, mode_by) = ((c, None) if isinstance(c, str) else (d[0], c)
                                        for c, d in zip(chosen[:2], choices))
        if isinstance(args[0], ir.Str):
            return ir.UseAsset(args[0].value, span, up=up, mode=mode, up_by=up_by, mode_by=mode_by)
        return ir.UseAsset("", span, name=self.expr(args[0]), up=up, mode=mode, up_by=up_by, mode_by=mode_by)

    def op_cube(self, op, args, span):
        """``primitiveCube()`` is ``i("builtin:cube")``; with its sizes a ``Primitive``."""
        if not args:
            return ir.UseAsset("builtin:cube", span)
        return self.op_primitive(op, args, span)

    def op_primitive(self, op, args, span):
        """``primitiveQuad/Disk/Cylinder/Sphere/Cone(segments..., sizes...)``: all segments or none, then all
        sizes or none (``ir.PRIMITIVES``)."""
        kind = op.removeprefix("primitive").lower()
        defaults, sizes = ir.PRIMITIVES[kind]
        if not self.arity(op, args, tuple(sorted({0, len(defaults), len(defaults) + len(sizes)})), span):
            return ir.Empty(span)
        values = [self.expr(a) for a in args]
        segments = tuple(values[:len(defaults)]) if values else tuple(ir.Num(float(d), span) for d in defaults)
        given = tuple(values[len(defaults):])
        return ir.Primitive(kind, segments, given or None, span)

    def op_nil(self, op, args, span):
        return ir.Empty(span)

    def op_set(self, op, args, span):
        if not self.arity(op, args, (2,), span):
            return ir.Empty(span)
        target = args[0]
        if isinstance(target, ir.ContextRef) and target.name in ir.MATERIAL_FIELDS:
            return self.set_material(target.name, self.expr(args[1]), span)
        if isinstance(target, ir.ScopeRef) and target.field[0] in "tsr":
            return self.set_scope(target, self.expr(args[1]), span)
        if isinstance(target, ir.Name) and target.name in ir.SHAPE_ATTRIBUTES:
            return ir.SetAttr(target.name, self.expr(args[1]), span)
        if isinstance(target, ir.Name) and target.name.startswith("material."):
            return ir.NotApplied(f"set({target.name})", span)
        if not isinstance(target, ir.Name):
            return self.unsupported("set of this target", span, "set(attribute, value)")
        return ir.SetAttr(target.name, self.expr(args[1]), span)

    def set_material(self, name: str, value: ir.Expr, span) -> ir.Op:
        """``set(material.*, v)`` of an attribute the shape carries (``ir.MATERIAL_FIELDS``): a texture
        channel is a string attribute; a colour component is ``color`` with the other two kept, the
        opacity the colour's alpha."""
        if name in ir.SHAPE_ATTRIBUTES:
            return ir.SetAttr(name, value, span)
        if name == "material.opacity":
            return ir.SetOpacity(value, span)
        channel = "rgb".index(name[-1])
        return ir.SetColor(tuple(value if k == channel else ir.ContextRef(f"material.color.{c}", span)
                                 for k, c in enumerate("rgb")), span)

    def op_texture(self, op, args, span):
        """``texture(path)`` is ``set(material.colormap, path)``."""
        if not self.arity(op, args, (1,), span):
            return ir.Empty(span)
        return ir.SetAttr("material.colormap", self.expr(args[0]), span)

    def set_scope(self, target: ir.ScopeRef, value: ir.Expr, span) -> ir.Op:
        """``set(scope.tx, v)`` and its kin: the one field set, the other two of its vector kept. Positions
        and angles are the pivot's (``scope.t*``, ``scope.r*`` read them there), so they become an absolute
        ``translate``/``rotate`` in the pivot system; sizes an ``s`` of absolute sizes."""
        kind, axis = target.field[0], "xyz".index(target.field[1])
        values = tuple(value if k == axis else ir.ScopeRef(kind + "xyz"[k], target.span) for k in range(3))
        if kind == "s":
            return ir.Scale(tuple(ir.Size(ir.SizeKind.ABSOLUTE, v, getattr(v, "span", span)) for v in values), span,
                            mirrors=True)
        return ir.Transform("translate" if kind == "t" else "rotate", False, "pivot", values, span)

    def op_split(self, op, args, parts, span, repeat=False):
        """``split(axis[, adjust|noAdjust]){ size : A | { size : B }* | ... }``, repeated as a whole when
        ``repeat`` (``{ ... }*``)."""
        texture = None
        if args and isinstance(args[0], ir.Name) and args[0].name in ("u", "v"):
            space = args[1].name if len(args) == 3 and isinstance(args[1], ir.Name) else None
            if space not in ("uvSpace", "unitSpace"):
                return self.unsupported(f"split({args[0].name}) with these arguments", span,
                                        f"split({args[0].name}, uvSpace|unitSpace, uvSet)")
            texture = self.uv_set("split", args[2], span), space == "unitSpace"
            if texture[0] is None:
                return ir.Empty(span)
            args = (ir.Name("xy"[args[0].name == "v"], args[0].span),)
        if not args or not isinstance(args[0], ir.Name) or args[0].name not in ("x", "y", "z"):
            self.diags.error("axis", "`split` expects an axis x, y or z", span)
            return ir.Empty(span)
        for extra in args[1:]:
            if not (isinstance(extra, ir.Name) and extra.name in ("adjust", "noAdjust")):
                return self.unsupported("this split option", getattr(extra, "span", span))
        sizes, groups, bodies = [], [], []
        n_groups = 0
        for item in parts:
            if isinstance(item, Group):
                for inner in item.parts:
                    if isinstance(inner, Group):
                        return self.unsupported("nested repeat groups", inner.span)
                    sizes.append(self.size_of(inner))
                    groups.append(n_groups)
                    bodies.append(inner.body)
                n_groups += 1
            else:
                sizes.append(self.size_of(item))
                groups.append(-1)
                bodies.append(item.body)
        adjust = not any(isinstance(extra, ir.Name) and extra.name == "noAdjust" for extra in args[1:])
        uv_set, unit_space = texture or (-1, False)
        return ir.GroupSplit("xyz".index(args[0].name), tuple(sizes), tuple(groups), tuple(bodies), repeat,
                             span, self.site(), adjust, uv_set, unit_space)

    def op_split_area(self, op, args, parts, span, repeat=False):
        """``splitArea(axis[, adjust|noAdjust]){ area : A | ... }[*]``: a split's parts, their sizes areas."""
        split = self.op_split(op, args, parts, span, repeat)
        if not isinstance(split, ir.GroupSplit):
            return split
        return ir.SplitArea(*(getattr(split, f.name) for f in fields(split)))

    def size_of(self, part: Part) -> ir.Size:
        if part.merged:
            self.unsupported("`=` in split", part.span)
        return ir.Size(part.size.kind, part.size.value, part.size.span)

    def op_comp(self, op, args, parts, span):
        if len(args) != 1 or not isinstance(args[0], ir.Name) or args[0].name not in COMP_SELECTORS:
            kind = args[0].name if args and isinstance(args[0], ir.Name) else "?"
            return self.unsupported(f"comp({kind})", span, "comp(f), comp(e) and comp(v)")
        kind = args[0].name
        picks: list[ir.Expr] = []
        noun = {"f": "faces", "e": "edges", "v": "vertices"}[kind]
        chosen = self.selector_parts("comp", parts, COMP_SELECTORS[kind], named=f"comp({kind})", noun=noun,
                                     indices=picks)
        if chosen is None:
            return ir.Empty(span)
        return ir.CompFaces(*chosen, span, self.site(), kind, picks=tuple(picks))

    def op_setback(self, op, args, parts, span):
        """``setback(d) { sel: A | remainder: B }``; ``shapeL/U/O(widths...) { shape: A | remainder: B }``;
        ``setback(comp(fe){ sel: d | ... }) { ... }`` with distances per edge."""
        sides = SETBACK_OPS[op]
        if op == "setback" and len(args) == 1 and isinstance(args[0], EdgeDistances):
            chosen = self.selector_parts(op, parts, SETBACK_SELECTORS)
            if chosen is None:
                return ir.Empty(span)
            return ir.Setback(args[0].values, chosen[0], chosen[1], span, self.site(), per_edge=True)
        if not self.arity(op, args, (len(sides) if sides else 1,), span):
            return ir.Empty(span)
        known = SETBACK_SELECTORS if not sides else frozenset({"shape", "remainder"})
        chosen = self.selector_parts(op, parts, known)
        if chosen is None:
            return ir.Empty(span)
        selectors = tuple("all" if s == "shape" else s for s in chosen[0])
        exprs = tuple(self.expr(a) for a in args)
        if sides:
            distances = tuple(zip(sides, exprs))
        else:
            distances = tuple((s, exprs[0]) for s in selectors if s != "remainder")
        return ir.Setback(distances, selectors, chosen[1], span, self.site())

    def op_setback_per_edge(self, op, args, parts, span):
        """``setbackPerEdge(d[, uvSet]) { ... }``: the reference's shortcut for ``setback(comp(fe){ all: d
        }) { ... }``, ``d`` evaluated for each edge. ``uvSet`` only matters to the uv selectors, which
        grammarc's setbacks do not have: it is read and has no effect."""
        if not self.arity(op, args, (1, 2), span):
            return ir.Empty(span)
        chosen = self.selector_parts(op, parts, SETBACK_SELECTORS)
        if chosen is None:
            return ir.Empty(span)
        return ir.Setback((("all", self.expr(args[0])),), chosen[0], chosen[1], span, self.site(), per_edge=True)

    def op_setback_to_area(self, op, args, parts, span):
        """``setbackToArea(area[, minDistances[, maxDistances]][, uvSet]) { ... }``. A distance list is an
        array (``[2, 0, 1]``: edge ``comp.index`` takes its element; a minimum past its end is 0, a maximum
        none) or ``comp(fe){ sel: d | ... }``. The reference tells ``uvSet`` from a list only by its type:
        a number written as such after the lists is ``uvSet`` (read, without effect as in
        ``setbackPerEdge``), any other expression a list."""
        if args and len(args) > 1 and isinstance(args[-1], ir.Num):
            args = args[:-1]
        if not self.arity(op, args, (1, 2, 3), span):
            return ir.Empty(span)
        chosen = self.selector_parts(op, parts, SETBACK_SELECTORS)
        if chosen is None:
            return ir.Empty(span)
        index = ir.ContextRef("comp.index", span)
        lists = []
        for k, arg in enumerate(args[1:]):
            if isinstance(arg, EdgeDistances):
                lists.append(arg.values)
                continue
            array = self.expr(arg)
            element = ir.Index(array, index, span=span)
            if k == 1:  # past the end of the maximums: no cap
                inside = ir.Binary("<", index, ir.Call("size", (array,), span, self.site()), span)
                element = ir.Select(inside, element, ir.Num(float("inf"), span), span)
            lists.append((("all", element),))
        minimum, maximum = (*lists, (), ())[:2]
        return ir.SetbackToArea(self.expr(args[0]), minimum, maximum, chosen[0], chosen[1], span, self.site())

    def op_align_scope_to_bbox(self, op, args, span):
        """``alignScopeToGeometryBBox(alignAxes)``, the two scope axes it turns (``xz``: x along the longer
        side, z across it, about y)."""
        if not self.arity(op, args, (1,), span):
            return ir.Empty(span)
        axes = _selector(args[0])
        if axes is None or len(axes) != 2 or set(axes) not in ({"x", "y"}, {"x", "z"}, {"y", "z"}):
            return self.unsupported(f"{op} with these axes", getattr(args[0], "span", span),
                                    "alignAxes is one of xy, yx, xz, zx, yz, zy")
        return ir.AlignScopeToBBox(("xyz".index(axes[0]), "xyz".index(axes[1])), span)

    def op_setback_alone(self, op, args, span):
        """``setback(d)`` without parts (public files write it, as if it were an operation on its own):
        the reference knows only the form with parts, and a user who writes it means the face set back by
        ``d`` all round, the remainder that ``setback(d){ all: NIL | remainder: ... }`` would give:
        ``offset(-d, inside)``, whose mitred inset is the same polygon."""
        if not self.arity(op, args, (1,), span):
            return ir.Empty(span)
        distance = self.expr(args[0])
        return ir.Offset(ir.Unary("-", distance, getattr(distance, "span", span)), "inside", span)

    def op_label(self, op, args, span):
        if not self.arity(op, args, (1,), span):
            return ir.Empty(span)
        return ir.Label(self.expr(args[0]), span)

    def op_convexify(self, op, args, span):
        if len(args) > 1:
            return self.unsupported(f"convexify with {len(args)} arguments", span,
                                    "convexify() and convexify(maxLength)")
        return ir.Convexify(self.expr(args[0]) if args else None, span)

    def op_cleanup(self, op, args, span):
        """``cleanupGeometry(components, tolerance)``, components one of ``ir.CLEANUP_COMPONENTS``."""
        if not self.arity(op, args, (2,), span):
            return ir.Empty(span)
        component = args[0]
        known = ir.CLEANUP_COMPONENTS
        if not isinstance(component, ir.Name) or component.name not in known:
            got = (f"`{component.name}`{suggest(component.name, known)}" if isinstance(component, ir.Name)
                   else "a string" if isinstance(component, ir.Str) else "an expression")
            self.diags.error("component", f"`{op}` cleans up {', '.join(sorted(known))}, got {got}",
                             getattr(component, "span", span))
            return ir.Empty(span)
        return ir.CleanupGeometry(component.name, self.expr(args[1]), span)

    def op_inner_rectangle(self, op, args, parts, span):
        """``innerRectangle(scope|edge) { shape: A | remainder: B }``."""
        if len(args) != 1 or not isinstance(args[0], ir.Name) or args[0].name not in ("scope", "edge"):
            return self.unsupported("innerRectangle with these arguments", span,
                                    "innerRectangle(scope) and innerRectangle(edge)")
        chosen = self.selector_parts(op, parts, frozenset({"shape", "remainder"}))
        if chosen is None:
            return ir.Empty(span)
        return ir.InnerRectangle(args[0].name, chosen[0], chosen[1], span, self.site())

    def op_scatter(self, op, args, body, span):
        """``scatter(domain, n, uniform|gaussian[, mean[, stddev]]) { operations }``: the gaussian's mean
        defaults to ``center`` and its deviation to ``'0.16``, as the reference has them."""
        if not 3 <= len(args) <= 5:
            self.diags.error("arity", f"`{op}` takes 3 to 5 arguments, got {len(args)}", span)
            return ir.Empty(span)
        names = [a.name if isinstance(a, ir.Name) else None for a in args]
        for i, noun, known in ((0, "domain", ir.SCATTER_DOMAINS), (2, "distribution", SCATTER_TYPES)):
            if names[i] not in known:
                return self.unsupported(f"scatter {noun} `{names[i] or 'expression'}`", args[i].span,
                                        f"scatter takes {', '.join(sorted(known))}")
        if len(args) > 3 and names[2] != "gaussian":
            return self.unsupported("scatter uniform with a mean", args[3].span, "only gaussian takes one")
        mean = names[3] if len(args) > 3 else "center"
        if mean not in ir.SCATTER_MEANS:
            return self.unsupported(f"scatter mean `{mean or 'expression'}`", args[3].span,
                                    f"the mean is one of {', '.join(sorted(ir.SCATTER_MEANS))}")
        stddev = args[4] if len(args) > 4 else Sized(ir.SizeKind.RELATIVE, ir.Num(0.16, span), span)
        relative = isinstance(stddev, Sized) and stddev.kind is ir.SizeKind.RELATIVE
        value = stddev.value if relative else self.expr(stddev)
        return ir.Scatter(names[0], self.expr(args[1]), names[2] == "gaussian", mean, value, relative, (body,),
                          span, self.site())

    def uv_set(self, op, arg, span) -> int | None:
        """The texture set an operation names: a whole number in [0, 9] (None after an error)."""
        if isinstance(arg, ir.Num) and arg.value == int(arg.value) and 0 <= arg.value <= 9:
            return int(arg.value)
        self.unsupported(f"{op} with this uvSet", getattr(arg, "span", span), "a number from 0 to 9")
        return None

    def texture_size(self, arg) -> ir.Size:
        """A texture width, height or offset: absolute, relative (``'0.5``) or floating (``~2``)."""
        if isinstance(arg, Sized):
            return ir.Size(arg.kind, arg.value, arg.span)
        value = self.expr(arg)
        return ir.Size(ir.SizeKind.ABSOLUTE, value, getattr(value, "span", ir.NO_SPAN))

    def op_setup_projection(self, op, args, span):
        """``setupProjection(uvSet, scope.xy|world.xz|..., width, height[, uOffset, vOffset][, uwFactor])``: the
        reference's four forms (a fifth argument alone is ``uwFactor``, which drives the w coordinate grammarc
        does not keep)."""
        if not self.arity(op, args, (4, 5, 6, 7), span):
            return ir.Empty(span)
        uv_set = self.uv_set(op, args[0], span)
        axes = ir.PROJECTION_AXES.get(args[1].name) if isinstance(args[1], ir.Name) else None
        if axes is None:
            return self.unsupported(f"{op} axes", getattr(args[1], "span", span),
                                    "scope.xy, scope.xz, world.xz... (two different axes)")
        if uv_set is None:
            return ir.Empty(span)
        zero = ir.Size(ir.SizeKind.ABSOLUTE, ir.Num(0.0, span), span)
        offsets = (self.texture_size(args[4]), self.texture_size(args[5])) if len(args) > 5 else (zero, zero)
        return ir.SetupProjection(uv_set, *axes, (self.texture_size(args[2]), self.texture_size(args[3])),
                                  offsets, span)

    def op_project_uv(self, op, args, span):
        """``projectUV(uvSet)`` and ``deleteUV(uvSet)``."""
        if not self.arity(op, args, (1,), span):
            return ir.Empty(span)
        uv_set = self.uv_set(op, args[0], span)
        return ir.Empty(span) if uv_set is None else ir.ProjectUV(uv_set, op == "deleteUV", span)

    def op_transform_uv(self, op, args, span):
        """``translateUV(uvSet, u, v)``, ``scaleUV(uvSet, u, v)``, ``rotateUV(uvSet, degrees)``."""
        if not self.arity(op, args, (2,) if op == "rotateUV" else (3,), span):
            return ir.Empty(span)
        uv_set = self.uv_set(op, args[0], span)
        if uv_set is None:
            return ir.Empty(span)
        return ir.TransformUV(op[:-2], uv_set, tuple(self.expr(a) for a in args[1:]), span)

    def op_tile_uv(self, op, args, span):
        """``tileUV(uvSet, width, height)``."""
        if not self.arity(op, args, (3,), span):
            return ir.Empty(span)
        uv_set = self.uv_set(op, args[0], span)
        if uv_set is None:
            return ir.Empty(span)
        return ir.TileUV(uv_set, (self.texture_size(args[1]), self.texture_size(args[2])), span)

    def op_normalize_uv(self, op, args, span):
        """``normalizeUV(uvSet, uv|uvUniform|u|v, separatePerFace|collectiveAllFaces)``."""
        if not self.arity(op, args, (3,), span):
            return ir.Empty(span)
        uv_set = self.uv_set(op, args[0], span)
        names = [a.name if isinstance(a, ir.Name) else None for a in args[1:]]
        if names[0] not in NORMALIZE_MODES or names[1] not in ("separatePerFace", "collectiveAllFaces"):
            return self.unsupported(f"{op} with these selectors", span,
                                    "normalizeUV(uvSet, uv|uvUniform|u|v, separatePerFace|collectiveAllFaces)")
        return ir.Empty(span) if uv_set is None else ir.NormalizeUV(uv_set, names[0], span)

    def op_copy_uv(self, op, args, span):
        """``copyUV(uvSetSource, uvSetDest)``."""
        if not self.arity(op, args, (2,), span):
            return ir.Empty(span)
        source, dest = (self.uv_set(op, a, span) for a in args)
        return ir.Empty(span) if source is None or dest is None else ir.CopyUV(dest, source, span)

    def op_insert_along_uv(self, op, args, span):
        """``insertAlongUV(uvSet, asset, height[, scope.y|vertex.normal, alignPosition|keepPosition])``."""
        if not self.arity(op, args, (3, 5), span):
            return ir.Empty(span)
        uv_set = self.uv_set(op, args[0], span)
        chosen = [a.name if isinstance(a, ir.Name) else None for a in args[3:]]
        if chosen and (chosen[0] not in ir.ALONG_UV_DIRECTIONS or chosen[1] not in ir.ALONG_UV_ALIGNMENTS):
            return self.unsupported(f"{op} with these selectors", span, f"{op}(uvSet, asset, height, "
                                    "scope.y|vertex.normal, alignPosition|keepPosition)")
        direction, alignment = chosen or (ir.ALONG_UV_DIRECTIONS[0], ir.ALONG_UV_ALIGNMENTS[0])
        if uv_set is None:
            return ir.Empty(span)
        asset, name = (args[1].value, None) if isinstance(args[1], ir.Str) else ("", self.expr(args[1]))
        return ir.InsertAlongUV(uv_set, asset, self.expr(args[2]), span, name, direction, alignment)

    def op_reset_material(self, op, args, span):
        """``resetMaterial([shape|geometry|all])``: ``geometry`` resets an inserted asset's own materials,
        which grammarc does not keep, so it changes nothing in the record (its meta lists it)."""
        target = args[0].name if len(args) == 1 and isinstance(args[0], ir.Name) else "shape" if not args else None
        if target not in ("shape", "geometry", "all"):
            return self.unsupported(f"{op} with these arguments", span, f"{op}() or {op}(shape|geometry|all)")
        return ir.NotApplied(f"{op}(geometry)", span) if target == "geometry" else ir.ResetMaterial(span)

    def selector_parts(self, op, parts, known, named=None, noun="polygons", indices=None):
        """The selectors and bodies of ``{ sel: A | ... }`` parts, all among ``known`` (None after an
        error); ``sel=`` is derived as ``sel:``, with a warning. ``named`` is the operation as a selector
        error names it (``comp(f)``; default ``op``), ``noun`` what ``sel=`` would merge (None: nothing,
        the parts of ``comp(fe)`` are distances).

        With ``indices`` (a list, comp's), a whole number ``3`` selects the component of that index (the
        selector ``"3"``), and any other expression (``n + 1``, a constant, an attribute) the component
        whose index it evaluates to for the shape: the selector ``"#k"``, the expression appended to
        ``indices`` as its k-th. A bare name is an expression unless it is a selector word of CityEngine's,
        or one edit from one of ``known`` (``fornt``): a typo, not a constant."""
        named = named or op
        selectors, bodies = [], []
        for part in parts:
            if isinstance(part, Group):
                self.unsupported(f"repeat group in {op}", part.span)
                return None
            value = part.size.value
            if (indices is not None and part.size.kind is ir.SizeKind.ABSOLUTE and isinstance(value, ir.Num)
                    and value.value >= 0 and value.value == int(value.value)):
                selectors.append(str(int(value.value)))
                bodies.append(part.body)
                continue
            if indices is not None and part.size.kind is ir.SizeKind.ABSOLUTE and _index_expression(value, known):
                selectors.append(f"#{len(indices)}")
                indices.append(self.expr(value))
                bodies.append(part.body)
                continue
            if part.size.kind is not ir.SizeKind.ABSOLUTE or not isinstance(value, ir.Name):
                self.unsupported(f"this {op} selector", part.span)
                return None
            if value.name not in known:
                listed = ", ".join(sorted(known - {"remainder"}))
                why = f"{named} selects {listed}" + (" and remainder" if "remainder" in known else "")
                self.unsupported(f"{named} selector `{value.name}`", value.span, why + suggest(value.name, known))
                return None
            if part.merged and noun is not None:
                self.diags.warning(
                    "merged", f"`{value.name}=` gives one shape for all its {noun} in CityEngine; grammarc "
                    "derives them one by one (the same leaves; operations that read the scope differ)",
                    part.span)
            selectors.append(value.name)
            bodies.append(part.body)
        return tuple(selectors), tuple(bodies)


#: Operations called without parts: name -> handler(lowering, op, args, span).
OPERATIONS = {
    "color": OperationLowering.op_color,
    "offset": OperationLowering.op_offset,
    "mirror": direct(ir.Mirror),
    "alignScopeToAxes": OperationLowering.op_align,
    "alignScopeToGeometry": OperationLowering.op_align_geometry,
    "rotateScope": OperationLowering.op_rotate_scope,
    "extrude": OperationLowering.op_extrude,
    "t": OperationLowering.op_translate,
    "s": OperationLowering.op_scale,
    "r": OperationLowering.op_rotate,
    "translate": OperationLowering.op_transform,
    "rotate": OperationLowering.op_transform,
    "setPivot": OperationLowering.op_set_pivot,
    "center": OperationLowering.op_center,
    "i": OperationLowering.op_insert,
    "primitiveCube": OperationLowering.op_cube,
    "primitiveQuad": OperationLowering.op_primitive,
    "primitiveDisk": OperationLowering.op_primitive,
    "primitiveCylinder": OperationLowering.op_primitive,
    "primitiveSphere": OperationLowering.op_primitive,
    "primitiveCone": OperationLowering.op_primitive,
    "NIL": OperationLowering.op_nil,
    "set": OperationLowering.op_set,
    "report": direct(ir.Report),
    "convexify": OperationLowering.op_convexify,
    "cleanupGeometry": OperationLowering.op_cleanup,
    "deleteHoles": direct(ir.DeleteHoles),
    "label": OperationLowering.op_label,
    "envelope": OperationLowering.op_envelope,
    "roofHip": OperationLowering.op_roof,
    "roofGable": OperationLowering.op_roof,
    "roofShed": OperationLowering.op_roof,
    "roofPyramid": OperationLowering.op_roof,
    "trim": direct(ir.Trim),
    "reduceGeometry": direct(ir.ReduceGeometry),
    "mirrorScope": direct(ir.MirrorScope),
    "roofRidge": OperationLowering.op_roof,
    "texture": OperationLowering.op_texture,
    "setupProjection": OperationLowering.op_setup_projection,
    "projectUV": OperationLowering.op_project_uv,
    "deleteUV": OperationLowering.op_project_uv,
    "translateUV": OperationLowering.op_transform_uv,
    "scaleUV": OperationLowering.op_transform_uv,
    "rotateUV": OperationLowering.op_transform_uv,
    "tileUV": OperationLowering.op_tile_uv,
    "normalizeUV": OperationLowering.op_normalize_uv,
    "taper": direct(ir.Taper),
    "resetGeometry": direct(ir.ResetGeometry),
    "footprint": direct(ir.Footprint),
    "rectify": direct(ir.Rectify),
    "alignScopeToGeometryBBox": OperationLowering.op_align_scope_to_bbox,
    "copyUV": OperationLowering.op_copy_uv,
    "insertAlongUV": OperationLowering.op_insert_along_uv,
    "resetMaterial": OperationLowering.op_reset_material,
    "setMaterial": direct(ir.SetMaterial),
}
#: Operations with parts ``{ ... }``: name -> handler(lowering, op, args, parts, span); those of ``REPEATING``
#: also repeat (``{ ... }*``), with ``repeat=True``.
PART_OPERATIONS = {
    "split": OperationLowering.op_split,
    "splitArea": OperationLowering.op_split_area,
    "comp": OperationLowering.op_comp,
    "setback": OperationLowering.op_setback,
    "shapeL": OperationLowering.op_setback,
    "shapeU": OperationLowering.op_setback,
    "shapeO": OperationLowering.op_setback,
    "innerRectangle": OperationLowering.op_inner_rectangle,
    "setbackPerEdge": OperationLowering.op_setback_per_edge,
    "setbackToArea": OperationLowering.op_setback_to_area,
}
REPEATING = frozenset({"split", "splitArea"})
#: Operations with parts that may also come without them: name -> handler(lowering, op, args, span).
WITHOUT_PARTS = {
    "setback": OperationLowering.op_setback_alone,
}
#: Operations with a body ``{ operations }``: name -> handler(lowering, op, args, body, span).
BODY_OPERATIONS = {
    "scatter": OperationLowering.op_scatter,
}
#: The modes of ``normalizeUV``.
NORMALIZE_MODES = frozenset({"uv", "uvUniform", "u", "v"})
#: The distributions of ``scatter``.
SCATTER_TYPES = frozenset({"uniform", "gaussian"})
#: The optional arguments after a roof's value (roofGable's ``index`` only by angle).
ROOF_ARGUMENTS = {"roofHip": ("overhang", "even"), "roofGable": ("overhangX", "overhangY", "even"),
                   "roofShed": ("index",), "roofPyramid": (), "roofRidge": ()}
#: Operations CityEngine also takes without their parentheses (other bare names are rules).
BARE_OPS = frozenset({"NIL", "primitiveCube", "convexify", "alignScopeToAxes", "primitiveQuad", "primitiveDisk",
                      "primitiveCylinder", "primitiveSphere", "primitiveCone", "trim"})
#: Part operations whose parts are sizes or faces: without parts, `unsupported: split` (the others say
#: that their selector parts are missing).
SPLIT_OPS = frozenset({"split", "comp"})
#: CityEngine's street selectors (``geometry.streets``): the lot's street edges and the faces along them.
STREET_SELECTORS = frozenset(f"street.{s}" for s in ("front", "back", "left", "right", "side"))
COMP_SELECTORS = {
    "f": ir.FACE_SELECTORS | ir.OFFSET_SELECTORS | STREET_SELECTORS
    | {f"{frame}.{s}" for frame in ("object", "world") for s in ir.FACE_SELECTORS} | set(ir.WORLD_COMPASS),
    "e": ir.EDGE_SELECTORS,
    "v": ir.VERTEX_SELECTORS,
}
#: Setback operations and the edges their distances move (``setback`` moves those its parts select).
SETBACK_OPS = {"setback": (), "shapeL": ("front", "left"), "shapeU": ("front", "right", "left"),
                "shapeO": ("front", "right", "back", "left")}
#: Edge selectors of ``setback``: an edge is named as the face an extrusion of the polygon would make of it.
SETBACK_SELECTORS = (COMP_SELECTORS["f"] - ir.OFFSET_SELECTORS) | {"all", "remainder", "streetSide", "noStreetSide"}
#: Shape attributes that grammarc does not provide yet: comp.index, split.index, initialShape.origin...
UNSUPPORTED_MEMBERS = frozenset({"comp", "split", "initialShape", "geometry"})
#: Operations that are parsed and accepted but do not change the record (listed in its meta).
NOT_APPLIED = frozenset({
    "reverseNormals", "print", "setNormals", "softenNormals",
    # component tags name faces, edges and vertices for what reads them (inline, the boolean operations,
    # geometry.hasTags and geometry.tags, tag selectors), each unsupported with its own error
    "tag", "deleteTags", "setTagsFromEdgeAttrs",
})
#: CityEngine operations grammarc does not implement yet (the README's operations table says why).
#: With ``OPERATIONS``, ``PART_OPERATIONS`` and ``NOT_APPLIED`` they are every operation of CityEngine's
#: CGA reference, so that any other name called with parts, or a typo of one of them, is unknown.
UNSUPPORTED_OPS = frozenset({"inline", "modify", "splitAndSetbackPerimeter", "union", "subtract", "intersect"})
#: Every operation name CityEngine knows: what a misspelt one is suggested from.
ALL_OPERATIONS = (frozenset(OPERATIONS) | frozenset(PART_OPERATIONS) | frozenset(BODY_OPERATIONS) | NOT_APPLIED
                  | UNSUPPORTED_OPS)
#: Face and edge selectors of ``alignScopeToGeometry``.
ALIGN_FACES = frozenset({"largest", "world.lowest", "any"})
ALIGN_EDGES = frozenset({"longest", "world.lowest"})
#: ``setPivot``'s axis maps.
PIVOT_AXES = frozenset({"xyz", "yzx", "zxy"})
#: Axis selectors of ``center`` and ``alignScopeToAxes``.
AXIS_NAMES = {"x": (0,), "y": (1,), "z": (2,), "xy": (0, 1), "xz": (0, 2), "yz": (1, 2), "xyz": (0, 1, 2)}


def _index_expression(value, known) -> bool:
    """Whether a comp selector ``value`` is an index expression (``selector_parts``): an expression other
    than a number, or a name that is neither a selector word nor a typo of one of ``known``."""
    if isinstance(value, ir.Num):
        return False
    if not isinstance(value, ir.Name):
        return True
    name = value.name
    words = {w for selectors in COMP_SELECTORS.values() for w in selectors} | SETBACK_SELECTORS
    return name not in words and "." not in name and typo_of(name, known) is None


def _selector(arg) -> str | None:
    """A selector argument's name (CityEngine also takes a selector as a string: ``"zUp"``), else None."""
    if isinstance(arg, ir.Name):
        return arg.name
    return arg.value if isinstance(arg, ir.Str) else None


@cache
def _operation_typos() -> Typos:
    """The operations, sorted (a frozenset's order changes between processes), indexed for typos once a
    file calls a rule that does not exist."""
    return Typos(sorted(ALL_OPERATIONS))


def check_calls(rules: list[ir.Rule], imported, diags: Diagnostics) -> list[ir.Rule]:
    """``rules`` (a file's own) with their misspelt operations reported and dropped.

    A call ``name(args)`` that names neither an operation, nor one of the rules, nor a rule of the
    ``imported`` modules (those imported without a prefix merge theirs; a prefixed call ``p.Rule(...)`` is
    not looked at) is a rule call in CityEngine, of a missing rule: a leaf. When the name is a typo of an
    operation (``spilt(x)``), that is what was meant: an error ``unknown operation`` with the suggestion.
    Other names stay calls of a missing rule, which the types pass warns about; so do capitalised ones
    (``Envelope(h)``): operations are lower-case, rules are mostly named in capitals.
    """
    defined = {r.symbol for r in rules} | {r.symbol for module in imported for r in module.rules}

    def check(op):
        if isinstance(op, ir.Symbol) and op.args and not op.leaf and op.name not in defined \
                and "." not in op.name and not op.name[0].isupper():
            close = _operation_typos().of(op.name)
            if close is not None:
                diags.error("unknown-op", f"unknown operation `{op.name}` (did you mean `{close}`?)",
                            op.span)
                return ir.Empty(op.span)
        return op

    return [replace(rule, alternatives=tuple(replace(alt, body=rewrite_ops(alt.body, check))
                                             for alt in rule.alternatives)) for rule in rules]
