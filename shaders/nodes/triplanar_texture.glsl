// Triplanar Texture node: a texture by triplanar projection.
#include "context.glsl"

void node_triplanar_texture(sampler2D tex, float scale, float sharpness, out vec4 rgba,
                            out vec3 rgb) {
    // Geiss 2007 (GPU Gems 3, ch. 1): three planar lookups blended by |N|^sharpness
    vec3 p = g_surface.position * scale;
    vec3 w = pow(abs(g_surface.normal), vec3(max(sharpness, 1.0)));
    w /= max(w.x + w.y + w.z, 1e-6);
    rgba = texture(tex, p.zy) * w.x + texture(tex, p.xz) * w.y + texture(tex, p.xy) * w.z;
    rgb = rgba.rgb;
}
