// Image-based lighting: the split-sum approximation (prefiltered environment times the
// environment BRDF), order-2 spherical-harmonic irradiance for the diffuse, and the
// importance-sampled reference that estimates the full integral without the split.
// Functions take their textures as arguments; ibl_inputs.glsl declares the renderer's.
#include "common.glsl"
#include "brdf.glsl"
#include "sampling.glsl"

// Radiance of the environment prefiltered for this roughness, around the reflection vector.
vec3 prefilteredRadiance(samplerCube prefilteredEnv, vec3 R, float roughness, float mipCount) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 7: mip m of M holds roughness m / (M - 1)
    return textureLod(prefilteredEnv, R, roughness * (mipCount - 1.0)).rgb;
}

// Environment BRDF scale A and bias B, so that the specular is prefiltered * (F0 A + B).
vec2 environmentBRDF(sampler2D brdfLut, float NoV, float roughness) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 8: LUT over (NoV, roughness), A in R, B in G
    return texture(brdfLut, vec2(NoV, roughness)).rg;
}

// Split-sum specular from an already fetched prefiltered radiance and (A, B).
vec3 splitSumSpecular(vec3 prefiltered, vec2 envBRDF, vec3 F0) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 6-8: L_pref (F0 A + B)
    return prefiltered * (F0 * envBRDF.x + envBRDF.y);
}

// Multiple-scattering energy compensation from the environment BRDF: the specular's scale
// (single + multiple scattering over single) and what is left for the diffuse.
void energyCompensation(vec3 F0, vec2 envBRDF, out vec3 specularScale, out vec3 diffuseScale) {
    // Fdez-Aguera 2019, "A Multiple-Scattering Microfacet Model for Real-Time Image-based
    // Lighting": Ess = A + B, Fms = FssEss Favg / (1 - Ems Favg), Favg = F0 + (1 - F0) / 21
    vec3 FssEss = F0 * envBRDF.x + envBRDF.y;
    float Ess = envBRDF.x + envBRDF.y;
    float Ems = 1.0 - Ess;
    vec3 Favg = F0 + (1.0 - F0) / 21.0;
    vec3 Fms = FssEss * Favg / max(1.0 - Ems * Favg, vec3(1e-4));
    vec3 total = FssEss + Fms * Ems;
    specularScale = 1.0 + Fms * Ems / max(FssEss, vec3(1e-6));
    diffuseScale = saturate(1.0 - total);
}

// Irradiance E(N) from 9 SH coefficients of the radiance (order L00, L1-1, L10, L11,
// L2-2, L2-1, L20, L21, L22). A constant environment L gives E = pi L.
vec3 irradianceSH9(vec3 sh[9], vec3 N) {
    // Ramamoorthi and Hanrahan 2001, "An Efficient Representation for Irradiance Environment Maps", eq 13
    const float c1 = 0.429043;
    const float c2 = 0.511664;
    const float c3 = 0.743125;
    const float c4 = 0.886227;
    const float c5 = 0.247708;
    float x = N.x;
    float y = N.y;
    float z = N.z;
    return c1 * sh[8] * (x * x - y * y) + c3 * sh[6] * z * z + c4 * sh[0] - c5 * sh[6]
         + 2.0 * c1 * (sh[4] * x * y + sh[7] * x * z + sh[5] * y * z)
         + 2.0 * c2 * (sh[3] * x + sh[1] * y + sh[2] * z);
}

// Lambert diffuse under the SH environment: diffuseColor E(N) / pi.
vec3 diffuseIrradianceSH9(vec3 sh[9], vec3 N, vec3 diffuseColor) {
    // Karis 2013, "Real Shading in Unreal Engine 4", diffuse IBL: Lambert times irradiance
    return diffuseColor * irradianceSH9(sh, N) * INV_PI;
}

// Importance-sampled estimate of the specular integral from the unfiltered environment.
vec3 referenceSpecularIBL(samplerCube env, vec3 F0, float roughness, vec3 N, vec3 V,
                          uint sampleCount, vec2 offset) {
    // Karis 2013, "Real Shading in Unreal Engine 4", SpecularIBL: k = a / 2, exact Fresnel
    float a = roughness * roughness;
    float k = k_IBL(a);
    float NoV = max(dot(N, V), 1e-4);
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < sampleCount; i++) {
        vec2 Xi = rotatedHammersley(i, sampleCount, offset);
        vec3 H = importanceSampleGGX(Xi, a, N);
        vec3 L = 2.0 * dot(V, H) * H - V;
        float NoL = saturate(dot(N, L));
        float NoH = saturate(dot(N, H));
        float VoH = saturate(dot(V, H));
        if (NoL > 0.0) {
            float G = G1_Schlick(NoL, k) * G1_Schlick(NoV, k);
            vec3 F = F_SchlickExact(F0, VoH);
            sum += textureLod(env, L, 0.0).rgb * F * (G * VoH / max(NoH * NoV, 1e-8));
        }
    }
    return sum / float(sampleCount);
}

// Cosine-sampled estimate of the Lambert diffuse from the unfiltered environment.
vec3 referenceDiffuseIBL(samplerCube env, vec3 diffuseColor, vec3 N, uint sampleCount,
                         vec2 offset) {
    // Lambert under pdf = NoL / pi: the estimator is diffuseColor * L(l)
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < sampleCount; i++) {
        vec3 L = importanceSampleCosine(rotatedHammersley(i, sampleCount, offset), N);
        sum += textureLod(env, L, 0.0).rgb;
    }
    return diffuseColor * sum / float(sampleCount);
}

// The talk's importance-sampled reference: diffuse plus specular, no split sum.
vec3 referenceIBL(samplerCube env, vec3 diffuseColor, vec3 F0, float roughness, vec3 N,
                  vec3 V, uint sampleCount, vec2 offset) {
    // Karis 2013, "Real Shading in Unreal Engine 4", image-based lighting: reference
    return referenceDiffuseIBL(env, diffuseColor, N, sampleCount, offset)
         + referenceSpecularIBL(env, F0, roughness, N, V, sampleCount, offset);
}
