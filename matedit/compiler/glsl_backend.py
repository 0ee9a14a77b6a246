"""The GLSL back-end: a `Schedule` to vertex and fragment text for one GLSL dialect.

It owns everything that is GLSL: type names, literal syntax, declarations (uniform block,
samplers, stage interface), the call convention (library functions and material functions
take `out` parameters), the ops table's `glsl` column, the dialects' preludes, and the library
files (`shaders/<unit>.glsl`). HLSL and MSL come from the glsl450 text through SPIR-V
(`matedit.interop.cross`), not from a back-end of their own.
"""

from __future__ import annotations

import re
from functools import cache

from matedit.compiler import ops
from matedit.compiler.ir import Expr, Lit, Op, Param, Splat, SurfaceUV, Uni, Var
from matedit.compiler.schedule import (
    Entry,
    LayerGuard,
    LocalNames,
    Schedule,
    ScopePlan,
    SourceMap,
    Writer,
)
from matedit.compiler.targets import FIRST_TEXTURE_BINDING, FRAME_BINDING, MATERIAL_BINDING, Target
from matedit.glsl import layout as _layout
from matedit.glsl.include import Assembly, assemble, derivative_prelude, packing_prelude
from matedit.graph import nodes
from matedit.graph.types import PortType

# PortType -> GLSL type name
TYPE_NAMES = {PortType.FLOAT: "float", PortType.VEC2: "vec2", PortType.VEC3: "vec3",
              PortType.VEC4: "vec4", PortType.MATERIAL: "MaterialAttributes",
              PortType.TEXTURE: "sampler2D"}


def type_name(t: PortType) -> str:
    return TYPE_NAMES[t]


def float_literal(x: float) -> str:
    s = repr(float(x))
    if "inf" in s or "nan" in s:
        raise ValueError(f"cannot write {s} as a GLSL literal")
    if "e" not in s and "." not in s:
        s += ".0"
    return s


def expr(e: Expr, names: LocalNames) -> str:
    if type(e) is Var:
        return names.taken[e.name]  # the schedule named every variable
    if isinstance(e, (Param, Uni)):
        return e.name
    if isinstance(e, SurfaceUV):
        return "g_surface.uv"
    if isinstance(e, Lit):
        if e.type == PortType.MATERIAL:
            return "defaultMaterialAttributes()"
        if e.type == PortType.FLOAT:
            return float_literal(e.value)
        return f"{TYPE_NAMES[e.type]}({', '.join(float_literal(v) for v in e.value)})"
    if isinstance(e, Splat):
        return f"{TYPE_NAMES[e.type]}({expr(e.expr, names)})"
    raise TypeError(f"cannot emit {e!r}")


_TEMPLATES: dict[tuple[str, str], tuple[str, bool]] = {}


def _format(template: str, op: Op) -> tuple[str, bool]:
    """The template as a str.format string of (operands, type name, all operands, op data), and
    whether it uses all operands; made once a kind and template. `{k}` is operand k, `{T}` the
    result type, `{args}` all operands, `{name}` an input of the catalogue kind, else op data."""
    key = (op.kind, template)
    hit = _TEMPLATES.get(key)
    if hit is None:
        d = nodes.REGISTRY.get(op.kind)
        index = {i.name: k for k, i in enumerate(d.inputs)} if d else {}
        pieces = re.split(r"\{(\w+)\}", template)
        out = []
        for k, p in enumerate(pieces):
            if k % 2 == 0:
                out.append(p.replace("{", "{{").replace("}", "}}"))
            elif p.isdigit():
                out.append(f"{{0[{p}]}}")
            elif p == "T":
                out.append("{1}")
            elif p == "args":
                out.append("{2}")
            elif p in index:
                out.append(f"{{0[{index[p]}]}}")
            else:
                out.append(f"{{3[{p}]}}")
        hit = _TEMPLATES[key] = ("".join(out), "{2}" in out)
    return hit


# op kind -> (its definition, or None; its ops row; _format of its value template, or None
# where it calls a function), kept while the kind's definition is the same object
_ROWS: dict[str, tuple] = {}


