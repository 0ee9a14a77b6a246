"""What a material costs, per target, per node and per layer: the figures behind `matedit
stats` (docs/cli.md) and the canvas's cost overlay.

The fragment stage of each GLSL target goes through glslangValidator (Vulkan SPIR-V for
glsl450, OpenGL SPIR-V for glsl330 and essl300) and `spirv-opt -O`; the optimised module is
counted (`matedit.compiler.cost`). HLSL and MSL are spirv-cross translations of the glsl450
module (`matedit.interop.cross`), so their figures are that module's. Per-node figures come
from a second compile of the same text with glslang's `-gV` debug information, which
spirv-opt keeps through inlining: each instruction is charged to the outermost node of the
material whose generated line it was inlined from; what no node owns (the shading model,
lights, the entry point) is the `shading` row.
"""

from __future__ import annotations

import copy
import itertools
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from matedit.compiler.targets import CROSS_TARGETS, TARGETS

ALL_TARGETS = (*TARGETS, *CROSS_TARGETS)
SCHEMA_VERSION = 1
_TIMEOUT = 120
MAX_PERMUTATIONS = 16  # all combinations up to 4 switches; beyond, each switch on its own
ATTRIBUTION = (
    "Each instruction of the optimised SPIR-V (spirv-opt -O) is charged to the outermost "
    "material node whose generated line it was inlined from (glslang -gV debug scopes, kept "
    "by spirv-opt); code spirv-opt shares between nodes (one copy computing a value that "
    "another node also uses without being fed by the first) is split evenly between them; "
    "folded constants and dead nodes have no instructions and cost 0; code no "
    "node owns (shading model, lights, entry point) is the 'shading' row. The debug module "
    "is attributed and its shares are scaled to the release module's total.")
COUNTING = (
    "dynamic: each instruction counts as many times as it runs with the material's current "
    "values (matedit.compiler.trips): a loop whose exit is known from constants and the "
    "material's values (a node's octave count) counts once per run of its header, one whose "
    "exit needs a run-time value counts at its constant bound, one with neither counts once; "
    "a branch on a known value counts its one side, on an unknown one both. 'static' counts "
    "each instruction of the module once.")


# --- tools ----------------------------------------------------------------------------------
class ToolError(RuntimeError):
    pass


def _tool(name: str) -> str:
    from matedit.interop.cross import CrossCompileError, tool

    try:
        return tool(name)
    except CrossCompileError as exc:
        raise ToolError(str(exc)) from None


def _run(args: list[str], what: str) -> None:
    try:
        r = subprocess.run(args, capture_output=True, text=True, timeout=_TIMEOUT)
    except subprocess.TimeoutExpired:
        raise ToolError(f"{what}: {Path(args[0]).name} timed out") from None
    if r.returncode != 0:
        log = " ".join((r.stdout + r.stderr).split())[:400]
        raise ToolError(f"{what}: {Path(args[0]).name} failed: {log}")


def spirv_text(glsl: str, target: str, debug: bool, folder: Path) -> str:
    """The optimised fragment module of one GLSL target, disassembled. essl300: SPIR-V needs
    ES 3.10, so the text is compiled as `#version 310 es` (the only change)."""
    tag = f"{target}{'.g' if debug else ''}"
    src = folder / f"{tag}.frag"
    if target == "essl300":
        glsl = glsl.replace("#version 300 es", "#version 310 es", 1)
    src.write_text(glsl, encoding="utf-8")
    raw, opt = folder / f"{tag}.spv", folder / f"{tag}.opt.spv"
    args = [_tool("glslangValidator"), "-V" if TARGETS[target].vulkan else "-G"]
    if not TARGETS[target].vulkan:
        args += ["--auto-map-locations", "--auto-map-bindings"]
    if debug:
        args.append("-gV")
    _run([*args, "-S", "frag", "-o", str(raw), str(src)], f"{target} fragment to SPIR-V")
    _run([_tool("spirv-opt"), "-O", str(raw), "-o", str(opt)], f"{target} spirv-opt -O")
    dis = subprocess.run([_tool("spirv-dis"), "--raw-id", str(opt)], capture_output=True,
                         text=True, timeout=_TIMEOUT)
    if dis.returncode != 0:
        raise ToolError(f"{target}: spirv-dis failed: {dis.stderr.strip()[:300]}")
    return dis.stdout


# --- attribution ------------------------------------------------------------------------------
@dataclass
class OpRef:
    scope: str  # the GLSL function ("" for the material's evaluateMaterial)
    index: int  # the op's index in its scope
    node: str
    var: str


