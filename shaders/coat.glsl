// Clear coat (issue 23, beyond the talk): a second, colourless GGX lobe on top of the base,
// with its own normal and roughness and an F0 from its IOR, and the base seen through it.
// The layering is Filament's clear coat (the base scaled by what the coat's Fresnel lets
// through) applied in both directions, view and light, with OpenPBR's coat colour as a
// transmittance tint; docs/shading.md, "Clear coat", gives the formulas and the choices.
// Everything is compiled only where the graph writes the coat (MATERIAL_HAS_COAT).
#include "common.glsl"
#include "brdf.glsl"
#include "sampling.glsl"
#include "ibl.glsl"

#if defined(MATERIAL_HAS_COAT)

// What the coat's lobe needs to know about the point being shaded.
struct CoatContext {
    vec3 N;           // unit coat normal (the geometric normal, or m.coatNormal in its frame)
    float NoV;        // saturated, clamped away from 0
    float weight;     // m.coat in [0, 1]: how much of the surface is coated
    float roughness;  // perceptual, saturated: what the image-based light reads
    float a;          // alpha for analytic lights, from the clamped roughness
    float k;          // Schlick-Smith k for analytic lights
    float F0;         // the coat's reflectance at normal incidence, from its IOR
    vec3 tint;        // transmittance tint of the coat, mix(1, coatColor, weight)
    float scale;      // 1, or 0 where a lobe view hides the coat (lobeOn(LOBE_COAT))
};

// Reflectance at normal incidence of a dielectric coat of index n under air.
float coatF0FromIor(float ior) {
    // Fresnel at normal incidence, ((n - 1) / (n + 1))^2; glTF KHR_materials_clearcoat
    // fixes n = 1.5 (F0 = 0.04), OpenPBR's coat_ior makes it a parameter
    float r = (ior - 1.0) / (ior + 1.0);
    return r * r;
}

// The base's F0 seen from inside the coat: its interface is base | coat, not base | air.
// The base's index relative to air is recovered from F0 by inverting the normal-incidence
// Fresnel, n = (1 + sqrt F0) / (1 - sqrt F0), and F0 recomputed against the coat's index.
// Written in s = sqrt F0 so F0 = 1 (a white metal) stays exactly 1 with no division by 0.
// Metals are treated as dielectrics of that real index (no extinction coefficient): the
// exact dielectric relation of which Filament's f0ClearCoatToSurface is a polynomial fit
// for n = 1.5; it maps 1 to 1 and a dielectric of the coat's index to 0.
vec3 f0UnderCoat(vec3 F0, float coatIor) {
    // Fresnel at normal incidence ((n1 - n2) / (n1 + n2))^2 with n1 = coatIor; Filament
    // Materials documentation, "Clear coat: base layer modification" (same relation)
    vec3 s = sqrt(saturate(F0));
    vec3 num = (1.0 + s) - coatIor * (1.0 - s);
    vec3 den = (1.0 + s) + coatIor * (1.0 - s);
    vec3 r = num / den;
    return r * r;
}

// The coat's parameters at a point; `minRoughness` is the analytic lights' clamp.
CoatContext makeCoatContext(vec3 Nc, vec3 V, float weight, float roughness, float minRoughness,
                            vec3 color, float ior, float scale) {
    // Karis 2013, "Real Shading in Unreal Engine 4": a = roughness^2, k = (roughness + 1)^2 / 8,
    // for the coat's own roughness (glTF KHR_materials_clearcoat: clearcoatRoughness)
    CoatContext c;
    c.N = Nc;
    c.NoV = max(dot(Nc, V), 1e-4);
    c.weight = saturate(weight);
    c.roughness = saturate(roughness);
    float r = clamp(roughness, minRoughness, 1.0);
    c.a = r * r;
    c.k = k_Analytic(r);
    c.F0 = coatF0FromIor(ior);
    c.tint = mix(vec3(1.0), saturate(color), c.weight);
    c.scale = scale;
    return c;
}

// Fraction of light the coat reflects at incidence cos(theta) to its normal, times its weight.
float coatFresnel(CoatContext c, float cosTheta) {
    // Schlick 1994, "An Inexpensive BRDF Model for Physically-based Rendering": F0 + (1 - F0)
    // (1 - cos)^5 (exact power), weighted by the coat as glTF KHR_materials_clearcoat's layering
    return c.weight * (c.F0 + (1.0 - c.F0) * Fc_Exact(saturate(cosTheta)));
}

// What reaches the base and comes back out: the coat's Fresnel transmission towards the eye
// and towards the light, times its tint. NoLc is the light's cosine to the coat normal.
vec3 coatTransmittance(CoatContext c, float NoLc) {
    // Filament Materials documentation, "Clear coat": base scaled by (1 - Fc), here once for
    // V and once for L (Weidlich and Wilkie 2007, "Arbitrarily Layered Micro-Facet Surfaces":
    // the transmitted fraction in each direction); OpenPBR Surface 2024, coat_color tint
    return c.tint * ((1.0 - coatFresnel(c, c.NoV)) * (1.0 - coatFresnel(c, NoLc)));
}