def _row(op: Op) -> tuple:
    """(definition or None, ops row, _format of its value template or None) of op's kind."""
    kind = op.kind
    d = nodes.REGISTRY.get(kind)  # a catalogue kind's GLSL is its definition's
    row = _ROWS.get(kind)
    if row is None or row[0] is not d:
        impl = ops.implementation(kind)
        template = impl.glsl if impl.glsl is not None else d.inline if d is not None else None
        row = _ROWS[kind] = (d, impl, _format(template, op) if template is not None else None)
    return row


def op_line(op: Op, outs: list[tuple[str, PortType]], names: LocalNames) -> str:
    """One op as one line: a declaration of its value, or declarations and a call that fills
    them through `out` parameters."""
    d, impl, formatted = _row(op)
    taken = names.taken
    args = [taken[a.name] if type(a) is Var else expr(a, names) for a in op.args]
    if formatted is not None:
        (name, t), = outs
        fmt, joined = formatted
        type_name = TYPE_NAMES[t]
        value = fmt.format(args, type_name, ", ".join(args) if joined else "", op.data)
        line = f"{type_name} {name} = {value};"
        if impl.assigns:
            sets = " ".join(f"{name}.{f} = {a};" for f, a in zip(op.data[impl.assigns], args[1:]))
            line += " " + sets
        return line
    decls = " ".join(f"{TYPE_NAMES[t]} {n};" for n, t in outs)
    return f"{decls} {_call_text(d, op, args, outs)}"


def _call_text(d, op: Op, args: list[str], outs: list[tuple[str, PortType]]) -> str:
    """The call that fills an op's outputs through `out` parameters: the catalogue kind's
    GLSL function, or the material function the op names."""
    fn = d.glsl if d is not None else op.data.get("function")
    return f"{fn}({', '.join(args + [n for n, _ in outs])});"


def _guarded_line(op: Op, outs: list[tuple[str, PortType]], names: LocalNames,
                  guard: LayerGuard) -> str:
    """A layer's call evaluated only where its weight shows in the quad (schedule.
    hidden_layer_guards): its outputs start as the default attributes or zeros."""
    d, _, _ = _row(op)
    taken = names.taken
    args = [taken[a.name] if type(a) is Var else expr(a, names) for a in op.args]
    decls = " ".join(
        f"{TYPE_NAMES[t]} {n} = "
        f"{'defaultMaterialAttributes()' if t == PortType.MATERIAL else TYPE_NAMES[t] + '(0.0)'};"
        for n, t in outs)
    call = _call_text(d, op, args, outs)
    ws = [taken[a.name] if type(a) is Var else expr(a, names) for a in guard.args]
    weight = ws[0] if guard.function is None else f"{guard.function}({', '.join(ws)})"
    return f"    {decls} if (layerShows({weight})) {{ {call} }}"


def _scope(w: Writer, plan: ScopePlan) -> None:
    scope, names = plan.scope, plan.names
    if plan.main:
        w.add("MaterialAttributes evaluateMaterial() {")
    else:
        params = [f"{TYPE_NAMES[t]} {n}" for n, t in scope.params]
        params += [f"out {TYPE_NAMES[t]} out_{n}" for n, t, _ in scope.outputs]
        w.add(f"void {scope.name}({', '.join(params)}) {{")
        w.add(f"    // material function {scope.name}")
    lines, line_nodes, source = w.lines, w.map, scope.source
    taken = names.taken
    plain: dict[str, tuple | None] = {}  # kind -> (format, joined) where op_line is one format
    for op, outs in plan.steps:
        kind = op.kind
        if kind in plain:
            fast = plain[kind]
        else:
            _, impl, formatted = _row(op)
            fast = plain[kind] = formatted if not impl.assigns else None
        if fast is not None and len(outs) == 1:
            # op_line of a value template, inlined (most ops of a large graph)
            args = [taken[a.name] if type(a) is Var else expr(a, names) for a in op.args]
            (name, t), = outs
            fmt, joined = fast
            type_name = TYPE_NAMES[t]
            value = fmt.format(args, type_name, ", ".join(args) if joined else "", op.data)
            text = f"    {type_name} {name} = {value};"
        elif id(op) in plan.guards:
            text = _guarded_line(op, outs, names, plan.guards[id(op)])
        else:
            text = "    " + op_line(op, outs, names)
        if "\n" in text:
            w.add(text, op.node, source)
        else:  # w.add of one line
            lines.append(text)
            line_nodes[len(lines)] = (op.node, source)
    if plan.main:
        w.add(f"    return {expr(scope.outputs[0][2], names)};" if scope.outputs
              else "    return defaultMaterialAttributes();")
    else:
        for n, _, e in scope.outputs:
            w.add(f"    out_{n} = {expr(e, names)};")
    w.add("}")


