// The material the node graph writes and the shading reads: one struct, its
// defaults, and the derived diffuse colour and F0 of the metallic workflow.
#include "common.glsl"

struct MaterialAttributes {
    vec3 baseColor;
    float metallic;
    float roughness;
    float cavity;
    vec3 normal;    // tangent space
    vec3 emissive;
    float opacity;
};

// The values an unconnected material output reads.
MaterialAttributes defaultMaterialAttributes() {
    // docs/file-format.md#materialattributes: defaults of the MaterialAttributes inputs
    MaterialAttributes m;
    m.baseColor = vec3(0.5);
    m.metallic = 0.0;
    m.roughness = 0.5;
    m.cavity = 1.0;
    m.normal = vec3(0.0, 0.0, 1.0);
    m.emissive = vec3(0.0);
    m.opacity = 1.0;
    return m;
}

// Albedo of the Lambert lobe: metals have none.
vec3 computeDiffuseColor(vec3 baseColor, float metallic) {
    // Karis 2013, "Real Shading in Unreal Engine 4", material model: BaseColor (1 - Metallic)
    return baseColor * (1.0 - metallic);
}

// Reflectance at normal incidence: 4% for dielectrics, baseColor for metals.
vec3 computeF0(vec3 baseColor, float metallic) {
    // Karis 2013, "Real Shading in Unreal Engine 4", material model: lerp(0.04, BaseColor, Metallic)
    return mix(vec3(0.04), baseColor, metallic);
}

// Tangent-space normal to world space through the (T, B, N) frame, renormalised.
vec3 tangentToWorldNormal(vec3 tangentNormal, vec3 T, vec3 B, vec3 N) {
    // Mikkelsen 2008, "Simulation of Wrinkled Surfaces Revisited": n = T x + B y + N z
    return normalize(T * tangentNormal.x + B * tangentNormal.y + N * tangentNormal.z);
}
