// World Normal node: the interpolated geometric normal, before any normal map.
#include "context.glsl"

void node_world_normal(out vec3 normal) {
    // Read from the SurfaceContext the generated main() fills
    normal = g_surface.normal;
}