# --- the dialects -----------------------------------------------------------------------------
def prelude(target: Target) -> str:
    """What follows `#version`: ES precisions, and the binding macros (Vulkan: set 0)."""
    lines = []
    if target.es:
        lines += ["precision highp float;", "precision highp int;",
                  "precision highp sampler2D;", "precision highp samplerCube;"]
    if target.vulkan:
        lines += [
                  "#define MATEDIT_UBO(n) layout(std140, set = 0, binding = n)",
                  "#define MATEDIT_BINDING(n) layout(set = 0, binding = n)"]
    else:
        lines += ["#define MATEDIT_UBO(n) layout(std140)", "#define MATEDIT_BINDING(n)"]
    return "\n".join(lines)


def varying(target: Target, direction: str, location: int, decl: str) -> str:
    """An interface variable between stages; Vulkan needs explicit locations."""
    if target.vulkan:
        return f"layout(location = {location}) {direction} {decl};"
    return f"{direction} {decl};"


# The FrameBlock declaration, a str.format template of {binding} (matedit/glsl/layout.py)
FRAME_BLOCK = (_layout.FRAME_BLOCK.declaration("@B@").replace("{", "{{").replace("}", "}}")
               .replace("@B@", "{binding}"))

_VARYINGS = ["vec3 v_position", "vec3 v_normal", "vec4 v_tangent", "vec2 v_uv"]


def vertex_source(target: Target) -> Assembly:
    body = "\n".join([
        FRAME_BLOCK.format(binding=FRAME_BINDING),
        "layout(location = 0) in vec3 a_position;",
        "layout(location = 1) in vec3 a_normal;",
        "layout(location = 2) in vec4 a_tangent;",
        "layout(location = 3) in vec2 a_uv;",
        *(varying(target, "out", i, d) for i, d in enumerate(_VARYINGS)),
        "void main() {",
        "    vec4 world = uFrame.model * vec4(a_position, 1.0);",
        "    v_position = world.xyz;",
        "    v_normal = mat3(uFrame.normalMatrix) * a_normal;",
        "    v_tangent = vec4(mat3(uFrame.model) * a_tangent.xyz, a_tangent.w);",
        "    v_uv = a_uv;",
        "    gl_Position = uFrame.viewProjection * world;",
        "}",
    ])
    return assemble(body, target.version, [], "<vertex>", prelude=prelude(target))


@cache
def _define_line(define: str) -> str:
    """`NAME 1` for a bare name, `NAME value` for NAME=value (schedule checked the form)."""
    name, _, value = define.partition("=")
    return f"{name} {value or 1}"


# Preview- and bake-only blocks of an entry file (the viewport's attribute views, the bake on
# a mesh's view along the normal), `#ifdef NAME ... #else ... #endif` (no nesting):
# emitted only when the caller defines NAME, so the default program text is the same as if
# the block were not there (the exported shader and its structure hash do not change).
PREVIEW_BLOCKS = ("MATEDIT_ATTRIBUTE_VIEW", "MATEDIT_BAKE_VIEW_NORMAL")


