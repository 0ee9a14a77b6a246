"""How each node kind of the catalogue maps to MaterialX 1.39 stdlib nodes.

The one source is the catalogue: `NodeDef.mtlx` (matedit.graph.nodes). An entry is one of:

  MxNode(category, ports)   one stdlib node of that category; `ports` maps our input names
                            to its inputs in order, `fixed` adds constant inputs, `output`
                            names its output. Every input is converted to the op's result
                            type first, so the same-type node definition is always chosen.
  MxRecipe(name)            a few stdlib nodes, built by matedit.interop.mtlx_export (the
                            recipe of that name) and read back by matedit.interop.mtlx_import.
  BAKE                      not expressible node for node: the exporter bakes the node's
                            outputs over UV space into EXR images read by `image` nodes.
  LOWERED                   never reaches the exporter: the compiler lowers it to uniforms,
                            literals, inlined calls and blends.

This module only reads the catalogue for the exporter and the importer.
"""

from __future__ import annotations

from matedit.graph import nodes
from matedit.graph.nodes import BAKE, LOWERED, MxNode, MxRecipe

__all__ = ["BAKE", "LOWERED", "MxNode", "MxRecipe", "direct", "kind_mapped_to", "mapping",
           "mapped_kinds",
           "baked_kinds", "lowered_kinds"]


def mapping(kind: str) -> MxNode | MxRecipe | str:
    """The catalogue's entry for `kind`; names that are no kind bake."""
    d = nodes.get(kind)
    return d.mtlx if d is not None else BAKE


def mapped_kinds() -> list[str]:
    """Kinds exported node for node (a stdlib node or a recipe), sorted."""
    return sorted(k for k, d in nodes.REGISTRY.items() if isinstance(d.mtlx, (MxNode, MxRecipe)))


def baked_kinds() -> list[str]:
    return sorted(k for k, d in nodes.REGISTRY.items() if d.mtlx == BAKE)


def lowered_kinds() -> list[str]:
    return sorted(k for k, d in nodes.REGISTRY.items() if d.mtlx == LOWERED)


def direct() -> dict[str, tuple[str, dict[str, str]]]:
    """MaterialX category -> (our kind, {its input: our input}) for the kinds that map to one
    stdlib node with inputs and no fixed ones, or name one in `mtlx_reads`: what the
    importer reads back one for one."""
    out: dict[str, tuple[str, dict[str, str]]] = {}
    for kind, d in nodes.REGISTRY.items():
        for m in (d.mtlx, d.mtlx_reads):
            if isinstance(m, MxNode) and m.ports and not m.fixed and m.category not in out:
                out[m.category] = (kind, {theirs: ours for ours, theirs in m.ports})
    return out


def kind_mapped_to(name: str) -> str:
    """The catalogue kind that exports as the stdlib node `name` (an MxNode category, first
    registered wins) or as the recipe `name`: what the importer builds when it reads one
    back."""
    for kind, d in nodes.REGISTRY.items():
        m = d.mtlx
        if (isinstance(m, MxNode) and m.category == name) or \
                (isinstance(m, MxRecipe) and m.name == name):
            return kind
    raise LookupError(f"no catalogue kind exports as MaterialX {name!r}")
