// Normal Strength node.

void node_normal_strength(vec3 normal, float strength, out vec3 result) {
    // Scale the tangent-space tilt (x, y), keep z, renormalise; flat where it vanishes
    vec3 n = vec3(normal.xy * strength, normal.z);
    float len2 = dot(n, n);
    result = len2 > 0.0 ? n * inversesqrt(len2) : vec3(0.0, 0.0, 1.0);
}
