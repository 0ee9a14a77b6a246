"""The layers of the package and what each may import: the table of docs/architecture.md
("Layers and what each may import"), as data.

A module belongs to the layer whose entry names it or the nearest package above it (the
longest entry that is a prefix of its dotted name wins, so `matedit.io.rig` can sit in
another layer than the rest of `matedit.io`). A module may import

- the standard library,
- the third-party top-level modules its own layer lists (not those of other layers: only the
  application layer lists Qt; the renderer lists moderngl and not Qt), and
- matedit modules of its own layer or of a layer listed before it, never after.

No import cycle among matedit modules is allowed either. tests/test_layer_rule.py holds the
package to this, reading every import with `ast` (module level and inside functions; imports
under `if TYPE_CHECKING:` only serve the type checker and do not count).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Layer:
    name: str
    modules: tuple[str, ...]  # dotted packages or modules
    imports: tuple[str, ...] = ()  # third-party top-level modules it may import


LAYERS: tuple[Layer, ...] = (
    # the version; where shaders/, graphs/ and ui/ are; user folders; this table
    Layer("base", ("matedit", "matedit.resources", "matedit.dirs", "matedit.layers"),
          ("platformdirs",)),
    # port types and the one implicit conversion; the float32 rule; identifiers
    Layer("types", ("matedit.graph.types", "matedit.graph.numbers", "matedit.graph.names")),
    # the node kinds, one category module each: definitions, numpy twins, MaterialX recipes
    # (written through a builder the exporter passes in, so no MaterialX here)
    Layer("nodes", ("matedit.nodes",), ("numpy",)),
    # the node catalogue, documents, edit commands, layer stacks, validation
    Layer("model", ("matedit.graph",), ("networkx",)),
    # JSON load and save, migrations, the JSON Schema check, atomic writes, images
    Layer("format", ("matedit.io",), ("jsonschema", "referencing", "OpenImageIO", "numpy")),
    # GLSL assembly with #include and a #line map; bindings and block layouts
    Layer("glsl", ("matedit.glsl",)),
    # The numpy twin of shaders/. Before the compiler (the table once put it after): shading
    # is maths that knows nothing of graphs or IR, and the compiler's numpy evaluator decodes
    # a texture through shading.colorspace exactly as the renderer does.
    Layer("shading", ("matedit.shading",), ("numpy", "OpenImageIO")),
    # A light rig file is shading's Light list on disk: it reads JSON as the format layer
    # does and builds matedit.shading.lights.Light, so it stands above both.
    Layer("rig", ("matedit.io.rig",)),
    # document to typed IR to GLSL per target, reflection; the numpy evaluator
    Layer("compiler", ("matedit.compiler",), ("numpy",)),
    # environments, cube maps, SH irradiance, the on-disk cache: no GL
    Layer("ibl numerics", ("matedit.ibl.builtin", "matedit.ibl.cubemap", "matedit.ibl.sh",
                           "matedit.ibl.environment", "matedit.ibl.cache"), ("numpy",)),
    # GGX prefiltering and the BRDF LUT on a context it is given; IBL textures
    Layer("ibl", ("matedit.ibl",), ("numpy", "moderngl")),
    # the compiled-shader files, HLSL/MSL, texture baking, glTF, MaterialX, USD
    Layer("interop", ("matedit.interop",),
          ("MaterialX", "pygltflib", "pxr", "OpenImageIO", "numpy", "moderngl")),
    # the preview renderer on any moderngl context
    Layer("render", ("matedit.render",), ("numpy", "moderngl")),
    # the headless commands (validate, compile, render, bake, export, import ...) and their
    # one-line reports: what the editor's dialogs run too (File › Export: commands.export)
    Layer("commands", ("matedit.cli_support", "matedit.commands"),
          ("numpy", "moderngl", "OpenImageIO")),
    # the PySide6 editor
    Layer("app", ("matedit.app",), ("PySide6", "shiboken6", "numpy", "moderngl")),
    # the matedit command: the editor, or a headless command
    Layer("cli", ("matedit.cli", "matedit.__main__"), ("numpy",)),
)


def layer_of(module: str, layers: tuple[Layer, ...] = LAYERS) -> int | None:
    """The index in `layers` of a module's layer (None: in no layer)."""
    best, found = -1, None
    for i, layer in enumerate(layers):
        for entry in layer.modules:
            if (module == entry or module.startswith(entry + ".")) and len(entry) > best:
                best, found = len(entry), i
    return found
