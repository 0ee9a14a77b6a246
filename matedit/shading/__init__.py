"""numpy twin of the GLSL shading library in ``shaders/`` (numpy only: no Qt, no OpenGL).

Naming rule: every function here carries **exactly the name of its GLSL twin**
(``D_GGX``, ``F_Schlick``, ``importanceSampleGGX``, ``shadeSurface``), so a grep finds
both sides; one module per GLSL file (``brdf.py`` mirrors ``brdf.glsl``). Helpers that
exist only on the Python side (packers, dataclasses, SH projection) use snake_case.

Conventions: inputs broadcast against each other; vectors carry their components on
the last axis (``(..., 3)``), scalars have no component axis; everything is computed in
float64 (inputs are converted). Where the GLSL takes a texture, the twin takes a
callable or an array, as documented on the function.
"""

from matedit.shading.brdf import (
    D_GGX,
    F_Schlick,
    F_SchlickExact,
    Fc_Exact,
    Fc_SphericalGaussian,
    Fd_Lambert,
    G1_Schlick,
    V_SchlickSmith,
    diffuseLobe,
    k_Analytic,
    k_IBL,
    specularLobe,
)
from matedit.shading.lights import Light
from matedit.shading.lights_block import LIGHTS_BLOCK_SIZE, MAX_LIGHTS, pack_lights
from matedit.shading.material import MaterialAttributes, defaultMaterialAttributes
from matedit.shading.surface import IblInputs, shadeSurface

__all__ = [
    "D_GGX",
    "F_Schlick",
    "F_SchlickExact",
    "Fc_Exact",
    "Fc_SphericalGaussian",
    "Fd_Lambert",
    "G1_Schlick",
    "IblInputs",
    "LIGHTS_BLOCK_SIZE",
    "Light",
    "MAX_LIGHTS",
    "MaterialAttributes",
    "V_SchlickSmith",
    "defaultMaterialAttributes",
    "diffuseLobe",
    "k_Analytic",
    "k_IBL",
    "pack_lights",
    "shadeSurface",
    "specularLobe",
]
