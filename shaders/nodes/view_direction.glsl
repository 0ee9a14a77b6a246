// View Direction node: unit vector from the surface towards the eye, world space.
#include "context.glsl"

void node_view_direction(out vec3 direction) {
    // Read from the SurfaceContext the generated main() fills
    direction = g_surface.view;
}
