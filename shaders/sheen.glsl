// The sheen lobe (beyond the talk): the Charlie microfacet distribution of Estevez and
// Kulla with their fitted Smith Lambda for the visibility, the lobe's directional albedo
// E(NoV, roughness) from the blue channel of the environment BRDF LUT (shaders/bake/brdf_lut.frag), the albedo scaling of
// the layer under it (glTF KHR_materials_sheen) and the sheen's split-sum and sampling terms.
// No ShadingContext here: sheen_shading.glsl wires these into the lights and the IBL.
// Functions take their textures as arguments, like ibl.glsl.
#include "common.glsl"
#include "sampling.glsl"

// Smallest perceptual sheen roughness. Below ~0.26 Estevez and Kulla's fitted Lambda lets the
// lobe's directional albedo exceed 1 at grazing views (up to 2.9 at 0.07, 1.15 at 0.2, measured
// by brute force), which the albedo scaling of the base cannot conserve; at 0.3 the albedo stays
// below 0.93 for every NoV (tests/test_lobe_sheen.py). The LUT bake clamps the same way, so
// its low rows equal this one.
const float MIN_SHEEN_ROUGHNESS = 0.3;

// alpha of the sheen from its perceptual roughness, clamped away from 0.
float sheenAlpha(float sheenRoughness) {
    // glTF KHR_materials_sheen: alpha = sheenRoughness^2
    float r = clamp(sheenRoughness, MIN_SHEEN_ROUGHNESS, 1.0);
    return r * r;
}

// Charlie distribution: an inverted-Gaussian-like lobe of sin(theta_h)^(1/alpha), largest for
// half vectors in the tangent plane (fibres seen side-on); its projected area is 1.
// sin^2 is given as 1 - NoH^2 (|N x H|^2 from vectors keeps precision near NoH = 1).
float D_Charlie(float sin2h, float alpha) {
    // Estevez and Kulla 2017, "Production Friendly Microfacet Sheen BRDF", the Charlie
    // distribution (also glTF KHR_materials_sheen): D = (2 + 1 / alpha) sin^(1 / alpha) / (2 pi)
    float invAlpha = 1.0 / alpha;
    return (2.0 + invAlpha) * pow(max(sin2h, 0.0), 0.5 * invAlpha) / (2.0 * PI);
}

// Estevez and Kulla's fitted exponent L(x) of the Charlie lobe's Smith Lambda, its five
// coefficients interpolated between their r = 0 and r = 1 fits by (1 - alpha)^2.
float sheenLambdaFit(float x, float alpha) {
    // Estevez and Kulla 2017, "Production Friendly Microfacet Sheen BRDF", the fitted Lambda:
    // L(x) = a / (1 + b x^c) + d x + e (table of a..e at r = 0 and r = 1)
    float t = sq(1.0 - alpha);
    float a = mix(21.5473, 25.3245, t);
    float b = mix(3.82987, 3.32435, t);
    float c = mix(0.19823, 0.16801, t);
    float d = mix(-1.97760, -1.27393, t);
    float e = mix(-4.32054, -4.85967, t);
    return a / (1.0 + b * pow(x, c)) + d * x + e;
}

// Smith Lambda of the Charlie lobe for a direction of cosine NoX: exp(L) below 0.5, mirrored
// above so that it is smooth and falls to ~0 at normal incidence.
float sheenLambda(float NoX, float alpha) {
    // Estevez and Kulla 2017, "Production Friendly Microfacet Sheen BRDF", fitted Lambda:
    // exp(L(cos)) for cos < 0.5, else exp(2 L(0.5) - L(1 - cos))
    // 1 - NoX saturated: a cosine rounded just above 1 must not reach pow of a negative.
    float mirrored = saturate(1.0 - NoX);
    return NoX < 0.5 ? exp(sheenLambdaFit(NoX, alpha))
                     : exp(2.0 * sheenLambdaFit(0.5, alpha) - sheenLambdaFit(mirrored, alpha));
}

