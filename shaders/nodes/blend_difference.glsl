// Blend: difference node, mixed over base by opacity.

void node_blend_difference(vec3 base, vec3 blend, float opacity, out vec3 result) {
    // W3C Compositing Level 1: difference, |a - b|
    vec3 a = base;
    vec3 b = blend;
    vec3 r = abs(a - b);
    result = mix(a, r, opacity);
}
