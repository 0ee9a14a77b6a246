// Height Mask node: a ramp along the up axis in world space.
#include "context.glsl"

void node_height_mask(vec3 up, float low, float high, out float mask) {
    // Hermite ramp of the height (world position . up) from low to high
    float h = dot(g_surface.position, up * inversesqrt(max(dot(up, up), 1e-12)));
    float t = high > low + 1e-6 ? clamp((h - low) / (high - low), 0.0, 1.0) : step(low, h);
    mask = t * t * (3.0 - 2.0 * t);
}
