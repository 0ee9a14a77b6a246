// The subsurface diffuse (beyond the talk): a forward-path model of light that scatters
// under the surface, with no screen-space diffusion pass. The diffuse lobe becomes, by the
// subsurface weight, a mix of Lambert and a lobe of two parts:
//   - an energy-conserving wrapped diffuse, max(NoL + w, 0) / (1 + w)^2, whose wrap w grows
//     with the mean free path against the part's thickness (light creeps past the terminator);
//   - light transmitted through the part from behind, Lambert about -N, scaled by the
//     transmittance T = exp(-thickness / radius) of each channel.
// The reflected part keeps 1 - T, the transmitted part T, so over the sphere of directions
// the lobe returns exactly its albedo (docs/shading.md, Subsurface). No ShadingContext here:
// lights.glsl and surface.glsl wire these functions into the lights, the IBL and the
// reference.
#include "common.glsl"

// Shortest mean free path the lobe reads, metres (0.1 mm): keeps T and w finite at radius 0.
const float MIN_SUBSURFACE_RADIUS = 1e-4;

// The lobe at one point: its albedo (the weight and the metallic mask folded in), the wrap
// and the transmittance of each channel.
struct SubsurfaceLobe {
    vec3 color;          // subsurface x subsurfaceColor x (1 - metallic), as drawn
    vec3 wrap;           // w in [0, 1]
    vec3 transmittance;  // T in [0, 1]
};

// The wrap of each channel: the mean free path r against the thickness d, w = r / (r + d);
// 1 for a part much thinner than the path (light reaches round it), 0 for a thick one.
vec3 subsurfaceWrap(vec3 radius, float thickness) {
    // matedit's mapping (docs/shading.md, Subsurface): a wrap from the ratio of the mean free
    // path to the size of the part, after Green 2004, "Real-Time Approximations to Subsurface
    // Scattering" (GPU Gems ch. 16), wrap lighting
    vec3 r = max(radius, vec3(MIN_SUBSURFACE_RADIUS));
    return r / (r + max(thickness, 0.0));
}

// Transmittance of the part for each channel: Beer-Lambert over the thickness with the mean
// free path as the extinction length.
vec3 subsurfaceTransmittance(vec3 radius, float thickness) {
    // Beer-Lambert, T = exp(-d / l); the thin-part transmission of Filament's subsurface
    // model (Filament Materials documentation, "Subsurface model") takes the same form
    return exp(-max(thickness, 0.0) / max(radius, vec3(MIN_SUBSURFACE_RADIUS)));
}

// The lobe from the material's fields; `shown` is the lobe view's lobeOn(LOBE_SUBSURFACE).
SubsurfaceLobe makeSubsurfaceLobe(float weight, vec3 color, vec3 radius, float thickness,
                                  float metallic, float shown) {
    // standard_surface / OpenPBR: subsurface_color is the albedo of the subsurface part,
    // which the weight mixes with the diffuse; metals have none
    SubsurfaceLobe l;
    l.color = saturate(color) * (saturate(weight) * (1.0 - metallic) * shown);
    l.wrap = subsurfaceWrap(radius, thickness);
    l.transmittance = subsurfaceTransmittance(radius, thickness);
    return l;
}

// The energy-conserving wrapped cosine: max(NoL + w, 0) / (1 + w)^2, of signed NoL. Its
// integral over the sphere is pi for every w, as the clamped cosine's (w = 0).
vec3 wrappedDiffuseCosine(float NoL, vec3 w) {
    // Green 2004, "Real-Time Approximations to Subsurface Scattering", wrap lighting
    // (NoL + w) / (1 + w), divided once more by (1 + w) so its integral stays pi
    return max(vec3(NoL) + w, vec3(0.0)) / ((1.0 + w) * (1.0 + w));
}

// f NoL of the lobe for a light of signed cosine NoL (towards L, to the shading normal):
// color / pi [(1 - T) wrap(NoL) + T max(-NoL, 0)].
vec3 subsurfaceCosine(SubsurfaceLobe l, float NoL) {
    // matedit's subsurface lobe (docs/shading.md, Subsurface): reflected wrapped diffuse plus
    // Lambert transmission about -N, split by the transmittance
    return l.color * INV_PI * ((1.0 - l.transmittance) * wrappedDiffuseCosine(NoL, l.wrap)
                               + l.transmittance * max(-NoL, 0.0));
}

// Irradiance of the wrapped cosine kernel from 9 SH coefficients of the radiance: the
// clamped cosine's bands scaled by the wrap's (Funk-Hecke), band 1 by 1 - w/2, band 2 by
// (1 - w)^2; w = 0 gives irradianceSH9's E(N).
vec3 wrappedIrradianceSH9(vec3 sh[9], vec3 N, vec3 w) {
    // Ramamoorthi and Hanrahan 2001, "An Efficient Representation for Irradiance Environment
    // Maps", eq 13 split by band; the band factors 2 pi int k(t) P_l(t) dt of the wrapped
    // kernel over those of the clamped cosine (docs/shading.md, Subsurface)
    const float c1 = 0.429043;
    const float c2 = 0.511664;
    const float c3 = 0.743125;
    const float c4 = 0.886227;
    const float c5 = 0.247708;
    float x = N.x;
    float y = N.y;
    float z = N.z;
    vec3 band0 = c4 * sh[0];
    vec3 band1 = 2.0 * c2 * (sh[3] * x + sh[1] * y + sh[2] * z);
    vec3 band2 = c1 * sh[8] * (x * x - y * y) + c3 * sh[6] * z * z - c5 * sh[6]
               + 2.0 * c1 * (sh[4] * x * y + sh[7] * x * z + sh[5] * y * z);
    return band0 + (1.0 - 0.5 * w) * band1 + (1.0 - w) * (1.0 - w) * band2;
}

// The lobe under an environment, from the wrapped kernel's irradiance at N (Ewrap,
// wrappedIrradianceSH9) and the clamped cosine's about -N (Eback, ibl.glsl irradianceSH9 at
// -N): color / pi [(1 - T) Ewrap + T Eback].
vec3 subsurfaceIrradiance(SubsurfaceLobe l, vec3 Ewrap, vec3 Eback) {
    // the lights' subsurfaceCosine integrated against the environment's radiance
    return l.color * INV_PI * ((1.0 - l.transmittance) * Ewrap + l.transmittance * Eback);
}
