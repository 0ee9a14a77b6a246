// Blend: dodge node, mixed over base by opacity.

void node_blend_dodge(vec3 base, vec3 blend, float opacity, out vec3 result) {
    // W3C Compositing Level 1: color-dodge, 0 where a = 0, 1 where b >= 1, else
    // min(1, a / (1 - b))
    vec3 a = base;
    vec3 b = blend;
    vec3 q = min(vec3(1.0), a / max(1.0 - b, 1e-6));
    vec3 r = mix(q, vec3(1.0), vec3(greaterThanEqual(b, vec3(1.0))));
    r = mix(r, vec3(0.0), vec3(lessThanEqual(a, vec3(0.0))));
    result = mix(a, r, opacity);
}
