// Panner node: uv scrolled over time.
#include "context.glsl"

void node_panner(vec2 uv, vec2 speed, out vec2 result) {
    // UE4 Panner: uv + speed * time
    result = uv + speed * g_surface.time;
}
