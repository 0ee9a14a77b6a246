// Attribute views of the viewport (MATEDIT_ATTRIBUTE_VIEW in the FORWARD entry): a field of
// the material drawn in place of its shading, linear, so the image reads the field's value.
#include "common.glsl"
#include "material.glsl"

#define ATTRIBUTE_VIEW_ROUGHNESS 1
#define ATTRIBUTE_VIEW_NORMAL 2
#define ATTRIBUTE_VIEW_COAT 3
#define ATTRIBUTE_VIEW_ANISOTROPY 4
#define ATTRIBUTE_VIEW_THIN_FILM 6
// Stripes a UV unit across the anisotropy direction (the preview meshes' UVs span 0..1).
#define ATTRIBUTE_VIEW_STRIPES 32.0

// Lines parallel to the direction: the direction is tangent-space (x along the mesh tangent,
// the UV's u; y along the bitangent, its v), so a coordinate across it in UV space,
// u = uv . (-d.y, d.x), has level lines that run along the direction on the surface, for a
// field that varies slowly against the stripe spacing. Anti-aliased by its screen width,
// over the base colour dimmed to a fifth; the lines go from grey (anisotropy 0) to amber (1),
// so both the direction and the amount read.
vec3 anisotropyStripes(MaterialAttributes m, vec2 uv) {
    // A distance-to-nearest-line pattern, |fract(u + 1/2) - 1/2|, its edge smoothed over
    // fwidth(u) (one pixel): a step filtered by its filter width. The direction as glTF
    // KHR_materials_anisotropy lays it in the tangent plane (x: tangent, y: bitangent).
    // Apodaca & Gritz 1999, "Advanced RenderMan", shader antialiasing (filterwidth)
    vec2 d = m.anisotropyDirection.xy;
    float len2 = dot(d, d);
    d = len2 > 1e-12 ? d * inversesqrt(len2) : vec2(1.0, 0.0);
    float u = dot(uv, vec2(-d.y, d.x)) * ATTRIBUTE_VIEW_STRIPES;
    float dist = abs(fract(u + 0.5) - 0.5);
    float aa = max(fwidth(u), 1e-4);
    float line = 1.0 - smoothstep(0.15 - aa, 0.15 + aa, dist);
    vec3 dim = 0.2 * saturate(m.baseColor);
    vec3 ink = mix(vec3(0.45), vec3(1.0, 0.72, 0.18), saturate(m.anisotropy));
    return mix(dim, ink, line);
}

// The view `view` (ATTRIBUTE_VIEW_*) of the material at one fragment: roughness and coat
// weight as grey levels (saturated, as the shading reads them), the world shading normal
// encoded N / 2 + 1/2, the anisotropy direction as stripes, the thin film's thickness in
// micrometres (nm / 1000) as a grey level.
vec3 attributeView(int view, MaterialAttributes m, vec2 uv, vec3 N) {
    // A debug view, no shading model: the values as the shading reads them.
    // Karis 2013, "Real Shading in Unreal Engine 4" (the buffer visualisations of its
    // material model); glTF KHR_materials_clearcoat and KHR_materials_anisotropy fields
    if (view == ATTRIBUTE_VIEW_ROUGHNESS) return vec3(saturate(m.roughness));
    if (view == ATTRIBUTE_VIEW_NORMAL) return N * 0.5 + 0.5;
    if (view == ATTRIBUTE_VIEW_COAT) return vec3(saturate(m.coat));
    // glTF KHR_materials_iridescence's thickness (nm), drawn in micrometres, unclamped
    if (view == ATTRIBUTE_VIEW_THIN_FILM) return vec3(max(m.thinFilmThickness, 0.0) * 1e-3);
    return anisotropyStripes(m, uv);
}
