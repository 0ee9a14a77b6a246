// Facing Ratio node.
#include "context.glsl"

void node_facing_ratio(out float value) {
    // N . V clamped to [0, 1]
    value = clamp(dot(g_surface.normal, g_surface.view), 0.0, 1.0);
}
