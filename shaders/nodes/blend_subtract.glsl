// Blend: subtract node, mixed over base by opacity.

void node_blend_subtract(vec3 base, vec3 blend, float opacity, out vec3 result) {
    // Linear subtract: a - b
    vec3 a = base;
    vec3 b = blend;
    vec3 r = a - b;
    result = mix(a, r, opacity);
}
