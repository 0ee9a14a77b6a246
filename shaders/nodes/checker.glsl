// Checker node: a two-colour checkerboard, `scale` squares per UV unit, band-limited.
#include "filter_lib.glsl"

void node_checker(vec2 uv, float scale, vec3 color_a, vec3 color_b, float filter_width,
                  out vec3 color, out float mask) {
    // Parity of the integer cell, (floor(u s) + floor(v s)) mod 2, as the product of two
    // square waves; each box-filtered over filter_width pixels (Quilez, "Filtering the
    // checkerboard pattern"): 0 -> color_a, 1 -> color_b
    vec2 p = uv * scale;
    vec2 w = fwidth(p) * filter_width;
    mask = 0.5 - 0.5 * nodeFilteredSquare(p.x, w.x) * nodeFilteredSquare(p.y, w.y);
    color = mix(color_a, color_b, mask);
}
