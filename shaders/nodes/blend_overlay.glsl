// Blend: overlay node, mixed over base by opacity.

void node_blend_overlay(vec3 base, vec3 blend, float opacity, out vec3 result) {
    // W3C Compositing Level 1: overlay, hard light with base and blend swapped
    vec3 a = base;
    vec3 b = blend;
    vec3 r = mix(2.0 * a * b, 1.0 - 2.0 * (1.0 - a) * (1.0 - b), vec3(greaterThanEqual(a, vec3(0.5))));
    result = mix(a, r, opacity);
}