def op_lines(cm) -> dict[int, OpRef]:
    """Generated line number -> the op written on it, for every scope of the material (the
    back-end writes one line per op after each scope's header, `glsl_backend._scope`)."""
    text = cm.fragment_text.split("\n")
    s = cm.source_map.source_number
    from matedit.glsl.include import LINE_STRIDE

    marker = f"#line {s * LINE_STRIDE + 1} {s}"
    start = text.index(marker) + 1
    generated = text[start:]
    scopes = {f.name: f for f in cm.ir.functions}
    out: dict[int, OpRef] = {}
    for i, line in enumerate(generated):
        if line.startswith("MaterialAttributes evaluateMaterial() {"):
            name, scope, first = "", cm.ir.main, i + 2  # lines count from 1
        elif line.startswith("void ") and line[5:].split("(")[0] in scopes:
            name = line[5:].split("(")[0]
            scope, first = scopes[name], i + 3  # header, comment line
        else:
            continue
        for k, op in enumerate(scope.ops):
            n = first + k
            hit = cm.source_map.lines.get(n)
            if hit is None or hit[0] != op.node:
                raise AssertionError(f"source map and ops disagree at line {n} of {name!r}")
            out[n] = OpRef(name, k, op.node, op.var)
    return out


def _owner_fn(cm):
    """chain (innermost line first) -> the path of ops it runs through, outermost first,
    as a string key 'main-index/function:index/...'; None: no op of the material."""
    from matedit.glsl.include import LINE_STRIDE

    lines = op_lines(cm)
    s = cm.source_map.source_number

    def owner(chain: list[int]) -> str | None:
        path = []
        for line in reversed(chain):
            src, n = divmod(line, LINE_STRIDE)
            if src == s and n in lines:
                ref = lines[n]
                path.append(f"{ref.scope}:{ref.index}")
        if not path or not path[0].startswith(":"):
            return None
        return "/".join(path)

    return owner, lines


def _layer_info(doc) -> dict[str, Any]:
    """node id of the layer stack -> its layers (id, name, blend), or {}."""
    from matedit.graph.nodes import Role, role_of
    from matedit.graph.ports import layer_entries

    out = {}
    for n in doc.graph.nodes.values():
        if role_of(n.kind) == Role.LAYER_STACK:
            out[n.id] = [{"id": e["id"], "name": e.get("name") or e["id"],
                          "blend": e.get("blend", "alpha"),
                          "visible": e.get("visible", True)} for e in layer_entries(n)]
    return out


def _round(x: float) -> float:
    return round(x, 1)


def _depends(ops) -> list[set[int]]:
    """For each op of a scope, the indices of the ops it depends on, transitively."""
    from matedit.compiler.ir import Splat, Var

    by_name: dict[str, int] = {}
    for k, op in enumerate(ops):
        for port, _ in op.outs:
            by_name[op.out(port).name] = k
    deps: list[set[int]] = []
    for op in ops:
        d: set[int] = set()
        for a in op.args:
            while isinstance(a, Splat):
                a = a.expr
            if isinstance(a, Var) and a.name in by_name:
                k = by_name[a.name]
                d.add(k)
                d |= deps[k]
        deps.append(d)
    return deps


class _Share:
    """Instructions and samples (floats: shared code is split) of one owner."""

    def __init__(self) -> None:
        self.instructions = 0.0
        self.samples = 0.0

    def add(self, f: dict) -> None:
        from matedit.compiler.cost import instructions

        self.instructions += instructions(f)
        self.samples += f["samples"]


def uniform_values(cm, doc) -> dict[str, Any]:
    """The current value of each of the compiled material's scalar uniforms, by name, from the
    document (what `trips` evaluates loop exits with)."""
    from matedit.graph.types import PortType, coerce_value

    out: dict[str, Any] = {}
    for u in cm.ir.uniforms:
        node = doc.graph.nodes.get(u.node)
        value = node.values.get(u.port, u.default) if node is not None else u.default
        try:
            v = coerce_value(PortType(u.type.value), value)
        except (ValueError, TypeError):
            continue
        if isinstance(v, (int, float)):
            out[u.name] = v
    return out


