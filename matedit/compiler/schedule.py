"""The target-neutral half of emission: what a back-end writes, and in which order.

A `Schedule` is the optimised IR laid out for one entry point: the scopes in emission order
(material functions callees first, then the material), each op's local variable names, the
library units to include, the feature defines, the entry's outputs, and the uniform block's
layout. It holds no text of any shading language; a back-end (`glsl_backend`) turns it into
source, and records each line's node in a `SourceMap` as it writes.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from enum import Enum

from matedit.compiler import ops
from matedit.compiler.ir import Expr, Lit, MaterialIR, Op, Scope, Splat, Var, expr_vars
from matedit.glsl.layout import BINDINGS, Block, Member
from matedit.graph import nodes
from matedit.graph.types import PortType


@dataclass
class SourceMap:
    """Line numbers of the generated source string -> (node id, file of that node)."""

    lines: dict[int, tuple[str, str]] = field(default_factory=dict)
    source_number: int = -1  # the generated text's source-string number in the assembly

    def node_at(self, source: int, line: int) -> tuple[str, str] | None:
        if source != self.source_number:
            return None
        return self.lines.get(line)


class Writer:
    """Generated lines and the node each came from (the source map under construction)."""

    def __init__(self) -> None:
        self.lines: list[str] = []
        self.map: dict[int, tuple[str, str]] = {}

    def add(self, text: str, node: str | None = None, file: str = "") -> None:
        lines = self.lines
        if "\n" not in text:  # most are one line
            lines.append(text)
            if node is not None:
                self.map[len(lines)] = (node, file)
            return
        for line in text.split("\n"):
            lines.append(line)
            if node is not None:
                self.map[len(lines)] = (node, file)


_UNDERSCORES = re.compile(r"_+")


class LocalNames:
    """Local variable names: `l_<node>_<port>` (IR names are `node.port`), in a name space of
    their own (no uniform, parameter, function or library name starts with `l_`), made unique
    within the function deterministically, in the order the scope first uses them."""

    def __init__(self) -> None:
        self.taken: dict[str, str] = {}
        self.used: set[str] = set()

    def __call__(self, raw: str) -> str:
        if raw in self.taken:
            return self.taken[raw]
        stem = raw.replace(".", "_")
        if "__" in stem:
            stem = _UNDERSCORES.sub("_", stem)
        name = "l_" + stem
        base, i = name, 2
        while name in self.used:
            name, i = f"{base}_{i}", i + 1
        self.used.add(name)
        self.taken[raw] = name
        return name

    def visit(self, e: Expr) -> None:
        """Name the variable of an operand (an operand holds at most one)."""
        while type(e) is Splat:
            e = e.expr
        if type(e) is Var and e.name not in self.taken:
            self(e.name)


@dataclass
class ScopePlan:
    """One scope in emission order, its local names fixed."""

    scope: Scope
    main: bool
    names: LocalNames
    steps: list[tuple[Op, list[tuple[str, PortType]]]]  # each op, its outputs' local names
    # id(op) -> where that layer shows (`hidden_layer_guards`)
    guards: dict[int, LayerGuard] = field(default_factory=dict)

    @property
    def source(self) -> str:
        return self.scope.source


# The preview's define that asks for hidden-layer guards (`hidden_layer_guards`). Exported
# shaders never carry it: their text stays the graph's, one branch-free evaluation.
SKIP_HIDDEN_LAYERS = "MATEDIT_SKIP_HIDDEN_LAYERS"
# What every variant the viewport links carries (the renderer's programs and the compile
# worker, which warms the same GBUFFER variant off the UI thread).
PREVIEW_DEFINES = (SKIP_HIDDEN_LAYERS,)
# Blends that give their base exactly where the weight is 0, whatever finite attributes the
# layer holds: the compiler's stack blends and the catalogue's Layer Blend (mask) node, whose
# weight is their third operand; the Layer Blend (height) node, whose weight is
# heightBlendWeight of its heights and contrast (shaders/nodes/height_blend.glsl).
_WEIGHT_BLENDS = frozenset((ops.BLEND, ops.COAT, ops.FILM, nodes.kind_for(nodes.Role.MASK_BLEND)))
_HEIGHT_BLEND = nodes.kind_for(nodes.Role.HEIGHT_BLEND)
# Outputs a guarded call may have besides the one the blend reads: types with a zero value.
_GUARDABLE = frozenset((PortType.FLOAT, PortType.VEC2, PortType.VEC3, PortType.VEC4,
                        PortType.MATERIAL))


@dataclass(frozen=True)
class LayerGuard:
    """Where a guarded layer shows: `function` of `args` (the blend's operands) is its
    weight; `function` None: the single operand is the weight itself."""

    function: str | None
    args: tuple[Expr, ...]


def _blend_guard(op: Op) -> LayerGuard | None:
    if op.kind in _WEIGHT_BLENDS and len(op.args) == 3:
        weight = op.args[2]
        return None if isinstance(weight, Lit) else LayerGuard(None, (weight,))
    if op.kind == _HEIGHT_BLEND and len(op.args) == 5:
        return LayerGuard("heightBlendWeight", tuple(op.args[2:]))
    return None


def hidden_layer_guards(scope: Scope) -> tuple[list[Op], dict[int, LayerGuard]]:
    """The scope's ops in emission order, and the layer evaluations to guard by their weight.

    A layer is a material function call whose attributes only one blend reads, a blend that
    gives the stack below exactly where its weight is 0 whatever finite attributes the layer
    holds (`_WEIGHT_BLENDS`, the height blend). Such a call is moved to just before its blend
    (its operands are all defined by then), and the back end evaluates it only where the
    weight is non-zero somewhere in the pixel's 2x2 quad; elsewhere the layer holds the
    default attributes, which the blend then ignores. A rusted or mossy stack costs its upper
    layers only where they show, and derivatives inside a layer stay defined (the branch is
    uniform across each quad). Exact: no pixel changes."""
    blends = [op for op in scope.ops if op.kind in _WEIGHT_BLENDS or op.kind == _HEIGHT_BLEND]
    if not blends:  # most scopes of a large graph: nothing to count
        return scope.ops, {}
    uses: dict[str, int] = {}
    for op in scope.ops:
        for a in op.args:
            for name in expr_vars(a):
                uses[name] = uses.get(name, 0) + 1
    for _, _, e in scope.outputs:
        for name in expr_vars(e):
            uses[name] = uses.get(name, 0) + 2  # never a guarded layer's
    producer: dict[str, Op] = {}
    for op in scope.ops:
        for v in op.out_vars().values():
            producer[v.name] = op
    moved: dict[int, Op] = {}  # id(blend) -> the call emitted just before it
    guards: dict[int, LayerGuard] = {}
    for op in blends:
        guard = _blend_guard(op)
        if guard is None:
            continue
        value = op.args[1]
        if type(value) is not Var:
            continue
        call = producer.get(value.name)
        if call is None or call.kind != ops.CALL or id(call) in guards:
            continue
        if any(t not in _GUARDABLE for _, t in call.outs):
            continue
        if uses.get(value.name) != 1 or any(
                uses.get(v.name, 0) for v in call.out_vars().values() if v.name != value.name):
            continue
        guards[id(call)] = guard
        moved[id(op)] = call
    if not guards:
        return scope.ops, guards
    order: list[Op] = []
    for op in scope.ops:
        if id(op) in guards:
            continue
        call = moved.get(id(op))
        if call is not None:
            order.append(call)
        order.append(op)
    return order, guards


def plan_scope(scope: Scope, main: bool, guard_layers: bool = False) -> ScopePlan:
    names = LocalNames()
    for p, _ in scope.params:
        names.used.add(p)
    steps = []
    visit, taken, used = names.visit, names.taken, names.used
    order, guards = hidden_layer_guards(scope) if guard_layers else (scope.ops, {})
    for op in order:
        for a in op.args:
            if type(a) is Var:  # names.visit of the common operand
                if a.name not in taken:
                    names(a.name)
            else:
                visit(a)
        out_vars = op.out_vars()  # op.out of each output, at once
        outs = []
        for p, t in op.outs:
            raw = out_vars[p].name
            name = taken.get(raw)
            if name is None:
                # names(raw), inlined for a name of no "__" not yet used (the common case)
                name = "l_" + raw.replace(".", "_")
                if "__" in name or name in used:
                    name = names(raw)
                else:
                    used.add(name)
                    taken[raw] = name
            outs.append((name, t))
        steps.append((op, outs))
    for _, _, e in scope.outputs:
        names.visit(e)
    return ScopePlan(scope, main, names, steps, guards)


class Entry(Enum):
    """The fragment entry points; each back-end has one file per entry (GLSL:
    `shaders/entry/<value>.frag.glsl`).

    FORWARD: attributes and `shadeSurface` in one shader (what `compile` exports).
    GBUFFER: the attributes, the world-space shading normal and the position, packed into three
    targets (matedit/render/deferred.py), for the preview's deferred lighting pass
    (shaders/render/lighting.frag).
    ATTRIBUTES: the raw MaterialAttributes into four float targets (tests, `bake`).
    """

    FORWARD = "forward"
    GBUFFER = "gbuffer"
    ATTRIBUTES = "attributes"

    @classmethod
    def of(cls, mode: str | Entry) -> Entry:
        """An Entry from itself or its value ("forward", "gbuffer", "attributes")."""
        return mode if isinstance(mode, Entry) else cls(mode)


# Output variables of each entry (location order); the entry file writes them.
ENTRY_OUTPUTS = {
    Entry.FORWARD: ("fragColor",),
    Entry.GBUFFER: ("gbuffer0", "gbuffer1", "gbuffer2"),
    Entry.ATTRIBUTES: ("out0", "out1", "out2", "out3"),
}
# Library units every material needs, and those an entry needs beyond the material's own.
BASE_UNITS = ("common", "material", "nodes/context")
ENTRY_UNITS = {Entry.FORWARD: ("surface",), Entry.GBUFFER: ("gbuffer",), Entry.ATTRIBUTES: ()}

ATTRIBUTE_VIEW = "MATEDIT_ATTRIBUTE_VIEW"  # =<ATTRIBUTE_VIEW_*> of shaders/attribute_view.glsl
# A caller's define: a name (defined as 1), or NAME=<integer> (a view's mask or number).
_DEFINE = re.compile(r"MATEDIT_[A-Z0-9_]+(=[0-9]{1,9})?")


def has_defines(ir: MaterialIR) -> list[str]:
    """`MATERIAL_HAS_BASE_COLOR` and friends, for the attributes the graph writes."""
    return ["MATERIAL_HAS_" + re.sub(r"(?<!^)([A-Z])", r"_\1", f).upper() for f in ir.attributes]


@dataclass
class Schedule:
    ir: MaterialIR
    entry: Entry
    scopes: list[ScopePlan]  # material functions (callees first), then the material
    units: list[str]  # library units to include, in order
    defines: list[str]  # the material's feature defines, in order
    extra_defines: list[str]  # the caller's, after them
    outputs: tuple[str, ...]  # the entry's output variables, in location order


def schedule(ir: MaterialIR, mode: str | Entry = Entry.FORWARD,
             defines: tuple[str, ...] | list[str] = ()) -> Schedule:
    """The emission plan of one entry; `defines` are extra feature defines after the
    material's own (the preview's MATEDIT_SPLIT_SUM_ONLY, MATEDIT_ENERGY_COMPENSATION)."""
    entry = Entry.of(mode)
    for d in defines:
        if not _DEFINE.fullmatch(d):
            raise ValueError(f"not a define name: {d!r}")
    guard = SKIP_HIDDEN_LAYERS in defines
    scopes = [plan_scope(s, main=False, guard_layers=guard) for s in ir.functions]
    scopes.append(plan_scope(ir.main, main=True, guard_layers=guard))
    # the library file of each node kind used, and those the compiler's own ops need
    needed = {f"nodes/{k}" for k in ir.node_kinds if nodes.REGISTRY[k].glsl}
    kinds = {op.kind for s in [ir.main, *ir.functions] for op in s.ops}
    for kind in kinds:
        needed.update(ops.implementation(kind).units)
    if any(s.guards for s in scopes):
        needed.add("layer_guard")
    units = [*BASE_UNITS, *sorted(needed), *ENTRY_UNITS[entry]]
    if entry == Entry.FORWARD and any(d.partition("=")[0] == ATTRIBUTE_VIEW for d in defines):
        units.append("attribute_view")  # the viewport's attribute views (preview only)
    extra = [d for d in defines if d not in ir.defines]
    return Schedule(ir, entry, scopes, units, has_defines(ir) + list(ir.defines), extra,
                    ENTRY_OUTPUTS[entry])


def std140_layout(ir: MaterialIR) -> tuple[dict[str, int], int]:
    """Byte offsets of the MaterialParams members (in name order) and the block size, by the
    std140 rules of matedit.glsl.layout (the one implementation of them)."""
    if not ir.uniforms:
        return {}, 0
    block = Block("MaterialParams", "", BINDINGS["MATERIAL"],
                  tuple(Member(u.name, u.type.value) for u in ir.uniforms))
    return block.offsets(), block.size
