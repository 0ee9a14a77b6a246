// World Position node: the shaded point in world space, metres.
#include "context.glsl"

void node_world_position(out vec3 position) {
    // Read from the SurfaceContext the generated main() fills
    position = g_surface.position;
}
