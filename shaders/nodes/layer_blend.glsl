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
    return m;
}

void node_layer_blend(MaterialAttributes base, MaterialAttributes layer, float mask,
                      out MaterialAttributes result) {
    // Karis 2013, "Real Shading in Unreal Engine 4", material layering: lerp by a mask
    result = blendMaterialAttributes(base, layer, mask);
}