def _strip_preview_blocks(lines: list[str], defines: tuple[str, ...]) -> list[str]:
    names = {d.partition("=")[0] for d in defines}
    out: list[str] = []
    state = None  # None outside a block; "if" / "else" inside one that is not defined
    for line in lines:
        word = line.strip().split()
        if state is None and word[:1] == ["#ifdef"] and len(word) == 2 and \
                word[1] in PREVIEW_BLOCKS and word[1] not in names:
            state = "if"
        elif state is not None and word[:1] == ["#else"]:
            state = "else"
        elif state is not None and word[:1] == ["#endif"]:
            state = None
        elif state != "if":
            out.append(line)
    return out


# (entry file, defines) -> (mtime_ns, size, text): an entry file is read again only once
# edited, as the library files are (matedit.glsl.include)
_ENTRY_TEXTS: dict[tuple[str, tuple[str, ...]], tuple[int, int, str]] = {}


def entry_text(entry: Entry, defines: tuple[str, ...] = ()) -> str:
    """The entry file's `main`, without its leading comment lines (the file's documentation)
    and without the preview blocks the caller's `defines` do not ask for."""
    from matedit.resources import shaders_dir

    path = shaders_dir() / "entry" / f"{entry.value}.frag.glsl"
    st = path.stat()
    key = (str(path), tuple(defines))
    hit = _ENTRY_TEXTS.get(key)
    if hit is not None and hit[0] == st.st_mtime_ns and hit[1] == st.st_size:
        return hit[2]
    lines = path.read_text().split("\n")
    while lines and lines[0].startswith("//"):
        lines.pop(0)
    text = "\n".join(_strip_preview_blocks(lines, tuple(defines))).rstrip("\n")
    _ENTRY_TEXTS[key] = (st.st_mtime_ns, st.st_size, text)
    return text


# The GLSL type of an entry's output variable that is not a vec4 (the G-buffer's packed
# targets: matedit/render/deferred.py).
ENTRY_OUTPUT_TYPES = {"gbuffer0": "uvec4", "gbuffer1": "uvec4", "gbuffer2": "vec2"}


def fragment_source(plan: Schedule, target: Target) -> tuple[Assembly, SourceMap]:
    ir = plan.ir
    w = Writer()
    w.add(FRAME_BLOCK.format(binding=FRAME_BINDING))
    if ir.uniforms:
        w.add(f"MATEDIT_UBO({MATERIAL_BINDING}) uniform MaterialParams {{")
        for u in ir.uniforms:
            w.add(f"    {TYPE_NAMES[u.type]} {u.name};", u.node, ir.main.source)
        w.add("};")
    for i, t in enumerate(ir.textures):
        w.add(f"MATEDIT_BINDING({FIRST_TEXTURE_BINDING + i}) uniform "
              f"{TYPE_NAMES[PortType.TEXTURE]} {t.name};", t.node, ir.main.source)
    for i, decl in enumerate(_VARYINGS):
        w.add(varying(target, "in", i, decl))
    for i, name in enumerate(plan.outputs):
        w.add(f"layout(location = {i}) out {ENTRY_OUTPUT_TYPES.get(name, 'vec4')} {name};")
    for scope in plan.scopes:
        _scope(w, scope)
    w.add(entry_text(plan.entry, tuple(plan.extra_defines)))
    includes = [f"{unit}.glsl" for unit in plan.units]
    lines = "\n".join(f"#define {d} 1" for d in plan.defines)
    lines += "".join(f"\n#define {_define_line(d)}" for d in plan.extra_defines)
    head = prelude(target)
    if "gbuffer" in plan.units:  # shaders/gbuffer.glsl packs halves: the extension at 330
        head = "\n".join(x for x in (packing_prelude(target.version), head) if x)
    if "layer_guard" in plan.units:  # fine derivatives: the extension at 330, where offered
        head = "\n".join(x for x in (derivative_prelude(target.version), head) if x)
    asm = assemble("\n".join(w.lines), target.version, includes, "<material>",
                   prelude=head + "\n" + lines)
    return asm, SourceMap(w.map, len(asm.sources) - 1)