// Visibility of the sheen, G2 / (4 NoL NoV) with the height-correlated Smith G2 of the fitted
// Lambda. Chosen over Neubelt and Pettineo's 1 / (4 (NoL + NoV - NoL NoV)) (Filament's
// cloth) because that one is not a shadowing term: its albedo reaches 1.35 at roughness 0.3 at
// grazing views (tests/test_lobe_sheen.py), which no albedo scaling can conserve; with the
// fitted Lambda it stays below 0.95 for roughness >= 0.3 (MIN_SHEEN_ROUGHNESS). The paper's terminator softening
// (Lambda(NoL)^(1 + 2 (1 - NoL)^8)) is left out: it breaks reciprocity and energy bounds.
float V_Charlie(float NoV, float NoL, float alpha) {
    // Estevez and Kulla 2017, "Production Friendly Microfacet Sheen BRDF":
    // G2 = 1 / (1 + Lambda(NoV) + Lambda(NoL)), V = G2 / (4 NoV NoL)
    return 1.0 / ((1.0 + sheenLambda(NoV, alpha) + sheenLambda(NoL, alpha)) * 4.0 * NoV * NoL);
}

// The sheen BRDF without its colour and without NoL: D V (the lobe has no Fresnel term).
float sheenBRDF(vec3 N, vec3 V, vec3 L, float alpha) {
    // Estevez and Kulla 2017, "Production Friendly Microfacet Sheen BRDF": the microfacet
    // BRDF D G / (4 NoL NoV) with D = Charlie, F = 1 and V = V_Charlie
    float NoL = saturate(dot(N, L));
    if (NoL <= 0.0) return 0.0;
    float NoV = max(dot(N, V), 1e-4);
    vec3 h = L + V;
    vec3 H = h * inversesqrt(max(dot(h, h), 1e-30));
    vec3 NxH = cross(N, H);
    return D_Charlie(dot(NxH, NxH), alpha) * V_Charlie(NoV, NoL, alpha);
}

// The sheen's f NoL towards L with its colour: what a light or a sample contributes.
vec3 sheenBrdfCosine(vec3 N, vec3 V, vec3 L, vec3 sheenColor, float alpha) {
    // glTF KHR_materials_sheen: sheenColor D V, times NoL
    return sheenColor * (sheenBRDF(N, V, L, alpha) * saturate(dot(N, L)));
}

// Directional albedo of the white sheen lobe, E(NoV) = integral of D V NoL over L, and the
// sheen's environment DFG term (the same integral: the lobe has no Fresnel), from the LUT's
// B channel at (NoV, clamped sheen roughness).
float sheenDFG(sampler2D brdfLut, float NoV, float sheenRoughness) {
    // glTF KHR_materials_sheen, albedo-scaling: E(x) precomputed; Filament's cloth DFG
    return texture(brdfLut, vec2(NoV, clamp(sheenRoughness, MIN_SHEEN_ROUGHNESS, 1.0))).b;
}

// Scale of the layer under the sheen: the energy the sheen took, 1 - max(sheenColor) E.
float sheenAlbedoScaling(float sheenMax, float E) {
    // glTF KHR_materials_sheen, albedo-scaling: 1 - max3(sheenColor) E(x)
    return saturate(1.0 - sheenMax * E);
}

// Split-sum sheen: one prefiltered radiance (fetched at the sheen roughness) times the
// sheen colour and its DFG term.
vec3 sheenSplitSum(vec3 prefiltered, vec3 sheenColor, float dfg) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 6-8 split sum, with the Charlie
    // lobe's DFG as Filament's cloth IBL (prefiltered x sheenColor x DFG_charlie)
    return prefiltered * sheenColor * dfg;
}

// A direction for the point Xi, uniform over the hemisphere around N: the Charlie lobe is wide
// and largest near the horizon, where cosine sampling would put the fewest samples.
vec3 sheenSampleDirection(vec2 Xi, vec3 N, out float pdf) {
    // Uniform hemisphere sampling (cos theta uniform in [0, 1]); pdf = 1 / (2 pi)
    float phi = 2.0 * PI * Xi.x;
    float cosT = Xi.y;
    float sinT = sqrt(max(0.0, 1.0 - cosT * cosT));
    vec3 T;
    vec3 B;
    tangentFrame(N, T, B);
    pdf = 0.5 * INV_PI;
    return T * (sinT * cos(phi)) + B * (sinT * sin(phi)) + N * cosT;
}

// Solid-angle density of L under sheenSampleDirection.
float sheenSamplePdf(vec3 N, vec3 L) {
    // Uniform hemisphere sampling: 1 / (2 pi) above the horizon, 0 below
    return dot(N, L) > 0.0 ? 0.5 * INV_PI : 0.0;
}
