// Layer Blend (mask) node, and the blend of two MaterialAttributes every layer operation
// uses (the compiler calls blendMaterialAttributes for layer stacks too).
#include "../material.glsl"
#include "normal_math.glsl"

// a at t = 0, b at t = 1: every field linearly, the normal by nlerp.
MaterialAttributes blendMaterialAttributes(MaterialAttributes a, MaterialAttributes b,
                                           float t) {
    // Karis 2013, "Real Shading in Unreal Engine 4", material layering: blend the
    // parameters, shade once. Normals: normalised linear interpolation (nlerp) of the
    // tangent-space normals; opposite normals at t = 0.5 fall back to (0, 0, 1). The lobe
    // fields blend the same way (docs/shading.md, Lobes beyond the talk)
    MaterialAttributes m;
    m.baseColor = mix(a.baseColor, b.baseColor, t);
    m.metallic = mix(a.metallic, b.metallic, t);
    m.roughness = mix(a.roughness, b.roughness, t);
    m.cavity = mix(a.cavity, b.cavity, t);
    m.normal = nodeSafeNormalize(mix(a.normal, b.normal, t), vec3(0.0, 0.0, 1.0));
    m.emissive = mix(a.emissive, b.emissive, t);
    m.opacity = mix(a.opacity, b.opacity, t);
    m.specularColor = mix(a.specularColor, b.specularColor, t);
    m.ior = mix(a.ior, b.ior, t);
    m.coat = mix(a.coat, b.coat, t);
    m.coatRoughness = mix(a.coatRoughness, b.coatRoughness, t);
    m.coatColor = mix(a.coatColor, b.coatColor, t);
    m.coatIor = mix(a.coatIor, b.coatIor, t);
    m.coatNormal = nodeSafeNormalize(mix(a.coatNormal, b.coatNormal, t), vec3(0.0, 0.0, 1.0));
    m.sheenColor = mix(a.sheenColor, b.sheenColor, t);
    m.sheenRoughness = mix(a.sheenRoughness, b.sheenRoughness, t);
    m.anisotropy = mix(a.anisotropy, b.anisotropy, t);
    // The direction by nlerp too; opposite directions (the same line) fall back to +X.
    m.anisotropyDirection = nodeSafeNormalize(mix(a.anisotropyDirection, b.anisotropyDirection,
                                                  t), vec3(1.0, 0.0, 0.0));
    m.subsurface = mix(a.subsurface, b.subsurface, t);
    m.subsurfaceColor = mix(a.subsurfaceColor, b.subsurfaceColor, t);
    m.subsurfaceRadius = mix(a.subsurfaceRadius, b.subsurfaceRadius, t);
    m.thickness = mix(a.thickness, b.thickness, t);
    m.thinFilmThickness = mix(a.thinFilmThickness, b.thinFilmThickness, t);
    m.thinFilmIor = mix(a.thinFilmIor, b.thinFilmIor, t);
    m.transmission = mix(a.transmission, b.transmission, t);
    m.transmissionColor = mix(a.transmissionColor, b.transmissionColor, t);
    m.attenuationColor = mix(a.attenuationColor, b.attenuationColor, t);
    m.attenuationDistance = mix(a.attenuationDistance, b.attenuationDistance, t);
    return m;
}

void node_layer_blend(MaterialAttributes base, MaterialAttributes layer, float mask,
                      out MaterialAttributes result) {
    // Karis 2013, "Real Shading in Unreal Engine 4", material layering: lerp by a mask
    result = blendMaterialAttributes(base, layer, mask);
}

// The share of the combined coat that the new coat layer holds, where the layer of weight w
// lies over a coat of weight a: coverage w + (1 - w) a, the new coat's share w / coverage.
float coatLayerShare(float below, float w) {
    // Independent coverage of two partial coats (the union of two events): the layer covers
    // w, the coat below shows through the rest (1 - w) with its weight; 0 where w = 0 so the
    // stack's own coat is kept exactly. The weight is the coat's presence, as OpenPBR's
    // coat_weight (a mix of the coated and the uncoated surface), so two presences combine
    // as independent coverages. OpenPBR 2024, "OpenPBR Surface Specification", coat_weight
    float coverage = w + (1.0 - w) * below;
    return w / max(coverage, 1e-6);
}

// The `coat` layer blend: the layer lies over the stack as a clear coat (vertical layering);
// the stack's own fields stay as they are, the layer's become the coat's.
MaterialAttributes coatMaterialAttributes(MaterialAttributes base, MaterialAttributes layer,
                                          float w) {
    // A layer as a coat, not a lerp of the two: its roughness is the coat's roughness, its
    // base colour the coat's transmittance tint, its (tangent-space) normal the coat's normal,
    // its IOR the coat's IOR; its weight w = mask x opacity joins a coat already below by
    // coverage, 1 - (1 - a)(1 - w), and the coat fields by the new coat's share of it.
    // glTF KHR_materials_clearcoat (clearcoatFactor, clearcoatRoughness, clearcoatNormal);
    // OpenPBR 2024, "OpenPBR Surface Specification", coat_weight, coat_color, coat_ior
    MaterialAttributes m = base;
    float s = coatLayerShare(base.coat, w);
    m.coat = 1.0 - (1.0 - base.coat) * (1.0 - w);
    m.coatRoughness = mix(base.coatRoughness, layer.roughness, s);
    m.coatColor = mix(base.coatColor, layer.baseColor, s);
    m.coatIor = mix(base.coatIor, layer.ior, s);
    m.coatNormal = nodeSafeNormalize(mix(base.coatNormal, layer.normal, s),
                                     vec3(0.0, 0.0, 1.0));
    return m;
}

// The `film` layer blend: the layer's thin film laid over the stack by the weight w (mask x
// opacity); every other field of the stack kept, so w = 0 keeps the stack exactly.
MaterialAttributes filmMaterialAttributes(MaterialAttributes base, MaterialAttributes layer,
                                          float w) {
    // An oil film on a metal: vertical layering of a film the thickness of a few hundred
    // nanometres, its fields lerped by its coverage (docs/shading.md, Thin film);
    // glTF KHR_materials_iridescence (iridescenceThickness, iridescenceIor)
    MaterialAttributes m = base;
    m.thinFilmThickness = mix(base.thinFilmThickness, layer.thinFilmThickness, w);
    m.thinFilmIor = mix(base.thinFilmIor, layer.thinFilmIor, w);
    return m;
}