// The coat's specular lobe D Vis F times NoLc towards the unit direction L (colourless).
float coatSpecularTowards(CoatContext c, vec3 V, vec3 L) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 3-5 on the coat's normal and alpha;
    // Filament Materials documentation, "Clear coat specular BRDF": a second GGX lobe
    float NoL = saturate(dot(c.N, L));
    vec3 h = L + V;  // L = -V: H undefined, nothing reflected (as lights.glsl)
    if (NoL <= 0.0 || dot(h, h) < 1e-12) return 0.0;
    vec3 H = h * inversesqrt(dot(h, h));
    float NoH = saturate(dot(c.N, H));
    float VoH = saturate(dot(V, H));
    vec3 NxH = cross(c.N, H);
    float D = D_GGX(NoH, c.a, dot(NxH, NxH));
    float F = c.F0 + (1.0 - c.F0) * Fc_SphericalGaussian(VoH);
    return D * V_SchlickSmith(c.NoV, NoL, c.k) * F * NoL * c.weight * c.scale;
}

// One punctual light's radiance through the coat: the base's (already times NoL) seen through
// it towards L, plus the coat's own highlight.
vec3 coatLayer(CoatContext c, vec3 V, vec3 L, vec3 base) {
    // Filament Materials documentation, "Clear coat": f = f_base (1 - Fc) + f_coat
    return base * coatTransmittance(c, dot(c.N, L)) + vec3(coatSpecularTowards(c, V, L));
}

// Split-sum image-based light of the coat, and the base's seen through it. The base's light
// comes from every direction; its transmittance takes L as the mirror of V about the coat
// normal (NoL = NoV), the direction its specular mostly comes from.
vec3 coatImageBasedLighting(CoatContext c, vec3 V, vec3 baseIbl, samplerCube prefilteredEnv,
                            sampler2D brdfLut, float mipCount, float intensity) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 6-8 along the coat's reflection
    // vector at its roughness; Filament Materials documentation, "Clear coat IBL"
    vec3 Rc = reflect(-V, c.N);
    vec3 prefiltered = prefilteredRadiance(prefilteredEnv, Rc, c.roughness, mipCount);
    vec2 AB = environmentBRDF(brdfLut, saturate(dot(c.N, V)), c.roughness);
    float coat = (c.F0 * AB.x + AB.y) * c.weight * c.scale;
    return baseIbl * coatTransmittance(c, c.NoV) + prefiltered * (coat * intensity);
}

// --- for the importance-sampled reference of the image-based light -------------------------
// The coat's f NoL, a sampled direction with its density, and the density, with the IBL's
// Schlick-Smith k = a / 2 and the exact Fresnel power (ibl.glsl, referenceSpecularIBL).

// Alpha the reference reads: the coat's roughness squared, kept off 0 so D stays finite.
float coatReferenceAlpha(CoatContext c) {
    // Karis 2013, a = roughness^2; floor 1e-3 (D(1) = 1 / (pi a^2) ~ 3e5, finite in float32)
    return max(c.roughness * c.roughness, 1e-3);
}

// The coat's f(l, v) NoLc towards L for the image-based reference (colourless).
float coatBrdfCosine(CoatContext c, vec3 V, vec3 L) {
    // Karis 2013, "Real Shading in Unreal Engine 4", SpecularIBL: D G F / (4 NoL NoV), k = a / 2
    float NoL = saturate(dot(c.N, L));
    vec3 h = L + V;  // L = -V: H undefined, nothing reflected (as lights.glsl)
    if (NoL <= 0.0 || dot(h, h) < 1e-12) return 0.0;
    vec3 H = h * inversesqrt(dot(h, h));
    float a = coatReferenceAlpha(c);
    float NoH = saturate(dot(c.N, H));
    float VoH = saturate(dot(V, H));
    vec3 NxH = cross(c.N, H);
    float D = D_GGX(NoH, a, dot(NxH, NxH));
    float F = c.F0 + (1.0 - c.F0) * Fc_Exact(VoH);
    return D * V_SchlickSmith(c.NoV, NoL, k_IBL(a)) * F * NoL * c.weight * c.scale;
}

// Solid-angle density of L under the coat's GGX half-vector sampling.
float coatPdf(CoatContext c, vec3 V, vec3 L) {
    // Walter et al. 2007, "Microfacet Models for Refraction": p(l) = D(h) NoH / (4 VoH)
    vec3 h = L + V;
    float hh = dot(h, h);
    if (hh < 1e-12) return 0.0;
    vec3 H = h * inversesqrt(hh);
    float VoH = dot(V, H);
    if (VoH <= 0.0) return 0.0;
    float NoH = saturate(dot(c.N, H));
    vec3 NxH = cross(c.N, H);
    return D_GGX(NoH, coatReferenceAlpha(c), dot(NxH, NxH)) * NoH / (4.0 * VoH);
}

// A direction sampled from the coat's GGX lobe for the point Xi, and its density.
vec3 coatSampleDirection(CoatContext c, vec3 V, vec2 Xi, out float pdf) {
    // Karis 2013, ImportanceSampleGGX on the coat normal, L = 2 (V.H) H - V; Walter et al.
    // 2007, eq 14 and 38 for the density
    vec3 H = importanceSampleGGX(Xi, coatReferenceAlpha(c), c.N);
    vec3 L = 2.0 * dot(V, H) * H - V;
    pdf = coatPdf(c, V, L);
    return L;
}

#endif
