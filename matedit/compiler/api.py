"""compile_document: a material document to GLSL for one or all targets, with reflection."""

from __future__ import annotations

import copy
import gc
import hashlib
import re
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from matedit.compiler import ops
from matedit.compiler.emit import Entry, SourceMap, fragment_source, std140_layout, vertex_source
from matedit.compiler.ir import MaterialIR, Splat, Uni, Var
from matedit.compiler.lower import CompileError, lower_document
from matedit.compiler.passes import optimise
from matedit.compiler.targets import FIRST_TEXTURE_BINDING, MATERIAL_BINDING, TARGETS
from matedit.glsl.include import LINE_STRIDE, Assembly
from matedit.graph.model import MaterialDocument
from matedit.graph.ports import FunctionResolver

if TYPE_CHECKING:
    from matedit.graph.validate import Analysis

_LOC = re.compile(r"(\d+):(\d+)\(\d+\)|ERROR: (\d+):(\d+):|(\d+)\((\d+)\) :")


@dataclass
class CompiledMaterial:
    target: str
    vertex: Assembly
    fragment: Assembly
    source_map: SourceMap
    ir: MaterialIR
    structure_hash: str

    @property
    def vertex_text(self) -> str:
        return self.vertex.text

    @property
    def fragment_text(self) -> str:
        return self.fragment.text

    def variant(self, entry: Entry | str, defines: tuple[str, ...] = ()) -> CompiledMaterial:
        """The same material (same IR) through another entry point and/or extra defines,
        memoised on this object (the compile worker warms it off the UI thread)."""
        entry = Entry.of(entry)
        key = (entry, tuple(defines))
        cache = self.__dict__.setdefault("_variants", {})
        hit = cache.get(key)
        if hit is None:
            t = TARGETS[self.target]
            with _no_gc():
                frag, smap = fragment_source(self.ir, t, entry, defines)
            hit = CompiledMaterial(self.target, self.vertex, frag, smap, self.ir,
                                   structure_hash(self.vertex.text, frag.text))
            cache[key] = hit
        return hit

    def reflection(self) -> dict[str, Any]:
        offsets, size = std140_layout(self.ir)
        return {
            "target": self.target,
            "structure_hash": self.structure_hash,
            "attributes": list(self.ir.attributes),
            "uniform_block": {"name": "MaterialParams", "binding": MATERIAL_BINDING,
                              "size": size} if self.ir.uniforms else None,
            "uniforms": [
                {"name": u.name, "type": u.type.value, "default": u.default, "node": u.node,
                 "port": u.port, "offset": offsets[u.name],
                 **({"parameter": u.parameter} if u.parameter else {})}
                for u in self.ir.uniforms
            ],
            "textures": [
                {"name": t.name, "binding": FIRST_TEXTURE_BINDING + i, "path": t.ref,
                 "node": t.node, "parameter": t.parameter, "srgb": t.srgb,
                 "color_space": t.color_space}
                for i, t in enumerate(self.ir.textures)
            ],
            "functions": [f.name for f in self.ir.functions],
            **({"static_switches": dict(self.ir.switches)} if self.ir.switches else {}),
        }

    def pack_uniforms(self, values: dict[str, Any] | None = None) -> bytes:
        """The MaterialParams block bytes (std140) for defaults overridden by `values`."""
        import struct

        offsets, size = std140_layout(self.ir)
        buf = bytearray(size)
        for u in self.ir.uniforms:
            v = (values or {}).get(u.name, u.default)
            vals = [float(v)] if u.type.components == 1 else [float(x) for x in v]
            struct.pack_into(f"<{len(vals)}f", buf, offsets[u.name], *vals)
        return bytes(buf)

    def locate_error(self, log: str) -> list[tuple[str, str, int, str]]:
        """(node id, file, line, message) for each located line of a GL compile log."""
        out = []
        for line in log.splitlines():
            m = _LOC.search(line)
            if not m:
                continue
            src = int(m.group(1) or m.group(3) or m.group(5))
            ln = int(m.group(2) or m.group(4) or m.group(6))
            if ln >= LINE_STRIDE:  # the include mechanism encodes the source in the line
                src, ln = divmod(ln, LINE_STRIDE)
            hit = self.source_map.node_at(src, ln)
            if hit:
                out.append((hit[0], hit[1], ln, line.strip()))
            else:
                name, n = self.fragment.locate(src, ln)
                out.append(("", name, n, line.strip()))
        return out


def structure_hash(vertex: str, fragment: str) -> str:
    return hashlib.sha256((vertex + "\0" + fragment).encode()).hexdigest()[:16]


