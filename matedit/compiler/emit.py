"""GLSL emission: the optimised IR to vertex and fragment text for one target.

The fragment stage includes the shading library (`surface.glsl`); the generated
code fills a MaterialAttributes in `evaluateMaterial()` and never sees lights.
Every generated line records the node it came from (`SourceMap`), so a GL
compile error is reported on the node.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from enum import Enum
from functools import cache

from matedit.compiler.ir import Expr, Lit, MaterialIR, Op, Param, Scope, Splat, SurfaceUV, Uni, Var
from matedit.compiler.targets import FIRST_TEXTURE_BINDING, FRAME_BINDING, MATERIAL_BINDING, Target
from matedit.glsl import layout as _layout
from matedit.glsl.include import Assembly, assemble
from matedit.graph import nodes
from matedit.graph.types import PortType


def float_literal(x: float) -> str:
    s = repr(float(x))
    if "inf" in s or "nan" in s:
        raise ValueError(f"cannot write {s} as a GLSL literal")
    if "e" not in s and "." not in s:
        s += ".0"
    return s


@dataclass
class SourceMap:
    """Line numbers of the generated source string -> (node id, file of that node)."""

    lines: dict[int, tuple[str, str]] = field(default_factory=dict)
    source_number: int = -1  # the generated text's source-string number in the assembly

    def node_at(self, source: int, line: int) -> tuple[str, str] | None:
        if source != self.source_number:
            return None
        return self.lines.get(line)


class _Writer:
    def __init__(self) -> None:
        self.lines: list[str] = []
        self.map: dict[int, tuple[str, str]] = {}

    def add(self, text: str, node: str | None = None, file: str = "") -> None:
        for line in text.split("\n"):
            self.lines.append(line)
            if node is not None:
                self.map[len(self.lines)] = (node, file)


class _Names:
    """Local variable names: `l_<node>_<port>` (IR names are `node.port`), in a name space of
    their own (no uniform, parameter, function or library name starts with `l_`), made unique
    within the function deterministically."""

    def __init__(self) -> None:
        self.taken: dict[str, str] = {}
        self.used: set[str] = set()

    def __call__(self, raw: str) -> str:
        if raw in self.taken:
            return self.taken[raw]
        name = "l_" + re.sub(r"_+", "_", raw.replace(".", "_"))
        base, i = name, 2
        while name in self.used:
            name, i = f"{base}_{i}", i + 1
        self.used.add(name)
        self.taken[raw] = name
        return name


def _expr(e: Expr, names: _Names) -> str:
    if isinstance(e, Var):
        return names(e.name)
    if isinstance(e, Param):
        return e.name
    if isinstance(e, Uni):
        return e.name
    if isinstance(e, SurfaceUV):
        return "g_surface.uv"
    if isinstance(e, Lit):
        if e.type == PortType.MATERIAL:
            return "defaultMaterialAttributes()"
        if e.type == PortType.FLOAT:
            return float_literal(e.value)
        return f"{e.type.glsl}({', '.join(float_literal(v) for v in e.value)})"
    if isinstance(e, Splat):
        return f"{e.type.glsl}({_expr(e.expr, names)})"
    raise TypeError(f"cannot emit {e!r}")


_TEMPLATES: dict[tuple[str, str], list] = {}


def _inline(template: str, op: Op, args: list[str]) -> str:
    """The template with `{input}` replaced by argument expressions (parsed once a kind)."""
    key = (op.kind, template)
    parts = _TEMPLATES.get(key)
    if parts is None:
        index = {i.name: k for k, i in enumerate(nodes.REGISTRY[op.kind].inputs)}
        pieces = re.split(r"\{(\w+)\}", template)
        parts = [p if k % 2 == 0 else index[p] for k, p in enumerate(pieces)]
        _TEMPLATES[key] = parts
    return "".join(p if isinstance(p, str) else args[p] for p in parts)


def _op_line(op: Op, names: _Names) -> str:
    args = [_expr(a, names) for a in op.args]
    outs = [(names(op.out(p).name), t) for p, t in op.outs]
    k = op.kind
    if k == "mask":
        (name, t), = outs
        return f"{t.glsl} {name} = ({args[0]}).{op.data['channels']};"
    role = nodes.role_of(k)
    if role == nodes.Role.APPEND:
        (name, t), = outs
        return f"{t.glsl} {name} = {t.glsl}({', '.join(args)});"
    if role == nodes.Role.SET_ATTRIBUTES:
        (name, _), = outs
        sets = " ".join(f"{name}.{f} = {a};" for f, a in zip(op.data["fields"], args[1:]))
        return f"MaterialAttributes {name} = {args[0]}; {sets}"
    if k == "weight":
        (name, _), = outs
        return f"float {name} = clamp({args[0]} * {args[1]}, 0.0, 1.0);"
    if k == "blend":
        (name, _), = outs
        return f"MaterialAttributes {name} = blendMaterialAttributes({', '.join(args)});"
    if "inline" in op.data and op.data["inline"] is not None:
        (name, t), = outs
        return f"{t.glsl} {name} = {_inline(op.data['inline'], op, args)};"
    fn = op.data.get("glsl") or op.data.get("function")
    decls = " ".join(f"{t.glsl} {n};" for n, t in outs)
    return f"{decls} {fn}({', '.join(args + [n for n, _ in outs])});"


def _scope(w: _Writer, scope: Scope, main: bool) -> None:
    names = _Names()
    for p, _ in scope.params:
        names.used.add(p)
    if main:
        w.add("MaterialAttributes evaluateMaterial() {")
    else:
        params = [f"{t.glsl} {n}" for n, t in scope.params]
        params += [f"out {t.glsl} out_{n}" for n, t, _ in scope.outputs]
        w.add(f"void {scope.name}({', '.join(params)}) {{")
        w.add(f"    // material function {scope.name}")
    for op in scope.ops:
        w.add("    " + _op_line(op, names), op.node, scope.source)
    if main:
        w.add(f"    return {_expr(scope.outputs[0][2], names)};" if scope.outputs
              else "    return defaultMaterialAttributes();")
    else:
        for n, _, e in scope.outputs:
            w.add(f"    out_{n} = {_expr(e, names)};")
    w.add("}")


_STD140 = {PortType.FLOAT: (4, 4), PortType.VEC2: (8, 8), PortType.VEC3: (16, 12),
           PortType.VEC4: (16, 16)}


def std140_layout(ir: MaterialIR) -> tuple[dict[str, int], int]:
    """Byte offsets of the MaterialParams members (in name order) and the block size."""
    offsets, off = {}, 0
    for u in ir.uniforms:
        align, size = _STD140[u.type]
        off = (off + align - 1) // align * align
        offsets[u.name] = off
        off += size
    return offsets, (off + 15) // 16 * 16


# The FrameBlock declaration, a str.format template of {binding} (matedit/glsl/layout.py)
FRAME_BLOCK = (_layout.FRAME_BLOCK.declaration("@B@").replace("{", "{{").replace("}", "}}")
               .replace("@B@", "{binding}"))


def vertex_source(target: Target) -> Assembly:
    body = "\n".join([
        FRAME_BLOCK.format(binding=FRAME_BINDING),
        "layout(location = 0) in vec3 a_position;",
        "layout(location = 1) in vec3 a_normal;",
        "layout(location = 2) in vec4 a_tangent;",
        "layout(location = 3) in vec2 a_uv;",
        target.varying("out", 0, "vec3 v_position"),
        target.varying("out", 1, "vec3 v_normal"),
        target.varying("out", 2, "vec4 v_tangent"),
        target.varying("out", 3, "vec2 v_uv"),
        "void main() {",
        "    vec4 world = uFrame.model * vec4(a_position, 1.0);",
        "    v_position = world.xyz;",
        "    v_normal = mat3(uFrame.normalMatrix) * a_normal;",
        "    v_tangent = vec4(mat3(uFrame.model) * a_tangent.xyz, a_tangent.w);",
        "    v_uv = a_uv;",
        "    gl_Position = uFrame.viewProjection * world;",
        "}",
    ])
    return assemble(body, target.version, [], "<vertex>", prelude=target.prelude())


class Entry(Enum):
    """The fragment entry points; each is a GLSL file `shaders/entry/<value>.frag.glsl`.

    FORWARD: attributes and `shadeSurface` in one shader (what `compile` exports).
    GBUFFER: the attributes and the world-space shading normal into four float targets, for the
    preview's deferred lighting pass (shaders/render/lighting.frag).
    ATTRIBUTES: the raw MaterialAttributes into four float targets (tests, `bake`).
    """

    FORWARD = "forward"
    GBUFFER = "gbuffer"
    ATTRIBUTES = "attributes"

    @classmethod
    def of(cls, mode: str | Entry) -> Entry:
        """An Entry from itself or an older mode name ("shade" is FORWARD)."""
        if isinstance(mode, Entry):
            return mode
        return {"shade": cls.FORWARD}.get(mode) or cls(mode)


# Output variables of each entry (location order); the entry file writes them.
ENTRY_OUTPUTS = {
    Entry.FORWARD: ("fragColor",),
    Entry.GBUFFER: ("gbuffer0", "gbuffer1", "gbuffer2", "gbuffer3"),
    Entry.ATTRIBUTES: ("out0", "out1", "out2", "out3"),
}
# Library files an entry needs beyond the material's own.
ENTRY_INCLUDES = {Entry.FORWARD: ("surface.glsl",), Entry.GBUFFER: (), Entry.ATTRIBUTES: ()}


@cache
def entry_text(entry: Entry) -> str:
    """The entry file's `main`, without its leading comment lines (the file's documentation)."""
    from matedit.resources import shaders_dir

    lines = (shaders_dir() / "entry" / f"{entry.value}.frag.glsl").read_text().split("\n")
    while lines and lines[0].startswith("//"):
        lines.pop(0)
    return "\n".join(lines).rstrip("\n")


def __getattr__(name: str) -> str:
    # Older names of the entries' text (benchmarks import SHADE_MAIN)
    if name == "SHADE_MAIN":
        return entry_text(Entry.FORWARD)
    if name == "ATTRIBUTES_MAIN":
        return entry_text(Entry.ATTRIBUTES)
    raise AttributeError(name)


_DEFINE = re.compile(r"MATEDIT_[A-Z0-9_]+")


def has_defines(ir: MaterialIR) -> list[str]:
    """`MATERIAL_HAS_BASE_COLOR` and friends, for the attributes the graph writes."""
    return ["MATERIAL_HAS_" + re.sub(r"(?<!^)([A-Z])", r"_\1", f).upper() for f in ir.attributes]


def fragment_source(ir: MaterialIR, target: Target, mode: str | Entry = Entry.FORWARD,
                    defines: tuple[str, ...] | list[str] = ()) -> tuple[Assembly, SourceMap]:
    """The fragment stage of one entry; `defines` are extra `#define NAME 1` lines after the
    material's own (the preview's MATEDIT_SPLIT_SUM_ONLY, MATEDIT_ENERGY_COMPENSATION)."""
    entry = Entry.of(mode)
    for d in defines:
        if not _DEFINE.fullmatch(d):
            raise ValueError(f"not a define name: {d!r}")
    w = _Writer()
    w.add(FRAME_BLOCK.format(binding=FRAME_BINDING))
    if ir.uniforms:
        w.add(f"MATEDIT_UBO({MATERIAL_BINDING}) uniform MaterialParams {{")
        for u in ir.uniforms:
            w.add(f"    {u.type.glsl} {u.name};", u.node, ir.main.source)
        w.add("};")
    for i, t in enumerate(ir.textures):
        w.add(f"MATEDIT_BINDING({FIRST_TEXTURE_BINDING + i}) uniform sampler2D {t.name};",
              t.node, ir.main.source)
    for i, decl in enumerate(["vec3 v_position", "vec3 v_normal", "vec4 v_tangent", "vec2 v_uv"]):
        w.add(target.varying("in", i, decl))
    for i, name in enumerate(ENTRY_OUTPUTS[entry]):
        w.add(f"layout(location = {i}) out vec4 {name};")
    for scope in ir.functions:
        _scope(w, scope, main=False)
    _scope(w, ir.main, main=True)
    w.add(entry_text(entry))
    includes = ["common.glsl", "material.glsl", "nodes/context.glsl"]
    kinds = set(ir.node_kinds)
    if any(op.kind == "blend" for s in [ir.main, *ir.functions] for op in s.ops):
        kinds.add(nodes.kind_for(nodes.Role.MASK_BLEND))
    for kind in sorted(kinds):
        if nodes.REGISTRY[kind].glsl:
            includes.append(f"nodes/{kind}.glsl")
    includes += ENTRY_INCLUDES[entry]
    lines = "\n".join(f"#define {d} 1" for d in has_defines(ir) + list(ir.defines))
    for d in defines:
        if d not in ir.defines:
            lines += f"\n#define {d} 1"
    asm = assemble("\n".join(w.lines), target.version, includes, "<material>",
                   prelude=target.prelude() + "\n" + lines)
    smap = SourceMap(w.map, len(asm.sources) - 1)
    return asm, smap
