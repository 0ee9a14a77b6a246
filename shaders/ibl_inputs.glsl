// Inputs of image-based lighting: environment textures and one std140 uniform block.
//
// Bindings (Vulkan: set 0; in GL the renderer assigns units and block bindings by name):
//   0 LightsBlock (lights_block.glsl), 1 IblBlock, 2 uPrefilteredEnv, 3 uBrdfLut, 4 uEnvironment,
//   7 uEnvDistribution (5 and 6 are the compiler's FrameBlock and MaterialParams),
//   31 uAnisotropyLut (only under MATERIAL_HAS_ANISOTROPY; material textures are 8 and up).
// std140 layout of block `IblBlock` (instance `uIbl`), float32 unless said otherwise:
//   offset   0: vec4 sh[9]   xyz = order-2 SH coefficient of the environment radiance, w = 0;
//                            order L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22 (real SH basis,
//                            Ramamoorthi-Hanrahan 2001); see matedit.shading.ibl.sh9_basis
//   offset 144: vec4 params  x = mip count M of uPrefilteredEnv, y = environment intensity,
//                            z = reference-mode sample count, w = mode (0 split sum, 1 reference,
//                            2 no image-based light)
//   offset 160: vec4 sampleOffset  xy = per-frame offset of the reference sample set,
//                            z = 1: sphere and tube lights by Monte Carlo over their shapes
//                            (lights_reference.glsl; reference mode), else 0; w = 0
// Total 176 bytes. matedit.shading.ibl.pack_ibl_block writes exactly these bytes.

#include "bindings.glsl"
// IBL_MODE_* and the MATEDIT_*_BINDING numbers come from matedit/glsl/layout.py (IBL_BLOCK there
// gives pack_ibl_block its offsets).
#include "layout.glsl"

MATEDIT_UBO(MATEDIT_IBL_BINDING) uniform IblBlock {
    vec4 sh[9];
    vec4 params;
    vec4 sampleOffset;
} uIbl;

MATEDIT_BINDING(MATEDIT_PREFILTERED_ENV_BINDING) uniform samplerCube uPrefilteredEnv;  // GGX-prefiltered, mip m: roughness m/(M-1)
MATEDIT_BINDING(MATEDIT_BRDF_LUT_BINDING) uniform sampler2D uBrdfLut;           // (NoV, roughness) -> (A, B) in (R, G)
MATEDIT_BINDING(MATEDIT_ENVIRONMENT_BINDING) uniform samplerCube uEnvironment;     // unfiltered, for reference mode
MATEDIT_BINDING(MATEDIT_ENV_DISTRIBUTION_BINDING) uniform sampler2D uEnvDistribution;  // luminance CDFs and density (env_sampling.glsl), reference mode
#if defined(MATERIAL_HAS_ANISOTROPY)
// (dA, dB) of the anisotropic lobe's environment BRDF (anisotropicEnvironmentBRDF in
// anisotropy.glsl; matedit/ibl/anisotropy_lut.py): x NoV, y roughness, z slabs of anisotropy
MATEDIT_BINDING(MATEDIT_ANISOTROPY_LUT_BINDING) uniform highp sampler3D uAnisotropyLut;
#endif
