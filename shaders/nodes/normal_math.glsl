// Helpers shared by the normal and layer nodes (not a node kind).

// v / |v|, or `fallback` where v is zero (a NaN normal would poison the shading).
vec3 nodeSafeNormalize(vec3 v, vec3 fallback) {
    // GLSL normalize, as v * inversesqrt(dot(v, v)), with the zero vector guarded
    float len2 = dot(v, v);
    return len2 > 0.0 ? v * inversesqrt(len2) : fallback;
}
