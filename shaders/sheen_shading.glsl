// The sheen lobe in the shading: its ShadingContext set-up, its layering over the base for
// every light (lights.glsl declares sheenLayer and calls it), and its image-based term.
// surface.glsl includes this file after the IBL inputs, only where the material writes
// sheenColor (MATERIAL_HAS_SHEEN_COLOR); the maths is sheen.glsl's.
#include "common.glsl"
#include "lights.glsl"
#include "ibl_inputs.glsl"
#include "ibl.glsl"
#include "sheen.glsl"

// Everything below reads the ShadingContext's sheen fields, which exist only then.
#if defined(MATERIAL_HAS_SHEEN_COLOR)

// The sheen fields of the context: shownColor is the colour drawn (the material's sheenColor
// times the lobe view's lobeOn(LOBE_SHEEN)), sheenColor the material's own, which scales the
// base whether the view shows the sheen or not (the base keeps what it has in the full image).
void setupSheen(inout ShadingContext s, vec3 sheenColor, float sheenRoughness, vec3 shownColor) {
    // glTF KHR_materials_sheen, albedo-scaling: 1 - max3(sheenColor) E(NoV) for the view
    s.sheenColor = shownColor;
    s.sheenRoughness = clamp(sheenRoughness, MIN_SHEEN_ROUGHNESS, 1.0);
    s.sheenAlpha = sheenAlpha(sheenRoughness);
    s.sheenMax = max(max(sheenColor.r, sheenColor.g), sheenColor.b);
    s.sheenScaleV = sheenAlbedoScaling(s.sheenMax, sheenDFG(uBrdfLut, s.NoV, s.sheenRoughness));
}

// Scale of the base for light arriving from a direction with cosine NoL: the smaller of the
// view's and the light's albedo scalings, so neither direction sees more than the sheen left.
float sheenBaseScale(ShadingContext s, float NoL) {
    // glTF KHR_materials_sheen, albedo-scaling: min(1 - max3(c) E(NoV), 1 - max3(c) E(NoL))
    float EL = sheenDFG(uBrdfLut, saturate(NoL), s.sheenRoughness);
    float scaleL = sheenAlbedoScaling(s.sheenMax, EL);
    return min(s.sheenScaleV, scaleL);
}

// The base's radiance from one light, scaled, plus the sheen towards L; `cosine` is what the
// sheen BRDF is multiplied by (NoL for a direction, the segment's irradiance factor for a tube).
vec3 sheenLayer(ShadingContext s, vec3 base, vec3 L, float cosine) {
    // glTF KHR_materials_sheen: sheen f + base * sheen_albedo_scaling
    float NoL = saturate(dot(s.N, L));
    return base * sheenBaseScale(s, NoL)
         + s.sheenColor * (sheenBRDF(s.N, s.V, L, s.sheenAlpha) * cosine);
}

// The sheen's f NoL towards L with the base's scaling, for the area lights' reference:
// base is the base's f NoL towards L.
vec3 sheenLayerCosine(ShadingContext s, vec3 base, vec3 L) {
    // glTF KHR_materials_sheen, as sheenLayer with cosine = NoL
    return sheenLayer(s, base, L, saturate(dot(s.N, L)));
}

// The sheen's split-sum image-based light: the environment prefiltered at roughness 1
// around N (SHEEN_IBL_LOOKUP_ROUGHNESS), times sheenColor and the DFG term (reference mode
// integrates the sheen with the rest of the layered BRDF, reference_layered.glsl).
// The Charlie lobe is wide at every sheen roughness: it reflects the hemisphere's rim at
// normal views and spreads over the hemisphere at grazing ones, where R lies on the horizon.
// A GGX lobe of the sheen roughness around N is too narrow a stand-in for it (0.3: it reads
// the zenith only); the widest prefiltered mip, roughness 1 around N, is close to the
// cosine-weighted hemisphere the lobe averages. Measured (docs/shading.md, Sheen): split sum
// against reference mode on the velvet and fabric samples, studio 0.224 / 0.074 -> 0.113 /
// 0.044, sky 0.201 / 0.091 -> 0.109 / 0.058; the SH irradiance / pi instead: 0.120 / 0.047
// and 0.111 / 0.058.
const float SHEEN_IBL_LOOKUP_ROUGHNESS = 1.0;

vec3 sheenImageBasedLighting(ShadingContext s) {
    // Filament's cloth IBL, after Karis 2013 eq 6-8: prefiltered(r) sheenColor DFG_charlie,
    // with matedit's lookup roughness (above)
    int mode = int(uIbl.params.w + 0.5);
    if (mode == IBL_MODE_NONE) return vec3(0.0);
    float NoV = saturate(dot(s.N, s.V));
    vec3 prefiltered = prefilteredRadiance(uPrefilteredEnv, s.N, SHEEN_IBL_LOOKUP_ROUGHNESS,
                                           uIbl.params.x);
    float dfg = sheenDFG(uBrdfLut, NoV, s.sheenRoughness);
    return sheenSplitSum(prefiltered, s.sheenColor, dfg) * uIbl.params.y;
}
#endif
