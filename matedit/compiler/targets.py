"""The three GLSL dialects matedit emits, and the bindings they share.

Bindings (Vulkan: set 0; desktop GL and WebGL2 assign block bindings and texture
units by name at link time): 0 LightsBlock, 1 IblBlock, 2 prefiltered
environment, 3 BRDF LUT, 4 unfiltered environment (see shaders/ibl_inputs.glsl),
5 FrameBlock, 6 MaterialParams, 7 the environment's sampling table (reference mode),
8 and up the material's textures: matedit/glsl/layout.py,
the one source of these numbers.
"""

from __future__ import annotations

from dataclasses import dataclass

from matedit.glsl.layout import BINDINGS

FRAME_BINDING = BINDINGS["FRAME"]
MATERIAL_BINDING = BINDINGS["MATERIAL"]
FIRST_TEXTURE_BINDING = BINDINGS["FIRST_TEXTURE"]


@dataclass(frozen=True)
class Target:
    """A dialect, as data: the GLSL back-end (`glsl_backend.prelude`, `varying`) writes it."""

    name: str
    version: str
    vulkan: bool = False
    es: bool = False


TARGETS = {
    "glsl330": Target("glsl330", "330 core"),
    "glsl450": Target("glsl450", "450", vulkan=True),
    "essl300": Target("essl300", "300 es", es=True),
}

# HLSL (shader model 5.0) and MSL (2.0), translated from glsl450 through SPIR-V by
# matedit.interop.cross (needs glslang-tools, spirv-tools and spirv-cross).
CROSS_TARGETS = ("hlsl", "msl")
