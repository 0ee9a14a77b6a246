// Image-based lighting: the split-sum approximation (prefiltered environment times the
// environment BRDF), order-2 spherical-harmonic irradiance for the diffuse, and the
// importance-sampled reference that estimates the full integral without the split.
// Functions take their textures as arguments; ibl_inputs.glsl declares the renderer's.
#include "common.glsl"
#include "brdf.glsl"
#include "sampling.glsl"
#include "env_sampling.glsl"

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

// --- Reference with multiple importance sampling -------------------------------------------
// The reflected radiance integral of the full BRDF over the environment, estimated with two
// strategies a sample: a direction from the BRDF (a one-sample mixture of the cosine lobe
// and GGX) and one from the environment's luminance distribution (env_sampling.glsl),
// combined by the balance heuristic (Veach 1997). The BRDF is behind the three functions
// below and their struct, so further lobes only extend those.

// The surface the reference integrates: normal, view, Lambert albedo, specular F0,
// perceptual roughness and a scale of the specular (energy compensation).
struct ReferenceSurface {
    vec3 N;
    vec3 V;
    vec3 diffuseColor;
    vec3 F0;
    float roughness;
    vec3 specularScale;
};

ReferenceSurface makeReferenceSurface(vec3 N, vec3 V, vec3 diffuseColor, vec3 F0,
                                      float roughness, vec3 specularScale) {
    // matedit reference mode: the BRDF's inputs in one struct
    ReferenceSurface s;
    s.N = N;
    s.V = V;
    s.diffuseColor = diffuseColor;
    s.F0 = F0;
    s.roughness = roughness;
    s.specularScale = specularScale;
    return s;
}

// alpha of the reference's GGX: roughness^2, at least 1e-3 (a mirror's delta lobe is
// approximated by a lobe of about 0.06 degrees, narrower than an environment texel).
float referenceAlpha(ReferenceSurface s) {
    // Karis 2013, "Real Shading in Unreal Engine 4": alpha = roughness^2
    return max(s.roughness * s.roughness, 1e-3);
}

// Probability of drawing the GGX lobe rather than the cosine lobe: the lobes' estimated
// weights, luminance of F(NoV) times the specular scale against the diffuse albedo.
float referenceSpecularChance(ReferenceSurface s) {
    // one-sample model of Veach 1997: choose a lobe by its approximate share of the energy
    float NoV = saturate(dot(s.N, s.V));
    const vec3 Y = vec3(0.2126, 0.7152, 0.0722);
    float spec = dot(F_SchlickExact(s.F0, NoV) * s.specularScale, Y);
    float diff = dot(s.diffuseColor, Y);
    float total = spec + diff;
    return total > 0.0 ? saturate(spec / total) : 0.5;
}

// f(l, v) N.l of the whole BRDF towards the unit direction L: Lambert plus D Vis F with
// Schlick-Smith k = alpha / 2 and the exact Schlick Fresnel, as referenceSpecularIBL.
vec3 referenceBrdfCosine(ReferenceSurface s, vec3 L) {
    // Karis 2013, "Real Shading in Unreal Engine 4": c_diff / pi + D G F / (4 NoL NoV), k = a/2
    float NoL = dot(s.N, L);
    if (NoL <= 0.0) return vec3(0.0);
    vec3 h = L + s.V;
    float hh = dot(h, h);
    vec3 diffuse = s.diffuseColor * (INV_PI * NoL);
    if (hh < 1e-12) return diffuse;
    vec3 H = h * inversesqrt(hh);
    // V below the shading horizon (normal maps): no specular where GGX sampling cannot
    // reach (V.H <= 0, or a half vector below the surface, N.H <= 0, where D is 0 and the
    // cross-product form of D would not be), which above the horizon never happens
    float VoH = dot(s.V, H);
    float NoH = dot(s.N, H);
    if (VoH <= 0.0 || NoH <= 0.0) return diffuse;
    float a = referenceAlpha(s);
    float NoV = max(dot(s.N, s.V), 1e-4);
    vec3 NxH = cross(s.N, H);
    float D = D_GGX(NoH, a, dot(NxH, NxH));
    float Vis = V_SchlickSmith(NoV, NoL, k_IBL(a));
    return diffuse + (D * Vis * NoL) * F_SchlickExact(s.F0, VoH) * s.specularScale;
}