def target_figures(cm, doc, release: str, debug: str) -> dict[str, Any]:
    """The figures of one GLSL target's compile (`release`, `debug`: disassembled modules)."""
    from matedit.compiler import cost, trips
    from matedit.compiler.schedule import std140_layout

    values = uniform_values(cm, doc)
    rel = cost.parse(release)
    rel_trips = trips.weights(rel.body, rel.globals, values)
    static = cost.count(rel)
    totals = cost.count(rel, rel_trips.weights)
    mod = cost.parse(debug)
    dbg_weights = trips.weights(mod.body, mod.globals, values).weights
    owner, _lines = _owner_fn(cm)
    main_ops = cm.ir.main.ops
    deps = _depends(main_ops)

    def root(key: str) -> int:
        return int(key.split("/", 1)[0][1:])

    def shared(a: str, b: str) -> bool:  # b uses a's value, and b's op is not fed by a's
        ka, kb = root(a), root(b)
        return ka != kb and ka not in deps[kb]

    shares = cost.attribute(mod, owner, shared, dbg_weights)
    attributed = sum(cost.instructions(f) for f in shares.values())
    total = totals.figures.instructions
    scale = total / attributed if attributed else 1.0
    attributed_samples = sum(f["samples"] for f in shares.values())
    sample_scale = totals.figures.samples / attributed_samples if attributed_samples else 1.0
    # per op of the material's main scope, and per (layer call op, inner node)
    per_node: dict[str, _Share] = {}
    per_op: dict[int, _Share] = {}
    inner: dict[tuple[int, str], _Share] = {}
    shading = _Share()
    for key, fig in shares.items():
        if key is None:
            shading.add(fig)
            continue
        parts = key.split("/")
        k = root(key)
        per_op.setdefault(k, _Share()).add(fig)
        per_node.setdefault(main_ops[k].node, _Share()).add(fig)
        inner_node = ""
        if len(parts) > 1:
            fname, idx = parts[1].split(":")
            fn = next(f for f in cm.ir.functions if f.name == fname)
            inner_node = fn.ops[int(idx)].node
        inner.setdefault((k, inner_node), _Share()).add(fig)

    def row(fig: _Share) -> dict[str, float]:
        return {"instructions": _round(fig.instructions * scale),
                "samples": _round(fig.samples * sample_scale)}

    nodes = []
    for n in doc.graph.nodes.values():
        fig = per_node.get(n.id, _Share())
        nodes.append({"id": n.id, "kind": n.kind, **row(fig),
                      "share": round(fig.instructions / attributed, 4) if attributed else 0.0})
    nodes.sort(key=lambda r: (-r["instructions"], r["id"]))
    layers = []
    for stack, entries in _layer_info(doc).items():
        for e in entries:
            own, blend = _Share(), _Share()
            layer_nodes: dict[str, _Share] = {}
            for k, op in enumerate(main_ops):
                parts = op.var.split(".")
                if op.node != stack or len(parts) < 2 or parts[1] != e["id"]:
                    continue
                fig = per_op.get(k, _Share())
                own.instructions += fig.instructions
                own.samples += fig.samples
                if len(parts) > 2:  # the blend's ops: weight, blend, height blend, ...
                    blend.instructions += fig.instructions
                    blend.samples += fig.samples
                    continue
                for (kk, inner_node), f in inner.items():
                    if kk == k and inner_node:
                        acc = layer_nodes.setdefault(inner_node, _Share())
                        acc.instructions += f.instructions
                        acc.samples += f.samples
            layers.append({"stack": stack, "id": e["id"], "name": e["name"],
                           "blend": e["blend"], "visible": bool(e["visible"]), **row(own),
                           "blend_cost": row(blend),
                           "nodes": sorted(({"id": i, **row(f)} for i, f in
                                            layer_nodes.items()),
                                           key=lambda r: (-r["instructions"], r["id"]))})
    _offsets, ubytes = std140_layout(cm.ir)
    return {
        **totals.figures.as_dict(),
        "samplers": totals.samplers,
        "varyings": totals.inputs,
        "outputs": totals.outputs,
        "uniform_bytes": ubytes,
        "static": static.figures.as_dict(),
        "loops": {"count": len({h for h, _ in rel_trips.loops}),
                  "counted_once": len({h for h, n in rel_trips.loops if n is None})},
        "attributed_instructions": int(round(attributed)),
        "scale": round(scale, 4),
        "shading": row(shading),
        "nodes": nodes,
        "layers": layers,
    }


