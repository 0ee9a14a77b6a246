// Curvature node: mean curvature from screen-space derivatives of the normal.
#include "context.glsl"

void node_curvature(float scale, out float curvature, out float convex, out float concave) {
    // Normal change per unit length along the two screen directions, dN.dP / dP.dP,
    // averaged (a mean-curvature estimate, positive where convex), in 1/m
    vec3 dndx = dFdx(g_surface.normal);
    vec3 dndy = dFdy(g_surface.normal);
    vec3 dpdx = dFdx(g_surface.position);
    vec3 dpdy = dFdy(g_surface.position);
    float kx = dot(dndx, dpdx) / max(dot(dpdx, dpdx), 1e-12);
    float ky = dot(dndy, dpdy) / max(dot(dpdy, dpdy), 1e-12);
    curvature = 0.5 * (kx + ky);
    convex = clamp(curvature * scale, 0.0, 1.0);
    concave = clamp(-curvature * scale, 0.0, 1.0);
}
