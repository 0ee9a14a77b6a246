// Unpack Normal node: a normal-map texel in [0, 1] to a unit tangent-space normal
// (OpenGL convention: +Y is up the texture, i.e. towards +v).
#include "normal_math.glsl"

void node_unpack_normal(vec3 packedNormal, float strength, out vec3 normal) {
    // The usual normal-map encoding c = n / 2 + 1/2, inverted; strength scales the slope
    // (xy) before renormalising, so 0 gives the flat normal and 2 doubles the bumps
    vec3 n = packedNormal * 2.0 - 1.0;
    n.xy *= strength;
    normal = nodeSafeNormalize(n, vec3(0.0, 0.0, 1.0));
}