def material_stats(doc, resolver, targets: list[str]) -> dict[str, Any]:
    """The report of `doc` for `targets` (no --measure); raises CompileError, ToolError."""
    from matedit.compiler.api import compile_all

    glsl = sorted({t if t in TARGETS else "glsl450" for t in targets})
    compiled = compile_all(doc, resolver, glsl)
    out: dict[str, Any] = {}
    from concurrent.futures import ThreadPoolExecutor

    with tempfile.TemporaryDirectory(prefix="matedit-stats-") as tmp, \
            ThreadPoolExecutor(4) as pool:  # the tools run as processes: in parallel
        folder = Path(tmp)
        jobs = {(t, dbg): pool.submit(spirv_text, compiled[t].fragment_text, t, dbg, folder)
                for t in glsl for dbg in (True, False)}
        for t in glsl:
            out[t] = target_figures(compiled[t], doc, jobs[(t, False)].result(),
                                    jobs[(t, True)].result())
            out[t]["module"] = ("glslangValidator -V" if TARGETS[t].vulkan else
                                "glslangValidator -G") + " | spirv-opt -O" + \
                (" (as #version 310 es)" if t == "essl300" else "")
    for t in targets:
        if t in CROSS_TARGETS:
            out[t] = dict(out["glsl450"], module="glsl450's module, translated by spirv-cross")
    return {t: out[t] for t in targets}


# --- permutations -------------------------------------------------------------------------------
def switches(doc) -> list[dict[str, Any]]:
    """The static switches of the material: node id, parameter name, current value."""
    from matedit.graph.nodes import Role, role_of

    out = []
    for n in sorted(doc.graph.nodes.values(), key=lambda n: n.id):
        if role_of(n.kind) == Role.STATIC_SWITCH:
            out.append({"node": n.id, "name": n.settings.get("name") or n.id,
                        "value": bool(n.settings.get("value", True))})
    return out


def permutations(doc, resolver) -> dict[str, Any]:
    """Every combination of the switches (each on its own beyond MAX_PERMUTATIONS), with the
    glsl450 instructions and samples of each."""
    from matedit.compiler.api import compile_all

    sw = switches(doc)
    if not sw:
        return {"switches": [], "count": 1, "variants": []}
    n = len(sw)
    if 2 ** n <= MAX_PERMUTATIONS:
        combos = list(itertools.product((True, False), repeat=n))
    else:
        base = tuple(s["value"] for s in sw)
        combos = [base] + [tuple(not v if j == i else v for j, v in enumerate(base))
                           for i in range(n)]
    variants = []
    with tempfile.TemporaryDirectory(prefix="matedit-perm-") as tmp:
        for combo in combos:
            d = copy.deepcopy(doc)
            for s, v in zip(sw, combo):
                d.graph.nodes[s["node"]].settings["value"] = v
            cm = compile_all(d, resolver, ["glsl450"])["glsl450"]
            from matedit.compiler import cost, trips

            m = cost.parse(spirv_text(cm.fragment_text, "glsl450", False, Path(tmp)))
            t = cost.count(m, trips.weights(m.body, m.globals, uniform_values(cm, d)).weights)
            variants.append({"values": {s["name"]: v for s, v in zip(sw, combo)},
                             "instructions": t.figures.instructions,
                             "static_instructions": cost.count(m).figures.instructions,
                             "samples": t.figures.samples,
                             "current": all(s["value"] == v for s, v in zip(sw, combo))})
    return {"switches": sw, "count": 2 ** n, "variants": variants}


# --- the command ------------------------------------------------------------------------------


# --- budgets ----------------------------------------------------------------------------------
# WebGL2 (OpenGL ES 3.0) guarantees 16 texture units in the fragment stage
# (MAX_TEXTURE_IMAGE_UNITS); the instruction budget is a rule of thumb for a real-time
# material on mid-range hardware (dynamic glsl450 instructions, the shading included).
DEFAULT_BUDGET = {"samplers": 16, "instructions": 20000}
BUDGET_SAMPLER_TARGET = "essl300"
BUDGET_INSTRUCTION_TARGET = "glsl450"


def over_budget(per_target: dict[str, Any], samplers: int | None = None,
                instructions: int | None = None) -> list[str]:
    """One sentence for each budget the material passes: more samplers than `samplers` on
    essl300 (glsl450's count where essl300 was not computed), more dynamic instructions than
    `instructions` on glsl450. None: that budget is not checked."""
    out = []
    if samplers is not None:
        t = BUDGET_SAMPLER_TARGET if BUDGET_SAMPLER_TARGET in per_target else "glsl450"
        n = per_target.get(t, {}).get("samplers")
        if n is not None and n > samplers:
            out.append(f"{n} texture samplers on {t}: over the budget of {samplers}"
                       + (" (what WebGL2 guarantees)" if samplers == 16 else ""))
    if instructions is not None:
        n = per_target.get(BUDGET_INSTRUCTION_TARGET, {}).get("instructions")
        if n is not None and n > instructions:
            out.append(f"{n} instructions on {BUDGET_INSTRUCTION_TARGET} (dynamic): over the "
                       f"budget of {instructions}")
    return out
