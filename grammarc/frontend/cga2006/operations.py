"""The operations of the paper notation lowered to IR operations: scope rules (``T``, ``S``, ``R``), inserts
(``I``), splits (``Subdiv``, ``Repeat``, ``Comp``, ``Cut``), roofs and snap planes. ``OperationLowering`` is the
mixin of ``lowering.Lowering`` with a handler per operation that needs one; ``OPERATIONS`` and
``PART_OPERATIONS`` (calls with a body ``{ A | B }``) map names to handlers, or to ``direct`` where the
arguments are the IR node's fields.
"""

from __future__ import annotations

from grammarc.diagnostics import suggest
from grammarc.frontend.cga2006.nodes import Relative
from grammarc.frontend.direct import direct
from grammarc.ir import nodes as ir

#: Split axes of Subdiv and Repeat (paper section 2, "Basic split rule").
AXES = {
    "X": (0,), "Y": (1,), "Z": (2,),
    "XY": (0, 1), "XZ": (0, 2), "YZ": (1, 2), "XYZ": (0, 1, 2),
}
#: Snap split axes (paper section 3.3): the axis with ``S`` snaps to the lot's snap planes.
SNAP_AXES = {"XS": (0,), "YS": (1,), "ZS": (2,)}
#: The scope axis across a snap shape's plane, by the axes the paper names (``Snap("XZ")``: the floor
#: plane, across y; ``Snap("Y")``: the vertical line of a facade, a plane through it and the facade's
#: normal z, so across x).
SNAP_NORMALS = {"XZ": 1, "ZX": 1, "XY": 2, "YX": 2, "YZ": 0, "ZY": 0, "X": 1, "Y": 0, "Z": 0}

#: The paper's roof types (section 3.1) and the roofs that build them: a cross gable is the gable roof of
#: a cross-shaped footprint, a cone the pyramid of a many-sided one; mansard and gambrel are the hip and
#: the gable roof with two slopes (``geometry.roofs``).
ROOF_TYPES = {"hipped": "roofHip", "gabled": "roofGable", "cross-gable": "roofGable", "cone": "roofPyramid",
              "pyramid": "roofPyramid", "shed": "roofShed", "mansard": "mansard", "gambrel": "gambrel"}


