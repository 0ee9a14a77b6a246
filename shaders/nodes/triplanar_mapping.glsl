// Triplanar Mapping node: three planar projections and their weights.
#include "context.glsl"

void node_triplanar_mapping(float scale, float sharpness, out vec2 uv_x, out vec2 uv_y,
                            out vec2 uv_z, out vec3 weights) {
    // Geiss 2007 (GPU Gems 3, ch. 1) triplanar projection: world position projected on
    // the three axis planes, weights |N|^sharpness normalised to sum to 1
    vec3 p = g_surface.position * scale;
    uv_x = p.zy;
    uv_y = p.xz;
    uv_z = p.xy;
    vec3 w = pow(abs(g_surface.normal), vec3(max(sharpness, 1.0)));
    weights = w / max(w.x + w.y + w.z, 1e-6);
}
