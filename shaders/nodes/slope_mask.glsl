// Slope Mask node: where the surface faces up.
#include "context.glsl"

void node_slope_mask(vec3 up, float threshold, float softness, out float mask) {
    // Smooth threshold of the cosine between the world normal and up
    float d = dot(g_surface.normal, up * inversesqrt(max(dot(up, up), 1e-12)));
    float s = max(softness, 1e-4);
    mask = smoothstep(threshold - s, threshold + s, d);
}
