// The scene's analytic lights as one std140 uniform block, and its unpacking into Light.
//
// std140 layout of block `LightsBlock` (instance `uLights`), MATEDIT_MAX_LIGHTS = 16 by default,
// 16 + 64 * MATEDIT_MAX_LIGHTS bytes (1040), every field float32 unless said otherwise:
//   offset  0: ivec4 count             x = number of lights in use (int32), y, z, w = 0
//   offset 16 + 64 i, light i, four vec4:
//     +0  positionType        xyz = position (m), w = type (0 point, 1 directional, 2 sphere, 3 tube)
//     +16 colorIntensity      rgb = linear colour, w = intensity
//     +32 directionInfluence  xyz = direction (directional: travel direction; tube: unit axis),
//                             w = influence radius R (m)
//     +48 shape               x = source radius (m), y = source length (m), z, w = 0
// matedit.shading.lights_block.pack_lights writes exactly these bytes (matedit/glsl/layout.py's
// LIGHTS_BLOCK, from which the packer takes its offsets).
#include "lights.glsl"

#include "bindings.glsl"
// MATEDIT_MAX_LIGHTS and the binding point MATEDIT_LIGHTS_BINDING (Vulkan: descriptor binding in
// set 0) come from matedit/glsl/layout.py, the source of the packer's offsets too.
#include "layout.glsl"

struct LightData {
    vec4 positionType;
    vec4 colorIntensity;
    vec4 directionInfluence;
    vec4 shape;
};

MATEDIT_UBO(MATEDIT_LIGHTS_BINDING) uniform LightsBlock {
    ivec4 count;
    LightData light[MATEDIT_MAX_LIGHTS];
} uLights;

int lightCount() {
    // matedit lights block layout (above)
    return min(uLights.count.x, MATEDIT_MAX_LIGHTS);
}

Light getLight(int i) {
    // matedit lights block layout (above): four vec4 per light
    LightData data = uLights.light[i];
    Light light;
    light.type = int(data.positionType.w + 0.5);
    light.position = data.positionType.xyz;
    light.color = data.colorIntensity.rgb;
    light.intensity = data.colorIntensity.w;
    light.direction = data.directionInfluence.xyz;
    light.influenceRadius = data.directionInfluence.w;
    light.sourceRadius = data.shape.x;
    light.sourceLength = data.shape.y;
    return light;
}
