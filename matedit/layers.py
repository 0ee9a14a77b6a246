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
    holds: str  # what the layer is, one line (the documentation's "holds" column)
    imports: tuple[str, ...] = ()  # third-party top-level modules it may import


LAYERS: tuple[Layer, ...] = (
    Layer("base", ("matedit", "matedit.resources", "matedit.dirs", "matedit.layers"),
          "the version, where shaders/, graphs/ and ui/ are, user folders, this table",
          ("platformdirs",)),
    Layer("types", ("matedit.graph.types", "matedit.graph.numbers", "matedit.graph.names"),
          "port types and the one implicit conversion; the float32 rule; identifiers"),
    Layer("model", ("matedit.graph",),
          "the node catalogue, documents, edit commands, layer stacks, validation",
          ("networkx",)),
    Layer("format", ("matedit.io",),
          "JSON load and save, migrations, the JSON Schema check, atomic writes, images",
          ("jsonschema", "referencing", "OpenImageIO", "numpy")),
    Layer("glsl", ("matedit.glsl",),
          "GLSL assembly with #include and a #line map; bindings and block layouts"),
    # Before the compiler (the table once put it after): shading is numpy maths that knows
    # nothing of graphs or IR, and the compiler's numpy evaluator decodes a texture through
    # shading.colorspace exactly as the renderer does.
    Layer("shading", ("matedit.shading",),
          "the numpy twin of shaders/ (BRDF, lights, split sum, colour spaces)",
          ("numpy", "OpenImageIO")),
    # A light rig file is shading's Light list on disk: it reads JSON as the format layer
    # does and builds matedit.shading.lights.Light, so it stands above both.
    Layer("rig", ("matedit.io.rig",), "light rig files"),
    Layer("compiler", ("matedit.compiler",),
          "document to typed IR to GLSL per target, reflection; the numpy evaluator",
          ("numpy",)),
    Layer("ibl numerics", ("matedit.ibl.builtin", "matedit.ibl.cubemap", "matedit.ibl.sh",
                           "matedit.ibl.environment", "matedit.ibl.cache"),
          "environments, cube maps, SH irradiance, the on-disk cache", ("numpy",)),
    Layer("ibl", ("matedit.ibl",),
          "GGX prefiltering and the BRDF LUT on a context it is given; IBL textures",
          ("numpy", "moderngl")),
    Layer("interop", ("matedit.interop",),
          "MaterialX, glTF, texture baking, HLSL/MSL, the compiled-shader files",
          ("MaterialX", "pygltflib", "OpenImageIO", "numpy", "moderngl")),
    Layer("render", ("matedit.render",), "the preview renderer on any moderngl context",
          ("numpy", "moderngl")),
    Layer("app", ("matedit.app",), "the PySide6 editor",
          ("PySide6", "shiboken6", "numpy", "moderngl")),
    Layer("cli", ("matedit.cli_support", "matedit.commands", "matedit.cli", "matedit.__main__"),
          "the matedit command: the editor, or a headless command",
          ("numpy", "moderngl", "OpenImageIO")),
)


def layer_of(module: str) -> int | None:
    """The index in LAYERS of a matedit module's layer (None: not a matedit module)."""
    best, found = -1, None
    for i, layer in enumerate(LAYERS):
        for entry in layer.modules:
            if (module == entry or module.startswith(entry + ".")) and len(entry) > best:
                best, found = len(entry), i
    return found
