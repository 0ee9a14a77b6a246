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
    // Beyond the talk; each default turns its lobe off (docs/shading.md, Lobes beyond the talk).
    vec3 specularColor;        // tint of the dielectric F0
    float ior;                 // dielectric F0 = ((ior - 1) / (ior + 1))^2 specularColor
    float coat;                // clear coat weight
    float coatRoughness;
    vec3 coatColor;            // transmittance tint of the coat
    float coatIor;
    vec3 coatNormal;           // tangent space of the geometric normal
    vec3 sheenColor;           // black: no sheen
    float sheenRoughness;
    float anisotropy;          // 0: isotropic GGX
    vec3 anisotropyDirection;  // tangent space; +X is the mesh tangent
    float subsurface;          // weight of the subsurface diffuse (subsurface.glsl)
    vec3 subsurfaceColor;      // its albedo
    vec3 subsurfaceRadius;     // mean free path per channel, metres
    float thickness;           // of the part, metres
    float thinFilmThickness;   // nm; 0: no film (thin_film.glsl)
    float thinFilmIor;         // the film's IOR
    float transmission;        // weight of the specular transmission (transmission.glsl)
    vec3 transmissionColor;    // its tint
    vec3 attenuationColor;     // the colour white light takes after attenuationDistance
    float attenuationDistance; // metres; 0: no absorption
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
    m.specularColor = vec3(1.0);
    m.ior = 1.5;
    m.coat = 0.0;
    m.coatRoughness = 0.0;
    m.coatColor = vec3(1.0);
    m.coatIor = 1.5;
    m.coatNormal = vec3(0.0, 0.0, 1.0);
    m.sheenColor = vec3(0.0);
    m.sheenRoughness = 0.3;
    m.anisotropy = 0.0;
    m.anisotropyDirection = vec3(1.0, 0.0, 0.0);
    m.subsurface = 0.0;
    m.subsurfaceColor = vec3(1.0);
    m.subsurfaceRadius = vec3(1.0);
    m.thickness = 1.0;
    m.thinFilmThickness = 0.0;
    m.thinFilmIor = 1.3;
    m.transmission = 0.0;
    m.transmissionColor = vec3(1.0);
    m.attenuationColor = vec3(1.0);
    m.attenuationDistance = 0.0;
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

// F0 of a dielectric of index of refraction ior under air, tinted by specularColor.
vec3 dielectricF0(float ior, vec3 specularColor) {
    // Fresnel at normal incidence, ((n1 - n2) / (n1 + n2))^2 with n1 = 1; glTF
    // KHR_materials_ior and KHR_materials_specular: ior 1.5 and white give the talk's 0.04
    float r = (ior - 1.0) / (ior + 1.0);
    return min(vec3(r * r) * specularColor, vec3(1.0));
}

// F0 of the material: the talk's lerp(0.04, baseColor, metallic), its 0.04 the dielectric F0
// of ior and specularColor where the material writes either.
vec3 materialF0(MaterialAttributes m) {
    // Karis 2013, material model, with the dielectric F0 of glTF KHR_materials_ior/_specular
#if defined(MATERIAL_HAS_IOR) || defined(MATERIAL_HAS_SPECULAR_COLOR)
    return mix(dielectricF0(m.ior, m.specularColor), m.baseColor, m.metallic);
#else
    return computeF0(m.baseColor, m.metallic);
#endif
}

// Tangent-space normal to world space through the (T, B, N) frame, renormalised.
vec3 tangentToWorldNormal(vec3 tangentNormal, vec3 T, vec3 B, vec3 N) {
    // Mikkelsen 2008, "Simulation of Wrinkled Surfaces Revisited": n = T x + B y + N z
    return normalize(T * tangentNormal.x + B * tangentNormal.y + N * tangentNormal.z);
}
