// Make Material Attributes node: the struct from its seven fields.
#include "../material.glsl"

void node_make_attributes(vec3 baseColor, float metallic, float roughness, float cavity,
                          vec3 normal, vec3 emissive, float opacity,
                          out MaterialAttributes attributes) {
    // Karis 2013, "Real Shading in Unreal Engine 4", material model: the parameter set
    attributes.baseColor = baseColor;
    attributes.metallic = metallic;
    attributes.roughness = roughness;
    attributes.cavity = cavity;
    attributes.normal = normal;
    attributes.emissive = emissive;
    attributes.opacity = opacity;
}
