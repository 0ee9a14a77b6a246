// BRDF terms of the UE4 shading model: Lambert diffuse, GGX distribution,
// Schlick-Smith visibility and Schlick Fresnel, then a small dispatch so the
// light code never names a formula. `roughness` is perceptual, `a` is alpha.
#include "common.glsl"

// Widening of the highlight by a sphere or tube light: a' = a + sourceRadius / (DIVISOR d).
// 2: the form most public implementations of the notes use (a + 0.5 * sourceRadius / d);
// measured within 0.78 .. 1.20 of the true specular energy for r/d <= 0.25 at roughness >= 0.2
// (benchmarks/LIGHTS_ENERGY.md), where 3 (docs/shading.md's earlier reading) reaches x2.15.
#ifndef MATEDIT_AREA_WIDEN_DIVISOR
#define MATEDIT_AREA_WIDEN_DIVISOR 2.0
#endif

// Lambert diffuse lobe without the albedo: multiply by diffuseColor.
float Fd_Lambert() {
    // Karis 2013, "Real Shading in Unreal Engine 4", diffuse BRDF: Lambert, c_diff / pi
    return INV_PI;
}

// GGX / Trowbridge-Reitz normal distribution, alpha = roughness^2.
float D_GGX(float NoH, float a) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 3 (GGX, Trowbridge-Reitz)
    // 1 - NoH^2 (1 - a^2) written as (1 - NoH)(1 + NoH) + NoH^2 a^2: no cancellation near NoH = 1.
    float a2 = a * a;
    float d = (1.0 - NoH) * (1.0 + NoH) + NoH * NoH * a2;
    return a2 / (PI * d * d);
}

// GGX with 1 - NoH^2 given, as |N x H|^2 from the vectors: accurate where H is near N and
// the lobe is narrow (1 - NoH^2 from a rounded NoH loses everything at a ~ 1e-3).
float D_GGX(float NoH, float a, float oneMinusNoH2) {
    // Karis 2013, eq 3; Filament's cross-product form of 1 - NoH^2 (Lagrange's identity)
    float a2 = a * a;
    float d = oneMinusNoH2 + NoH * NoH * a2;
    return a2 / (PI * d * d);
}

// The half vector of a reflection density: H = normalize(L + V), V.H, N.H (saturated) and
// |N x H|^2, shared by the isotropic and anisotropic GGX densities (anisotropy.glsl); false
// where L + V vanishes or V.H <= 0 (no density there: GGX sampling cannot reach L).
bool reflectionHalfVector(vec3 N, vec3 V, vec3 L, out vec3 H, out float VoH, out float NoH,
                          out float oneMinusNoH2) {
    // Walter et al. 2007, "Microfacet Models for Refraction", eq 13 (h_r) and 14
    vec3 h = L + V;
    float hh = dot(h, h);
    H = vec3(0.0);
    VoH = 0.0;
    NoH = 0.0;
    oneMinusNoH2 = 0.0;
    if (hh < 1e-12) return false;
    H = h * inversesqrt(hh);
    VoH = dot(V, H);
    if (VoH <= 0.0) return false;
    NoH = saturate(dot(N, H));
    vec3 NxH = cross(N, H);
    oneMinusNoH2 = dot(NxH, NxH);
    return true;
}

// Solid-angle density of L under GGX half-vector sampling around N with alpha a,
// D NoH / (4 VoH); 0 where L + V vanishes or V.H <= 0 (the reference mode's estimators).
float ggxReflectionPdf(vec3 N, vec3 V, vec3 L, float a) {
    // Walter et al. 2007, "Microfacet Models for Refraction", eq 14 and 38
    vec3 H;
    float VoH, NoH, oneMinusNoH2;
    if (!reflectionHalfVector(N, V, L, H, VoH, NoH, oneMinusNoH2)) return 0.0;
    return D_GGX(NoH, a, oneMinusNoH2) * NoH / (4.0 * VoH);
}

// Schlick's k for analytic lights: Disney's remapping of roughness.
float k_Analytic(float roughness) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 4: k = (roughness + 1)^2 / 8
    float r = roughness + 1.0;
    return r * r * 0.125;
}

// Schlick's k for image-based lighting (no remapping).
float k_IBL(float a) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 4 note: k = alpha / 2 for IBL
    return 0.5 * a;
}

// Schlick-Smith G1 for one direction.
float G1_Schlick(float NoX, float k) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 4: G1(x) = x / (x (1 - k) + k)
    return NoX / (NoX * (1.0 - k) + k);
}

// Visibility Vis = G / (4 NoL NoV) with the NoL NoV folded out analytically.
float V_SchlickSmith(float NoV, float NoL, float k) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 4, G / (4 NoL NoV) simplified
    float gv = NoV * (1.0 - k) + k;
    float gl = NoL * (1.0 - k) + k;
    return 0.25 / (gv * gl);
}

// Schlick's Fresnel weight, spherical-Gaussian approximation of (1 - VoH)^5.
float Fc_SphericalGaussian(float VoH) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 5: 2^((-5.55473 VoH - 6.98316) VoH)
    return exp2((-5.55473 * VoH - 6.98316) * VoH);
}

// Schlick's Fresnel weight, exact fifth power.
float Fc_Exact(float VoH) {
    // Schlick 1994, "An Inexpensive BRDF Model for Physically-based Rendering": (1 - VoH)^5
    return pow5(1.0 - VoH);
}

// Schlick Fresnel for analytic lights (spherical-Gaussian weight).
vec3 F_Schlick(vec3 F0, float VoH) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 5: F0 + (1 - F0) Fc
    return F0 + (1.0 - F0) * Fc_SphericalGaussian(VoH);
}

// Schlick Fresnel with the exact fifth power (IBL integration, reference mode).
vec3 F_SchlickExact(vec3 F0, float VoH) {
    // Schlick 1994, as used by Karis 2013 IntegrateBRDF / SpecularIBL: exact (1 - VoH)^5
    return F0 + (1.0 - F0) * Fc_Exact(VoH);
}

// Specular lobe D * Vis * F for an analytic light; caller multiplies by NoL.
vec3 specularLobe(vec3 F0, float a, float k, float NoV, float NoL, float NoH, float VoH) {
    // Karis 2013, "Real Shading in Unreal Engine 4", specular BRDF D F G / (4 NoL NoV)
    return D_GGX(NoH, a) * V_SchlickSmith(NoV, NoL, k) * F_Schlick(F0, VoH);
}

// Diffuse lobe for an analytic light; caller multiplies by NoL.
vec3 diffuseLobe(vec3 diffuseColor) {
    // Karis 2013, "Real Shading in Unreal Engine 4", diffuse BRDF: Lambert
    return diffuseColor * Fd_Lambert();
}
