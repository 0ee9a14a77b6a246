// Blend: lighten node, mixed over base by opacity.

void node_blend_lighten(vec3 base, vec3 blend, float opacity, out vec3 result) {
    // W3C Compositing Level 1: lighten, max(a, b)
    vec3 a = base;
    vec3 b = blend;
    vec3 r = max(a, b);
    result = mix(a, r, opacity);
}
