// Fresnel node: Schlick's approximation on the geometric normal.
#include "context.glsl"

void node_fresnel(float base, float exponent, out float value) {
    // Schlick 1994: F0 + (1 - F0)(1 - N.V)^exponent
    float nov = clamp(dot(g_surface.normal, g_surface.view), 0.0, 1.0);
    value = base + (1.0 - base) * pow(1.0 - nov, max(exponent, 1e-4));
}