class OperationLowering:
    """The operation handlers of ``Lowering`` (which provides ``expr``, ``arity``, ``diags``, ``site``...)."""

    def expect_no_parts(self, op, parts, span) -> None:
        if parts is not None:
            self.diags.error("syntax", f"`{op}` takes no `{{...}}` body", span)

    def expect_parts(self, op, parts, span) -> tuple:
        if parts is None:
            self.diags.error("syntax", f"`{op}` needs a body `{{ A | B | ... }}`", span)
            return ((),)
        return parts

    def size(self, arg) -> ir.Size:
        if isinstance(arg, Relative):
            return ir.Size(ir.SizeKind.RELATIVE, arg.value, arg.span)
        return ir.Size(ir.SizeKind.ABSOLUTE, arg, getattr(arg, "span", self.fallback))

    def string_arg(self, op, arg, span, what) -> str | None:
        if isinstance(arg, ir.Str):
            return arg.value
        self.diags.error("type", f"`{op}` expects {what} as a string literal", getattr(arg, "span", span))
        return None

    def axes(self, op, arg, span) -> tuple[tuple[int, ...], bool] | None:
        """A split's axes and whether it snaps (``"XS"``), or None after an error."""
        text = self.string_arg(op, arg, span, "an axis")
        if text is None:
            return None
        if text in SNAP_AXES:
            return SNAP_AXES[text], True
        if text not in AXES:
            known = [*AXES, *SNAP_AXES]
            self.diags.error(
                "axis", f"unknown split axis \"{text}\", expected one of {', '.join(known)}", arg.span
            )
            return None
        return AXES[text], False

    def split_arguments(self, op, args, span, takes: str):
        """A split's axes, whether it snaps (``"XS"``), its sizes and its snap label (the trailing string of
        ``Subdiv("XS", ..., "tilesnap")``), or None after an error; ``takes`` says what it takes after
        the axis."""
        if len(args) < 2:
            self.diags.error("arity", f"`{op}` takes an axis and {takes}, "
                             f"got {_count(len(args), 'argument')}", span)
            return None
        chosen = self.axes(op, args[0], span)
        if chosen is None:
            return None
        axes, snap = chosen
        rest = args[1:]
        if snap and isinstance(rest[-1], ir.Str):
            return axes, snap, rest[:-1], rest[-1].value
        return axes, snap, rest, None

    # ------------------------------------------------------------------------------- calls without parts
    def op_scale(self, op, args, span):
        if not self.arity(op, args, (3,), span):
            return ir.Empty(span)
        return ir.Scale(tuple(self.size(a) for a in args), span)

    def op_rotate_axis(self, op, args, span):
        """``Rx(a)``, ``Ry(a)``, ``Rz(a)``: a rotation about one axis."""
        if not self.arity(op, args, (1,), span):
            return ir.Empty(span)
        zero = ir.Num(0.0, span)
        angles = [zero, zero, zero]
        angles["xyz".index(op[1])] = self.expr(args[0])
        return ir.Rotate(tuple(angles), span)

    def op_insert(self, op, args, span):
        if not self.arity(op, args, (1,), span):
            return ir.Empty(span)
        name = self.string_arg(op, args[0], span, "an asset name")
        return ir.Insert(name, span) if name is not None else ir.Empty(span)

    def op_snap(self, op, args, span):
        """``Snap(axes[, label])`` and ``SnapLines(axes[, label])``: construction planes (``ir.Snap``)."""
        if not self.arity(op, args, (1, 2), span):
            return ir.Empty(span)
        text = self.string_arg(op, args[0], span, "the axes of its plane")
        label = self.string_arg(op, args[1], span, "a label") if len(args) == 2 else None
        if text is None or (len(args) == 2 and label is None):
            return ir.Empty(span)
        if text not in SNAP_NORMALS:
            self.diags.error("axis", f"unknown snap axes \"{text}\", expected one of "
                             f"{', '.join(SNAP_NORMALS)}", args[0].span)
            return ir.Empty(span)
        return ir.Snap(SNAP_NORMALS[text], label, op == "SnapLines", span)

    # ---------------------------------------------------------------------------------- calls with parts
    def op_subdiv(self, op, args, parts, span):
        parts = self.expect_parts(op, parts, span)
        split = self.split_arguments(op, args, span, "at least one size")
        if split is None:
            return ir.Empty(span)
        axes, snap, rest, label = split
        sizes = tuple(self.size(a) for a in rest)
        cells = len(sizes) ** len(axes)
        if len(parts) != cells and not (len(axes) > 1 and len(parts) == 1):
            self.diags.error(
                "parts",
                f"`{op}` has {cells} {'parts' if len(axes) == 1 else 'cells'} but {len(parts)} "
                f"successor{'s' if len(parts) != 1 else ''} in its body",
                span,
                hint="give one successor per size, separated by `|` (use ε for an empty part)",
            )
        return ir.Split(axes, sizes, parts, span, self.site(), snap, label)

    def op_repeat(self, op, args, parts, span):
        parts = self.expect_parts(op, parts, span)
        split = self.split_arguments(op, args, span, "a size per axis")
        if split is None:
            return ir.Empty(span)
        axes, snap, rest, label = split
        if len(rest) != len(axes):
            self.diags.error("arity", f"`{op}(\"{args[0].value!s}\", ...)` takes {len(axes)} "
                             f"size{'s' if len(axes) > 1 else ''}, got {len(rest)}", span)
            return ir.Empty(span)
        return ir.Repeat(axes, tuple(self.expr(a) for a in rest), parts, span, self.site(), snap, label)

    def op_comp(self, op, args, parts, span):
        parts = self.expect_parts(op, parts, span)
        if not args:
            self.diags.error("arity", f"`{op}` takes a component type, got no arguments", span)
            return ir.Empty(span)
        kind = self.string_arg(op, args[0], span, "a component type")
        if kind is None:
            return ir.Empty(span)
        if kind not in ir.COMP_KINDS:
            self.diags.error("comp", f"unknown component type \"{kind}\"{suggest(kind, ir.COMP_KINDS)}",
                             args[0].span)
            return ir.Empty(span)
        want = (2,) if kind in ir.COMP_INDEXED else (1,)
        if not self.arity(f"{op}(\"{kind}\")", args, want, span):
            return ir.Empty(span)
        index = self.expr(args[1]) if len(args) == 2 else None
        return ir.Comp(kind, index, parts, span, self.site())

    def op_cut(self, op, args, parts, span):
        """``Cut(e1, t1, e2, t2){ A | B }``: a polygon divided by a line between two of its edges."""
        parts = self.expect_parts(op, parts, span)
        if not self.arity(op, args, (4,), span):
            return ir.Empty(span)
        if len(parts) != 2:
            self.diags.error("arity", f"`{op}` makes two pieces: its body has two parts `{{ A | B }}`, "
                             f"got {len(parts)}", span)
            return ir.Empty(span)
        e1, t1, e2, t2 = (self.expr(a) for a in args)
        return ir.Cut((e1, e2), (t1, t2), parts, span, self.site())

    def op_roof(self, op, args, parts, span):
        """``Roof(type, angle){ part }`` (paper section 3.1): a roof over the scope's footprint, its
        part applied to the roof. Lowered to the roof, then the part's operations; the part is optional."""
        if not self.arity(op, args, (2,), span):
            return ir.Empty(span)
        kind = self.string_arg(op, args[0], span, "a roof type")
        if kind is None:
            return ir.Empty(span)
        if kind not in ROOF_TYPES:
            self.diags.error("roof", f'unknown roof type "{kind}"{suggest(kind, ROOF_TYPES)}', args[0].span)
            return ir.Empty(span)
        if parts is not None and len(parts) != 1:
            self.diags.error("syntax", f"`{op}` takes one part, got {len(parts)}", span)
            return ir.Empty(span)
        zero = ir.Num(0.0, span)
        roof = ir.Roof(ROOF_TYPES[kind], self.expr(args[1]), False, zero, None, zero, span)
        return (roof, *(parts[0] if parts is not None else ()))


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


#: Operations called without a body: name -> handler(lowering, op, args, span). The lowering reports a
#: body ``{...}`` after one of them before calling its handler.
OPERATIONS = {
    "T": direct(ir.Translate),
    "S": OperationLowering.op_scale,
    "R": direct(ir.Rotate),
    "Rx": OperationLowering.op_rotate_axis,
    "Ry": OperationLowering.op_rotate_axis,
    "Rz": OperationLowering.op_rotate_axis,
    "I": OperationLowering.op_insert,
    "Snap": OperationLowering.op_snap,
    "SnapLines": OperationLowering.op_snap,
}
#: Operations with a body ``{ A | B | ... }``: name -> handler(lowering, op, args, parts, span), ``parts``
#: None when the body is missing.
PART_OPERATIONS = {
    "Subdiv": OperationLowering.op_subdiv,
    "Repeat": OperationLowering.op_repeat,
    "Comp": OperationLowering.op_comp,
    "Roof": OperationLowering.op_roof,
    "Cut": OperationLowering.op_cut,
}
