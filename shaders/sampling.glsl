// Low-discrepancy points and GGX / cosine importance sampling for the IBL bakes and the reference mode.
#include "common.glsl"

// Radical inverse in base 2 (Van der Corput), by bit reversal; integer ops only so it runs on ES 3.00.
float radicalInverse_VdC(uint bits) {
    // Hacker's Delight bit reversal, as used by Karis 2013 ("Real Shading in UE4", Hammersley)
    bits = (bits << 16u) | (bits >> 16u);
    bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
    bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
    bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
    bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
    return float(bits) * 2.3283064365386963e-10; // / 2^32
}

// Point i of an n-point Hammersley set in [0, 1)^2.
vec2 hammersley(uint i, uint n) {
    // Karis 2013, "Real Shading in Unreal Engine 4", image-based lighting: Hammersley points
    return vec2(float(i) / float(n), radicalInverse_VdC(i));
}

// Point i of the n-point sample set, rotated per frame (Cranley-Patterson) by `offset`.
vec2 rotatedHammersley(uint i, uint n, vec2 offset) {
    // Cranley and Patterson 1976, "Randomization of Number Theoretic Methods": fract(x + u)
    return fract(hammersley(i, n) + offset);
}

// Orthonormal tangent frame around N: the notes' up vector Z, except near +-Z, where the
// notes' X would turn the frame of N = +Z by 90 degrees (T = -Y); Y there gives T = X,
// B = Y, the identity, so a sample's local (x, y, z) is its world direction at N = +Z.
void tangentFrame(vec3 N, out vec3 T, out vec3 B) {
    // Karis 2013, ImportanceSampleGGX: UpVector = abs(N.z) < 0.999 ? Z : X (X replaced by Y)
    vec3 up = abs(N.z) < 0.999 ? vec3(0.0, 0.0, 1.0) : vec3(0.0, 1.0, 0.0);
    T = normalize(cross(up, N));
    B = cross(N, T);
}

// GGX half vector around N for a uniform point Xi; `a` is alpha = roughness².
vec3 importanceSampleGGX(vec2 Xi, float a, vec3 N) {
    // Karis 2013, "Real Shading in Unreal Engine 4", ImportanceSampleGGX
    // 1 + (a^2 - 1) y is summed as (1 - y) + a^2 y, and sin^2 = a^2 y / that, exactly:
    // no cancellation when y -> 1 or the lobe is narrow (float32 keeps ~1e-7 relative).
    float phi = 2.0 * PI * Xi.x;
    float a2y = a * a * Xi.y;
    float denom = max((1.0 - Xi.y) + a2y, 1e-30);
    float cosTheta = sqrt((1.0 - Xi.y) / denom);
    float sinTheta = sqrt(a2y / denom);
    vec3 H = vec3(sinTheta * cos(phi), sinTheta * sin(phi), cosTheta);
    vec3 T;
    vec3 B;
    tangentFrame(N, T, B);
    return T * H.x + B * H.y + N * H.z;
}

// Cosine-weighted direction around N (pdf = NoL / PI).
vec3 importanceSampleCosine(vec2 Xi, vec3 N) {
    // Malley's method: uniform disk point lifted to the hemisphere
    float phi = 2.0 * PI * Xi.x;
    float r = sqrt(Xi.y);
    vec3 L = vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - Xi.y)));
    vec3 T;
    vec3 B;
    tangentFrame(N, T, B);
    return T * L.x + B * L.y + N * L.z;
}
