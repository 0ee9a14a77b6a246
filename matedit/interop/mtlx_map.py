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
    back. A kind that maps to the node with no fixed inputs wins over one that fixes some
    (MaterialX's modulo reads back as our mod, not as frac's modulo by 1)."""
    for one_for_one in (True, False):
        for kind, d in nodes.REGISTRY.items():
            m = d.mtlx
            if isinstance(m, MxNode) and m.category == name and \
                    (not m.fixed or not one_for_one):
                return kind
            if isinstance(m, MxRecipe) and m.name == name:
                return kind
    raise LookupError(f"no catalogue kind exports as MaterialX {name!r}")


def _entry_text(m) -> str:
    if isinstance(m, MxNode):
        ins = ", ".join(f"{ours}→{theirs}" for ours, theirs in m.ports)
        fixed = ", ".join(f"{name}={value:g}" for name, value in m.fixed)
        return f"`{m.category}`" + (f" ({ins}" + (f"; {fixed}" if fixed else "") + ")"
                                    if ins or fixed else "")
    return f"recipe `{m.name}`"


def document() -> str:
    """docs/materialx.md: which catalogue kinds map to MaterialX and which bake (generated
    from the catalogue by docs/materialx.py; tests/test_kind_contract.py keeps it true)."""
    by_kind = nodes.REGISTRY
    mapped, baked, lowered = mapped_kinds(), baked_kinds(), lowered_kinds()
    lines = [
        "# MaterialX: what maps and what bakes",
        "",
        "Generated from the node catalogue (`NodeDef.mtlx` in matedit/nodes/) by",
        "`docs/materialx.py`; a test fails when it is out of date. `matedit export OUT.mtlx`",
        "(see [cli.md](cli.md)) writes a MaterialX 1.39 nodegraph feeding one",
        "`standard_surface`. Each kind is exported one of three ways:",
        "",
        "- **maps**: one stdlib node (its inputs named, ours→MaterialX's) or a recipe, a few",
        "  stdlib nodes that compute the same thing (written beside the kind in its category",
        "  module; the exporter's own for material attributes, their blends and texture",
        "  reads). Each is checked against MaterialX's own GLSL generator in",
        "  tests/test_interop_mtlx.py. A kind with no mapping the exporter can write is",
        "  refused by name.",
        "- **bakes**: not expressible node for node; the export evaluates its outputs over UV",
        "  space into EXR images read by `image` nodes, and reports each baked node.",
        "- **lowered**: never reaches the exporter; the compiler turns it into interface",
        "  inputs (parameters), values (constants), inlined calls and blends.",
        "",
        "The thin film (docs/shading.md, Thin film): `thinFilmThickness` (nm) and",
        "`thinFilmIor` export as standard_surface's `thin_film_thickness` (nm too) and",
        "`thin_film_IOR` (1.3 written where only the thickness is, its default being 1.5), and",
        "import back from them; from OpenPBR, `thin_film_thickness` is in micrometres (its",
        "library scales it by 1000 to nm), times `thin_film_weight`, and `thin_film_ior`.",
        "",
        f"{len(mapped)} kinds map, {len(baked)} bake, {len(lowered)} are lowered.",
        "",
        "## Kinds that map to MaterialX",
        "",
        "| kind | MaterialX |",
        "|---|---|",
    ]
    lines += [f"| `{k}` | {_entry_text(by_kind[k].mtlx)} |" for k in mapped]
    lines += ["", "## Kinds that bake", ""]
    lines += [", ".join(f"`{k}`" for k in baked), ""]
    lines += ["## Kinds lowered before export", ""]
    lines += [", ".join(f"`{k}`" for k in lowered), ""]
    lines += _TRANSMISSION_TEXT
    return "\n".join(lines)


# The surface inputs of the transmission lobe (matedit.interop.mtlx_export / mtlx_import).
_TRANSMISSION_TEXT = [
    "## Transmission",
    "",
    "standard_surface, both ways: `transmission` is our `transmission`; `thin_walled` is the",
    "Material Output's thin_walled setting (a constant only). `transmission_color` is a",
    "surface tint at `transmission_depth` 0 and the absorption colour reached at that depth",
    "otherwise (standard_surface's rule), so: a material with `attenuationDistance` writes",
    "`transmission_depth` = attenuationDistance and `transmission_color` = attenuationColor",
    "(its `transmissionColor` has no counterpart then and is not written); one without writes",
    "`transmission_color` = transmissionColor. The import reads the same rule back, and",
    "OpenPBR's `transmission_weight`, `transmission_color`, `transmission_depth` and",
    "`geometry_thin_walled` alike. The part's `thickness` travels as `subsurface_scale`",
    "(1 / thickness, see Subsurface in docs/shading.md).",
    "",
    "The base weight: our `cavity` multiplies all lighting, standard_surface's `base`",
    "(OpenPBR's `base_weight`) only the diffuse and the metal. A surface whose transmission",
    "weight is set (connected, or above 0) imports its base weight as a multiplier of the",
    "base colour, not as cavity, so a glass of `base` 0 does not import black; other surfaces",
    "keep base as cavity (the export writes cavity to `base` and `specular`).",
    "",
]
