// Flatten Normal node: moves a tangent-space normal towards (0, 0, 1).
#include "normal_math.glsl"

void node_flatten_normal(vec3 normal, float flatness, out vec3 result) {
    // Normalised linear interpolation (nlerp) towards the unperturbed normal (0, 0, 1)
    vec3 n = mix(normal, vec3(0.0, 0.0, 1.0), flatness);
    result = nodeSafeNormalize(n, vec3(0.0, 0.0, 1.0));
}
