// Blend: screen node, mixed over base by opacity.

void node_blend_screen(vec3 base, vec3 blend, float opacity, out vec3 result) {
    // W3C Compositing Level 1: screen, 1 - (1 - a)(1 - b)
    vec3 a = base;
    vec3 b = blend;
    vec3 r = 1.0 - (1.0 - a) * (1.0 - b);
    result = mix(a, r, opacity);
}