@contextmanager
def _no_gc():
    """A compile allocates many small objects that live until it ends; on large graphs the
    cyclic collector's repeated passes over them cost a third of the time (10,000 nodes).
    What survives the compile (the IR, the sources) lives as long as the compiled material,
    so it goes straight to the oldest generation (`freeze` then `unfreeze` moves every young
    object there without a pass over them, and zeroes the allocation count); otherwise the
    first allocation after the pause scans all of it (12 ms at 10,000 nodes)."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.freeze()
            gc.unfreeze()
            gc.enable()


def _uniforms_in(e, out: set[str]) -> None:
    while isinstance(e, Splat):
        e = e.expr
    if isinstance(e, Uni):
        out.add(e.name)


def prune(ir: MaterialIR) -> None:
    """After dead-code removal: drop the uniforms, textures and functions no live code uses,
    so unconnected nodes cost nothing (9,000 of them must not overflow the uniform block)."""
    called: set[str] = set()
    by_name = {f.name: f for f in ir.functions}
    todo = [ir.main]
    used: set[str] = set()
    while todo:
        scope = todo.pop()
        for op in scope.ops:
            for a in op.args:
                if type(a) is not Var:  # another op's output names no uniform
                    _uniforms_in(a, used)
            fn = op.data.get("function") if op.kind == ops.CALL else None
            if fn and fn not in called:
                called.add(fn)
                if fn in by_name:
                    todo.append(by_name[fn])
        for _, _, e in scope.outputs:
            _uniforms_in(e, used)
    ir.functions = [f for f in ir.functions if f.name in called]
    ir.uniforms = [u for u in ir.uniforms if u.name in used]
    ir.textures = [t for t in ir.textures if t.name in used]


def lower_and_optimise(doc: MaterialDocument, resolver: FunctionResolver | None,
                       analysis: Analysis | None = None) -> MaterialIR:
    with _no_gc():
        ir = lower_document(doc, resolver, analysis)
        for scope in [*ir.functions, ir.main]:
            optimise(scope)
        prune(ir)
    return ir


ENERGY_COMPENSATION_DEFINE = "MATEDIT_ENERGY_COMPENSATION"


def compile_document(doc: MaterialDocument, resolver: FunctionResolver | None = None,
                     target: str = "glsl330", mode: str | Entry = Entry.FORWARD,
                     ir: MaterialIR | None = None,
                     analysis: Analysis | None = None) -> CompiledMaterial:
    """Compile for one target; raises CompileError (with diagnostics) for a bad graph.
    `analysis`: the document's current analysis, when the caller has it (the editor)."""
    if target not in TARGETS:
        raise ValueError(f"unknown target {target!r} (expected {', '.join(TARGETS)})")
    if resolver is None:
        from matedit.io.document import FileResolver

        resolver = FileResolver()
    with _no_gc():  # one pause for the whole compile: the collector runs once, after it
        ir = ir if ir is not None else lower_and_optimise(doc, resolver, analysis)
        if isinstance(doc.preview, dict) and doc.preview.get("energy_compensation") is True \
                and ENERGY_COMPENSATION_DEFINE not in ir.defines:
            ir.defines.append(ENERGY_COMPENSATION_DEFINE)  # the material's option (shading)
        t = TARGETS[target]
        vert = vertex_source(t)
        frag, smap = fragment_source(ir, t, mode)
    return CompiledMaterial(target, vert, frag, smap, ir, structure_hash(vert.text, frag.text))


def compile_ir(ir: MaterialIR, target: str = "glsl330") -> CompiledMaterial:
    """A CompiledMaterial of an IR built by hand (the renderer's warm-up, benchmarks' floor)."""
    t = TARGETS[target]
    vert = vertex_source(t)
    frag, smap = fragment_source(ir, t)
    return CompiledMaterial(target, vert, frag, smap, ir, structure_hash(vert.text, frag.text))


def compile_all(doc: MaterialDocument, resolver: FunctionResolver | None = None,
                targets: list[str] | None = None) -> dict[str, CompiledMaterial]:
    if resolver is None:
        from matedit.io.document import FileResolver

        resolver = FileResolver()
    ir = lower_and_optimise(doc, resolver)
    return {t: compile_document(doc, resolver, t, ir=copy.deepcopy(ir))
            for t in (targets or list(TARGETS))}


__all__ = ["CompileError", "CompiledMaterial", "Entry", "compile_all", "compile_document",
           "lower_and_optimise"]
