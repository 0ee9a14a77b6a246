// Time node: seconds since the preview started.
#include "context.glsl"

void node_time(out float seconds) {
    // Read from the SurfaceContext the generated main() fills
    seconds = g_surface.time;
}
