// Blend: multiply node, mixed over base by opacity.

void node_blend_multiply(vec3 base, vec3 blend, float opacity, out vec3 result) {
    // Porter & Duff 1984 / W3C Compositing Level 1: multiply, a b
    vec3 a = base;
    vec3 b = blend;
    vec3 r = a * b;
    result = mix(a, r, opacity);
}
