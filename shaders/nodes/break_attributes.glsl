// Break Material Attributes node: the fields of the struct.
#include "../material.glsl"

void node_break_attributes(MaterialAttributes attributes, out vec3 baseColor,
                           out float metallic, out float roughness, out float cavity,
                           out vec3 normal, out vec3 emissive, out float opacity,
                           out vec3 specularColor, out float ior, out float coat,
                           out float coatRoughness, out vec3 coatColor, out float coatIor,
                           out vec3 coatNormal, out vec3 sheenColor, out float sheenRoughness,
                           out float anisotropy, out vec3 anisotropyDirection,
                           out float subsurface, out vec3 subsurfaceColor,
                           out vec3 subsurfaceRadius, out float thickness,
                           out float thinFilmThickness, out float thinFilmIor,
                           out float transmission, out vec3 transmissionColor,
                           out vec3 attenuationColor, out float attenuationDistance) {
    // Karis 2013, "Real Shading in Unreal Engine 4", material model: the parameter set, then
    // the lobes beyond it (docs/shading.md, Lobes beyond the talk)
    baseColor = attributes.baseColor;
    metallic = attributes.metallic;
    roughness = attributes.roughness;
    cavity = attributes.cavity;
    normal = attributes.normal;
    emissive = attributes.emissive;
    opacity = attributes.opacity;
    specularColor = attributes.specularColor;
    ior = attributes.ior;
    coat = attributes.coat;
    coatRoughness = attributes.coatRoughness;
    coatColor = attributes.coatColor;
    coatIor = attributes.coatIor;
    coatNormal = attributes.coatNormal;
    sheenColor = attributes.sheenColor;
    sheenRoughness = attributes.sheenRoughness;
    anisotropy = attributes.anisotropy;
    anisotropyDirection = attributes.anisotropyDirection;
    subsurface = attributes.subsurface;
    subsurfaceColor = attributes.subsurfaceColor;
    subsurfaceRadius = attributes.subsurfaceRadius;
    thickness = attributes.thickness;
    thinFilmThickness = attributes.thinFilmThickness;
    thinFilmIor = attributes.thinFilmIor;
    transmission = attributes.transmission;
    transmissionColor = attributes.transmissionColor;
    attenuationColor = attributes.attenuationColor;
    attenuationDistance = attributes.attenuationDistance;
}
