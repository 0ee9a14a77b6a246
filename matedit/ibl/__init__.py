"""Image-based lighting: environment -> prefiltered cube mips, BRDF LUT, SH irradiance.

Public API (see each module):

    load_environment(path_or_name, size=256) -> Environment      # EnvironmentMapError
    bake(env="studio", BakeSettings(...), ctx=ctx) -> IBLBake    # cached on disk
    bake_brdf_lut(size=128, samples=1024, ctx=ctx) -> np.ndarray # cached on disk
    brdf_lut(size, samples, ctx=ctx, method="quadrature")        # uncached

Baking runs in a moderngl context the caller provides (matedit.render.headless_context,
or the viewport's); a cache hit needs none.
    upload(ctx, ibl_bake) -> IBLTextures                         # moderngl textures
    write_bake(ibl_bake, folder) -> list[Path]                   # EXR + sh.json
    eval_irradiance(sh, normals)                                  # E(N) on the CPU
"""

from matedit.ibl.bake import BakeSettings, IBLBake, bake, bake_brdf_lut
from matedit.ibl.builtin import BUILTIN_NAMES
from matedit.ibl.environment import (
    DEFAULT_ENVIRONMENT,
    Environment,
    EnvironmentMapError,
    load_environment,
)
from matedit.ibl.lut import brdf_lut
from matedit.ibl.output import write_bake, write_lut
from matedit.ibl.sh import eval_irradiance, sh_basis, sh_irradiance
from matedit.ibl.textures import IBLTextures, upload

__all__ = [
    "BUILTIN_NAMES",
    "DEFAULT_ENVIRONMENT",
    "BakeSettings",
    "Environment",
    "EnvironmentMapError",
    "IBLBake",
    "IBLTextures",
    "bake",
    "bake_brdf_lut",
    "brdf_lut",
    "eval_irradiance",
    "load_environment",
    "sh_basis",
    "sh_irradiance",
    "upload",
    "write_bake",
    "write_lut",
]
