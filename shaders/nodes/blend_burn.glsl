// Blend: burn node, mixed over base by opacity.

void node_blend_burn(vec3 base, vec3 blend, float opacity, out vec3 result) {
    // W3C Compositing Level 1: color-burn, 1 where a >= 1, 0 where b <= 0, else
    // 1 - min(1, (1 - a) / b)
    vec3 a = base;
    vec3 b = blend;
    vec3 q = 1.0 - min(vec3(1.0), (1.0 - a) / max(b, 1e-6));
    vec3 r = mix(q, vec3(0.0), vec3(lessThanEqual(b, vec3(0.0))));
    r = mix(r, vec3(1.0), vec3(greaterThanEqual(a, vec3(1.0))));
    result = mix(a, r, opacity);
}
