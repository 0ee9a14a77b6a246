// Break Material Attributes node: the seven fields of the struct.
#include "../material.glsl"

void node_break_attributes(MaterialAttributes attributes, out vec3 baseColor,
                           out float metallic, out float roughness, out float cavity,
                           out vec3 normal, out vec3 emissive, out float opacity) {
    // Karis 2013, "Real Shading in Unreal Engine 4", material model: the parameter set
    baseColor = attributes.baseColor;
    metallic = attributes.metallic;
    roughness = attributes.roughness;
    cavity = attributes.cavity;
    normal = attributes.normal;
    emissive = attributes.emissive;
    opacity = attributes.opacity;
}
