// Make Material Attributes node: the struct from its fields.
#include "../material.glsl"

void node_make_attributes(vec3 baseColor, float metallic, float roughness, float cavity,
                          vec3 normal, vec3 emissive, float opacity, vec3 specularColor,
                          float ior, float coat, float coatRoughness, vec3 coatColor,
                          float coatIor, vec3 coatNormal, vec3 sheenColor,
                          float sheenRoughness, float anisotropy, vec3 anisotropyDirection,
                          float subsurface, vec3 subsurfaceColor, vec3 subsurfaceRadius,
                          float thickness, float thinFilmThickness, float thinFilmIor,
                          float transmission, vec3 transmissionColor,
                          vec3 attenuationColor, float attenuationDistance,
                          out MaterialAttributes attributes) {
    // Karis 2013, "Real Shading in Unreal Engine 4", material model: the parameter set, then
    // the lobes beyond it (docs/shading.md, Lobes beyond the talk)
    attributes.baseColor = baseColor;
    attributes.metallic = metallic;
    attributes.roughness = roughness;
    attributes.cavity = cavity;
    attributes.normal = normal;
    attributes.emissive = emissive;
    attributes.opacity = opacity;
    attributes.specularColor = specularColor;
    attributes.ior = ior;
    attributes.coat = coat;
    attributes.coatRoughness = coatRoughness;
    attributes.coatColor = coatColor;
    attributes.coatIor = coatIor;
    attributes.coatNormal = coatNormal;
    attributes.sheenColor = sheenColor;
    attributes.sheenRoughness = sheenRoughness;
    attributes.anisotropy = anisotropy;
    attributes.anisotropyDirection = anisotropyDirection;
    attributes.subsurface = subsurface;
    attributes.subsurfaceColor = subsurfaceColor;
    attributes.subsurfaceRadius = subsurfaceRadius;
    attributes.thickness = thickness;
    attributes.thinFilmThickness = thinFilmThickness;
    attributes.thinFilmIor = thinFilmIor;
    attributes.transmission = transmission;
    attributes.transmissionColor = transmissionColor;
    attributes.attenuationColor = attenuationColor;
    attributes.attenuationDistance = attenuationDistance;
}
