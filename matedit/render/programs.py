"""The renderer's program cache: (structure hash of an entry variant) -> linked program, and
the location of a failed link on the graph's nodes.

A material is linked through one of its entry variants (matedit.compiler.emit.Entry, with the
preview's extra defines); the variant's structure hash covers its whole text, so it is the key.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import moderngl

from matedit.compiler.api import CompiledMaterial
from matedit.compiler.emit import Entry


@dataclass
class MaterialStatus:
    ok: bool
    errors: list[tuple[str, str]] = field(default_factory=list)  # (node id, message)
    log: str = ""


def failure(compiled: CompiledMaterial, exc: Exception) -> MaterialStatus:
    """The status of a failed link, its errors located on nodes where the log allows."""
    log = str(exc)
    located = compiled.locate_error(log)
    errors = [(node, msg) for node, _, _, msg in located if node and "error" in msg.lower()]
    if not errors:
        errors = [("", next((m for _, _, _, m in located if "error" in m.lower()),
                            log.strip().splitlines()[-1] if log.strip() else log))]
    return MaterialStatus(False, errors, log)


class ProgramCache:
    """Linked material programs; `bind` assigns a new program's block bindings and units."""

    def __init__(self, ctx: moderngl.Context, bind) -> None:
        self.ctx = ctx
        self.table: dict[str, moderngl.Program] = {}
        self.link_count = 0
        self._bind = bind

    def get(self, compiled: CompiledMaterial, entry: Entry,
            defines: tuple[str, ...] = ()) -> tuple[moderngl.Program, CompiledMaterial]:
        """The program of one variant (linked on first use; raises moderngl.Error) and the
        variant itself (for locating errors)."""
        variant = compiled.variant(entry, tuple(defines))
        prog = self.table.get(variant.structure_hash)
        if prog is None:
            prog = self.ctx.program(vertex_shader=variant.vertex_text,
                                    fragment_shader=variant.fragment_text)
            self.link_count += 1
            self._bind(prog)
            self.table[variant.structure_hash] = prog
        return prog, variant

    def release(self, forget=None) -> None:
        for p in self.table.values():
            if forget is not None:
                forget(p)
            p.release()
        self.table.clear()
