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

from dataclasses import dataclass

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
        "(see [cli.md](cli.md)) writes a MaterialX 1.39 nodegraph feeding one surface",
        "shader (`open_pbr_surface` by default, `standard_surface` or `gltf_pbr`: see",
        "Export, below). Each kind is exported one of three ways:",
        "",
        "- **maps**: one stdlib node (its inputs named, ours→MaterialX's) or a recipe, a few",
        "  stdlib nodes that compute the same thing (written beside the kind in its category",
        "  module; the exporter's own for material attributes, their blends and texture",
        "  reads). Each is checked against MaterialX's own GLSL generator in",
        "  tests/test_interop_mtlx.py. A kind with no mapping the exporter can write is",
        "  refused by name.",
        "- **bakes**: not expressible node for node; the export evaluates its outputs over UV",
        "  space into maps in `OUT_textures/` (8-bit PNG, sRGB for a colour map, or float",
        "  EXR) read by `image` nodes, and reports each baked node.",
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
    lines += _EXPORT_TEXT
    lines += _TRANSMISSION_TEXT
    return "\n".join(lines)


# Each attribute field on the three surfaces the export writes (matedit.interop.mtlx_export;
# tests/test_interop_mtlx_surfaces.py holds the round trip to it).
_EXPORT_TEXT = [
    "## Export: the three surfaces",
    "",
    "`--surface` picks the surface shader. Every field goes to the input of the same",
    "meaning (a lobe's inputs only where the graph writes the lobe), and the import reads it",
    "back within 1e-6, except where the table says otherwise; each such field is a `note:`",
    "line on export. The anisotropy's roughness stretch is each surface's own on all three",
    "(ours: α (1 + a) along the direction, α (1 − a) across), noted as approximated.",
    "",
    "| field | open_pbr_surface | standard_surface | gltf_pbr |",
    "|---|---|---|---|",
    "| baseColor | `base_color` | `base_color` | `base_color` |",
    "| metallic | `base_metalness` | `metalness` | `metallic` |",
    "| roughness | `specular_roughness` | `specular_roughness` | `roughness` |",
    "| cavity | `base_weight` and `specular_weight` | `base` and `specular` | `occlusion`"
    " (indirect light only: noted) |",
    "| normal | `geometry_normal` (a `normalmap`) | `normal` (a `normalmap`) | `normal`"
    " (a `normalmap`) |",
    "| emissive | `emission_color`, `emission_luminance` 1000 | `emission_color`,"
    " `emission` 1 | `emissive` |",
    "| opacity | `geometry_opacity` | `opacity` (grey) | `alpha`, `alpha_mode` 2 (BLEND) |",
    "| specularColor | `specular_color` | `specular_color` | `specular_color` |",
    "| ior | `specular_ior` | `specular_IOR` | `ior` |",
    "| coat, coatRoughness | `coat_weight`, `coat_roughness` | `coat`, `coat_roughness` |"
    " `clearcoat`, `clearcoat_roughness` |",
    "| coatColor | `coat_color` | `coat_color` | none: noted, dropped |",
    "| coatIor | `coat_ior` (1.5 written, its default 1.6) | `coat_IOR` | none (glTF's"
    " is 1.5): noted unless 1.5 |",
    "| coatNormal | `geometry_coat_normal` | `coat_normal` | `clearcoat_normal` |",
    "| sheenColor, sheenRoughness | `fuzz_color` (`fuzz_weight` 1), `fuzz_roughness`:"
    " noted (OpenPBR's fuzz is its own lobe) | `sheen_color` (`sheen` 1), `sheen_roughness`"
    " | `sheen_color`, `sheen_roughness` |",
    "| anisotropy | `specular_roughness_anisotropy` | `specular_anisotropy` |"
    " `anisotropy_strength` |",
    "| anisotropyDirection | `geometry_tangent`: a constant as the world tangent turned"
    " about the normal by its angle (`rotate3d`), a varying one as normalize(T x + B y +"
    " N z) | `specular_rotation` (turns; a constant) | `anisotropy_rotation` (radians; a"
    " constant) |",
    "| subsurface, subsurfaceColor | `subsurface_weight`, `subsurface_color` |"
    " `subsurface`, `subsurface_color` | none: noted, dropped |",
    "| subsurfaceRadius, thickness | `subsurface_radius_scale` = radius,"
    " `subsurface_radius` = 1 / thickness: radius / thickness kept, the thickness reads"
    " back as 1 (noted) | `subsurface_radius`, `subsurface_scale` = 1 / thickness |"
    " radius none (noted); `thickness` (the volume's; 0 where thin-walled) |",
    "| thinFilmThickness | `thin_film_thickness` in µm, `thin_film_weight` 1 |"
    " `thin_film_thickness` (nm) | `iridescence_thickness` (nm), `iridescence` 1 |",
    "| thinFilmIor | `thin_film_ior` | `thin_film_IOR` | `iridescence_ior` |",
    "| transmission | `transmission_weight` | `transmission` | `transmission` |",
    "| transmissionColor | `transmission_color` (no depth) | `transmission_color`"
    " (no depth) | none: noted, dropped |",
    "| attenuationColor, attenuationDistance | `transmission_color`,"
    " `transmission_depth` | `transmission_color`, `transmission_depth` |"
    " `attenuation_color`, `attenuation_distance` |",
    "| thin_walled (the output's) | `geometry_thin_walled` | `thin_walled` | `thickness` 0 |",
    "",
    "A varying anisotropy direction is refused by name on standard_surface and gltf_pbr",
    "(their rotation inputs take a constant here). Baked maps and copies",
    "of the textures the material reads go into `OUT_textures/` beside the document,",
    "named by relative paths (docs/cli.md, export).",
    "",
]

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
    "## The base weight",
    "",
    "standard_surface's `base` (OpenPBR's `base_weight`) is the diffuse weight, and scales",
    "the metal's reflectivity through `base_color` (both surfaces' own graphs): the import",
    "reads it as a multiplier of our `baseColor`, exactly, for dielectrics, metals and glass",
    "alike. It is never our `cavity`, which darkens every lobe (a glass of base 0 would",
    "import black, and a base of 0.8 would darken the specular). The one exception is our own",
    "export's: it writes cavity to `base` and `specular` (`specular_weight`) alike, and the",
    "two from one source (one constant, or one node's output) darken the diffuse, the metal",
    "and the dielectric reflection together, which is our cavity: they read back as cavity,",
    "exactly where the surface has no coat, sheen, subsurface or transmission, and with a",
    "`warning:` (approximated) where it has one (our cavity darkens that lobe too).",
    "",
    "## Import: what maps and what warns",
    "",
    "`matedit import` (and the editor's File › Import MaterialX) drops nothing silently:",
    "every input a surface, a nodegraph node or the `surfacematerial` sets (an input at its",
    "node definition's default changes nothing and is not reported) is either read exactly",
    "or named in a `warning:` line with its value, node and material, ending `dropped` or",
    "`approximated`; `--strict` makes the warnings errors (docs/cli.md). Nodes and inputs",
    "the import cannot read at all (an unsupported node such as `fractal3d` or",
    "`hextilednormalmap`, a connected anisotropy rotation, a world-space normal not from a",
    "`normalmap`, a connected address mode) are `error:` lines, as before.",
    "tests/test_interop_mtlx_warnings.py checks the rule on every input of the documents in",
    "tests/data/mtlx, MaterialX's own examples included (their tally is at the end).",
    "",
    "### Texture nodes",
    "",
    "- `image`: its file (relative), colour space (MaterialX's name, matched through",
    "  OpenColorIO's aliases) and `texcoord`. Periodic addressing and linear filtering read",
    "  as a Texture Sample; any other `uaddressmode` / `vaddressmode` (`clamp`, `mirror`,",
    "  `constant`, whose border colour is the image's `default`) or `filtertype` `closest`",
    "  as an Addressed Texture Sample (`texture_sample_addressed`), which reads them as",
    "  MaterialX's GLSL renderer binds them (GL_CLAMP_TO_EDGE, GL_MIRRORED_REPEAT,",
    "  GL_CLAMP_TO_BORDER, GL_NEAREST; tests/test_texture_addressed.py compares it with",
    "  OpenGL's own samplers). `filtertype` `cubic` is read as linear, as that renderer does,",
    "  with a `warning:` (approximated: other renderers filter it bicubically).",
    "- Stdlib nodes MaterialX defines as a nodegraph of other stdlib nodes (`tiledimage`,",
    "  `place2d`, `gltf_image`, `gltf_colorimage`, `gltf_normalmap`, and any other whose",
    "  nodes all map) are read through that definition: each of its nodes by its own rule,",
    "  with the instance's inputs (or the definition's defaults) for its interface. An input",
    "  the instance sets that its definition does not use warns (dropped). `place2d`'s",
    "  `operationorder` (a `switch`) must be a constant.",
    "- `normalmap`: its `scale` (a float or a vector2, a constant) scales the decoded",
    "  tangent-space x and y before normalising, as MaterialX's; its `normal`, `tangent`",
    "  and `bitangent` may be the surface's own (unset, or world-space geometry nodes of",
    "  those names), any other is an error.",
    "- `texcoord`: matedit meshes carry one UV set; an `index` other than 0 reads set 0",
    "  with a `warning:` naming it (approximated).",
    "- `hextiledimage` reads as a Hex-Tiled Texture (`hex_tiled_texture`): the same hex",
    "  grid (Mikkelsen's hex-tiling), random rotation, scale and offset per tile, and",
    "  luminance-weighted blend with its falloff; its `default` (a missing file's colour)",
    "  warns (dropped).",
    "- `rgbtohsv` reads as RGB to HSV, `hsvtorgb` as HSV to RGB.",
    "",
    "tests/test_interop_mtlx_textures.py draws each of these with MaterialX's own GLSL",
    "generator and compares the imported material's CPU evaluation (2e-3).",
    "",
    "Read exactly (besides the transmission and base weight above):",
    "",
    "- **standard_surface**: `base_color`, `metalness`, `specular_roughness`, `specular_IOR`,",
    "  `specular_color` (a dielectric's), `emission` × `emission_color`, `opacity` (grey),",
    "  `normal` and `coat_normal` (from a `normalmap`), `coat`, `coat_color`,",
    "  `coat_roughness`, `coat_IOR`, `sheen` × `sheen_color`, `sheen_roughness` (from 0.3),",
    "  `specular_anisotropy`, `specular_rotation` (turns, a constant), `subsurface`,",
    "  `subsurface_color`, `subsurface_radius`, `subsurface_scale` (1 / thickness),",
    "  `thin_film_thickness`, `thin_film_IOR`.",
    "- **open_pbr_surface**: the same through OpenPBR's names (`base_metalness`,",
    "  `specular_ior`, `specular_roughness_anisotropy`, `coat_weight`, `fuzz_weight` ×",
    "  `fuzz_color`, `fuzz_roughness`, `emission_luminance` (1000 nits is our emissive 1),",
    "  `geometry_opacity`, `geometry_normal`, `geometry_coat_normal`, `subsurface_weight`,",
    "  `subsurface_radius` × `subsurface_radius_scale`, `thin_film_thickness` (µm) ×",
    "  `thin_film_weight` (0 or 1), `thin_film_ior`, and `geometry_tangent` where it is",
    "  our export's: the world tangent turned about the world normal by a constant",
    "  `rotate3d`, whose amount turns clockwise, or normalize(T x + B y + N z) of the world",
    "  tangent, bitangent and normal, read as the anisotropy direction; any other tangent",
    "  warns, dropped).",
    "- **gltf_pbr**: `base_color`, `metallic`, `roughness`, `normal`, `emissive` ×",
    "  `emissive_strength`, `alpha` under `alpha_mode` 2 (BLEND), `ior`, `specular_color`,",
    "  `transmission`, `thickness` (0: thin-walled where it transmits),",
    "  `attenuation_distance`, `attenuation_color`, `clearcoat`, `clearcoat_roughness`,",
    "  `clearcoat_normal`, `sheen_color`, `sheen_roughness` (from 0.3),",
    "  `anisotropy_strength`, `anisotropy_rotation` (radians), `iridescence_thickness` (nm)",
    "  × `iridescence` (0 or 1), `iridescence_ior`.",
    "- **UsdPreviewSurface**: `diffuseColor`, `emissiveColor`, `metallic`, `roughness`,",
    "  `normal` (tangent space), `clearcoat`, `clearcoatRoughness`, `opacity`, `ior`.",
    "",
    "Warned about, approximated (read, but not exactly):",
    "",
    "- `specular_color` of a surface with metal: it tints the dielectric's F0 only; the",
    "  metal's edge colour it also is in standard_surface and OpenPBR is not ours.",
    "- `sheen_roughness` / `fuzz_roughness` below 0.3 (our sheen clamps there), and any",
    "  connected one (it may be).",
    "- `thin_film_weight` and gltf_pbr's `iridescence` other than 0 or 1: they scale the",
    "  film's thickness (we have no film weight).",
    "- gltf_pbr's and UsdPreviewSurface's `occlusion` other than 1: read as our cavity, which",
    "  darkens direct light too.",
    "- standard_surface's colour `opacity` that is not grey: its first channel.",
    "- gltf_pbr's `alpha_mode` 1 (MASK): read as blending, without the cutoff.",
    "- `base` and `specular` as one value on a surface with another lobe (above).",
    "- a colour value in another colour space than `lin_rec709`, and a value with a `unit`:",
    "  read as written, without MaterialX's conversion.",
    "- an image's `filtertype` `cubic` (read as linear) and a `texcoord` `index` other than",
    "  0 (set 0 is read).",
    "",
    "Warned about, dropped (no counterpart): standard_surface's `specular` weight (OpenPBR's",
    "`specular_weight`, gltf_pbr's `specular`) other than 1, `diffuse_roughness`",
    "(`base_diffuse_roughness`), `coat_anisotropy`, `coat_rotation`,",
    "`coat_affect_color`, `coat_affect_roughness` (`coat_darkening`,",
    "`coat_roughness_anisotropy`), `subsurface_anisotropy`",
    "(`subsurface_scatter_anisotropy`), `transmission_dispersion`,",
    "`transmission_extra_roughness`, `transmission_scatter` and its anisotropy, OpenPBR's",
    "`transmission_dispersion_scale` and `_abbe_number`, `tangent` (OpenPBR's",
    "`geometry_tangent` but the rotation above); gltf_pbr's `alpha`",
    "under `alpha_mode` 0 (OPAQUE ignores it) and",
    "`dispersion`; UsdPreviewSurface's `useSpecularWorkflow`, `specularColor`,",
    "`opacityThreshold`, `displacement`; a `surfacematerial`'s `displacementshader`; a",
    "constant world-space `normal` (gltf_pbr's examples write (0, 0, 1)); and on",
    "nodegraph nodes every input the import does not read (an `image`'s `default` outside",
    "constant addressing, its `layer`",
    "and frame inputs, a `time`'s `fps`, ...). Any other input a file sets that the import",
    "does not read warns the same way: the list is what the rule found, not what it checks.",
    "",
]


@dataclass(frozen=True)
class Arithmetic:
    """Our kinds of MaterialX's multiply, add and subtract: what an importer of another
    format (matedit.interop.gltf_import) builds factors and offsets with."""

    multiply: str
    add: str
    subtract: str


def arithmetic() -> Arithmetic:
    return Arithmetic(*(kind_mapped_to(c) for c in ("multiply", "add", "subtract")))
