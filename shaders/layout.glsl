// Binding numbers and shared constants of matedit's shaders.
// GENERATED from matedit/glsl/layout.py by `python -m matedit.glsl.layout`:
// edit that file, not this one (tests check that the two agree).
#ifndef MATEDIT_LAYOUT_GLSL
#define MATEDIT_LAYOUT_GLSL
#define MATEDIT_LIGHTS_BINDING 0
#define MATEDIT_IBL_BINDING 1
#define MATEDIT_PREFILTERED_ENV_BINDING 2
#define MATEDIT_BRDF_LUT_BINDING 3
#define MATEDIT_ENVIRONMENT_BINDING 4
#define MATEDIT_FRAME_BINDING 5
#define MATEDIT_MATERIAL_BINDING 6
#define MATEDIT_ENV_DISTRIBUTION_BINDING 7
#define MATEDIT_FIRST_TEXTURE_BINDING 8
#define MATEDIT_ANISOTROPY_LUT_BINDING 31
#ifndef MATEDIT_MAX_LIGHTS
#define MATEDIT_MAX_LIGHTS 16
#endif
#define IBL_MODE_SPLIT_SUM 0
#define IBL_MODE_REFERENCE 1
#define IBL_MODE_NONE 2
// LightsBlock (std140): 1040 bytes; offsets count 0, light 16
// IblBlock (std140): 176 bytes; offsets sh 0, params 144, sampleOffset 160
// FrameBlock (std140): 224 bytes; offsets viewProjection 0, model 64, normalMatrix 128, cameraPosition 192, params 208
#endif
