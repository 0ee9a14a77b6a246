// Blend: soft_light node, mixed over base by opacity.

void node_blend_soft_light(vec3 base, vec3 blend, float opacity, out vec3 result) {
    // W3C Compositing Level 1: soft-light, with D(a) the quartic below 1/4, sqrt above
    vec3 a = clamp(base, 0.0, 1.0);
    vec3 b = blend;
    vec3 d = mix(sqrt(a), ((16.0 * a - 12.0) * a + 4.0) * a, vec3(lessThanEqual(a, vec3(0.25))));
    vec3 dark = a - (1.0 - 2.0 * b) * a * (1.0 - a);
    vec3 light = a + (2.0 * b - 1.0) * (d - a);
    vec3 r = mix(light, dark, vec3(lessThanEqual(b, vec3(0.5))));
    result = mix(base, r, opacity);
}