// Solid-angle density of L under the reference's GGX half-vector sampling, D NoH / (4 VoH)
// (Walter et al. 2007); 0 where L + V vanishes or V.H <= 0.
float referenceGgxPdf(ReferenceSurface s, vec3 L) {
    // Walter et al. 2007 (brdf.glsl)
    return ggxReflectionPdf(s.N, s.V, L, referenceAlpha(s));
}

// A direction from the reference's GGX lobe for the point Xi (may lie below the horizon).
vec3 referenceGgxSample(ReferenceSurface s, vec2 Xi) {
    // Karis 2013, ImportanceSampleGGX, then L = 2 (V.H) H - V
    vec3 H = importanceSampleGGX(Xi, referenceAlpha(s), s.N);
    return 2.0 * dot(s.V, H) * H - s.V;
}

// Solid-angle density of L under referenceBrdfSample: the mixture of NoL / pi and the GGX
// half-vector density.
float referenceBrdfPdf(ReferenceSurface s, vec3 L) {
    // the one-sample mixture's density: (1 - c) p_cos + c p_ggx
    float c = referenceSpecularChance(s);
    float cosine = max(dot(s.N, L), 0.0) * INV_PI;
    return (1.0 - c) * cosine + c * referenceGgxPdf(s, L);
}

// A direction drawn from the BRDF for the uniform point Xi (may lie below the horizon);
// `pdf` receives referenceBrdfPdf of it, or 0 for a failed GGX draw: one whose half vector
// has V.H < 0 (V below a mapped normal's horizon), whose L the GGX density does not count
// as drawn (its own half vector is the opposite one). Weighted by the cosine lobe's
// density alone it would be a firefly and a bias; dropped, the estimator stays unbiased.
vec3 referenceBrdfSample(ReferenceSurface s, vec2 Xi, out float pdf) {
    // Xi.x picks the lobe and is stretched back to [0, 1) for it (Veach 1997, 9.2.4)
    float c = referenceSpecularChance(s);
    vec3 L;
    bool specular = Xi.x < c;
    if (specular) {
        vec2 X = vec2(min(Xi.x / c, 0.99999994), Xi.y);
        L = referenceGgxSample(s, X);
    } else {
        vec2 X = vec2(min((Xi.x - c) / (1.0 - c), 0.99999994), Xi.y);
        L = importanceSampleCosine(X, s.N);
    }
    pdf = (!specular || referenceGgxPdf(s, L) > 0.0) ? referenceBrdfPdf(s, L) : 0.0;
    return L;
}

// The environment sample's point of a pair: the Hammersley point swapped and shifted, so
// that the two strategies' samples are not aligned.
vec2 environmentSamplePoint(vec2 Xi) {
    // Cranley-Patterson rotation of the swapped point
    return fract(Xi.yx + vec2(0.5, 0.25));
}

// Full reference (diffuse and specular) of the environment `env` with its distribution
// `dist`: per sample, one BRDF and one environment direction, balance heuristic.
vec3 referenceEnvironmentIBL(samplerCube env, sampler2D dist, ReferenceSurface s,
                             uint sampleCount, vec2 offset) {
    // Veach 1997, "Robust Monte Carlo Methods for Light Transport Simulation", ch. 9:
    // sum over strategies of f L / (p_brdf + p_env), one sample of each
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < sampleCount; i++) {
        vec2 Xi = rotatedHammersley(i, sampleCount, offset);
        float pb;
        vec3 Lb = referenceBrdfSample(s, Xi, pb);
        if (pb > 0.0 && dot(s.N, Lb) > 0.0) {
            vec3 f = referenceBrdfCosine(s, Lb);
            sum += f * textureLod(env, Lb, 0.0).rgb / (pb + environmentPdf(dist, Lb));
        }
        float pe;
        vec3 Le = sampleEnvironmentDirection(dist, environmentSamplePoint(Xi), pe);
        if (pe > 0.0 && dot(s.N, Le) > 0.0) {
            vec3 f = referenceBrdfCosine(s, Le);
            sum += f * textureLod(env, Le, 0.0).rgb / (pe + referenceBrdfPdf(s, Le));
        }
    }
    return sum / float(sampleCount);
}
