// Specular transmission (beyond the talk): light that passes through a dielectric part,
// glass, water, honey. The base's specular reflection is kept as it is; the transmission
// takes what it leaves, 1 - F, and the diffuse is scaled by 1 - transmission. Two models of
// the part (docs/shading.md, Transmission):
//   - solid (the default): one rough refraction in (Walter et al. 2007) and a smooth exit
//     through a sphere of diameter `thickness` (the exit's normal from the sphere's
//     geometry), absorbed along the chord;
//   - thin-walled (the Material Output's thin_walled, MATERIAL_THIN_WALLED): a wall of
//     thickness `thickness` with parallel faces; the ray leaves unbent, its roughness is the
//     reflection lobe's mirrored through the tangent plane.
// Absorption is Beer-Lambert, attenuationColor^(d / attenuationDistance) over the path
// length d. No ShadingContext here: lights.glsl and surface.glsl wire these in.
#include "common.glsl"
#include "brdf.glsl"

// The lobe at one point: its weight, tint (colour and absorption) and the ray inside.
struct TransmissionLobe {
    float weight;  // transmission x (1 - metallic) x lobe view, in [0, 1]
    vec3 tint;     // transmissionColor x the absorption along the path
    float eta;     // the part's index of refraction over the outside's (>= 1)
    vec3 inside;   // the view ray after the first interface (thin-walled: -V)
};

// GLSL's refract of I through n (n.I < 0) at the index ratio eta, with the root's argument
// kept at 0 or more: at the edge of total internal reflection the ray goes tangent, and it
// moves continuously there (float rounding cannot flip it to 0).
vec3 refractClamped(vec3 I, vec3 n, float eta) {
    // Snell's law in vector form (the GLSL specification's refract)
    float c = dot(n, I);
    float k = max(1.0 - eta * eta * (1.0 - c * c), 0.0);
    return eta * I - (eta * c + sqrt(k)) * n;
}

// The view ray refracted into the part through N, refract(-V, N, 1 / eta).
vec3 transmissionEntry(vec3 N, vec3 V, float eta) {
    // Snell's law, Walter et al. 2007, "Microfacet Models for Refraction through Rough
    // Surfaces", eq 40 with the macro normal
    return refractClamped(-V, N, 1.0 / eta);
}

// The ray inside a sphere of diameter D whose surface it entered at P with normal N leaves
// it after the chord D cos, cos = -N.inside; the exit's outward normal is 2 cos inside + N.
// Returns the ray refracted out (by the sphere's symmetry never totally reflected: it leaves
// at the entry's angle).
vec3 transmissionSphereExit(vec3 N, vec3 inside, float eta) {
    // matedit's solid model (docs/shading.md, Transmission), after Filament's "refraction
    // through a solid sphere" (Filament Materials documentation, Refraction): the centre is
    // P - N D / 2, the exit point P + inside D cos
    float c = max(-dot(N, inside), 0.0);
    vec3 nOut = normalize(2.0 * c * inside + N);
    return normalize(refractClamped(inside, -nOut, eta));
}

// Beer-Lambert transmittance over a path of length d: attenuationColor^(d / distance);
// distance 0 means no absorption.
vec3 beerLambert(vec3 attenuationColor, float attenuationDistance, float d) {
    // Beer-Lambert law; glTF KHR_materials_volume's attenuationColor and attenuationDistance
    // (the colour white light takes after that distance)
    if (attenuationDistance <= 0.0) return vec3(1.0);
    vec3 c = clamp(attenuationColor, vec3(1e-6), vec3(1.0));
    return exp(log(c) * (max(d, 0.0) / attenuationDistance));
}

// The lobe from the material's fields; `thin` 1 thin-walled, 0 solid; `shown` is the lobe
// view's lobeOn(LOBE_TRANSMISSION).
TransmissionLobe makeTransmissionLobe(float weight, vec3 color, vec3 attenuationColor,
                                      float attenuationDistance, float thickness, float ior,
                                      float metallic, float thin, vec3 N, vec3 V,
                                      float shown) {
    // standard_surface / OpenPBR transmission_weight and transmission_color; metals have none
    TransmissionLobe l;
    l.weight = saturate(weight) * (1.0 - metallic) * shown;
    l.eta = max(ior, 1.0 + 1e-4);
    vec3 entry = transmissionEntry(N, V, l.eta);
    float c = max(-dot(N, entry), 1e-3);  // cos of the refracted ray to -N
    float d;
    if (thin > 0.5) {
        // the wall crossed along the refracted ray, thickness / cos; the ray leaves unbent
        l.inside = -V;
        d = thickness / c;
    } else {
        l.inside = entry;
        d = thickness * c;  // the sphere's chord
    }
    l.tint = saturate(color) * beerLambert(attenuationColor, attenuationDistance, d);
    return l;
}

// The direction the preview looks the environment up along. Thin-walled: the mirrored lobe's
// dominant direction, -V pulled towards -N as the lobe widens (as the specular peak shifts
// towards N). Solid: the refracted ray out of the sphere (the exit undoes much of the
// entry's spread, and the pull measured worse there: docs/shading.md, Transmission).
vec3 transmissionLookupRay(TransmissionLobe l, vec3 N, float roughness, float thin) {
    // Lagarde and de Rousiers 2014, "Moving Frostbite to PBR", the specular's dominant
    // direction, mirrored below the surface: mix(-N, ray, (1 - a)(sqrt(1 - a) + a)), a = r^2
    if (thin < 0.5) return transmissionSphereExit(N, l.inside, l.eta);
    float a = roughness * roughness;
    float f = (1.0 - a) * (sqrt(1.0 - a) + a);
    return normalize(mix(-N, l.inside, f));
}

// The roughness the preview's environment lookup takes: the material's for a thin wall (its
// mirrored lobe is the reflection's); for a solid the refracted lobe's spread, a microfacet
// tilt t deviating the ray by about (1 - 1/eta) t where a reflection deviates it by 2 t,
// so the lookup's alpha (1 - 1/eta) / 2 of the material's: r sqrt((1 - 1/eta) / 2).
float transmissionLookupRoughness(TransmissionLobe l, float roughness, float thin) {
    // matedit's small-angle mapping (docs/shading.md, Transmission) of the refraction's
    // deviation, Snell's law to first order in the microfacet tilt
    return thin > 0.5 ? roughness : roughness * sqrt(0.5 * (1.0 - 1.0 / l.eta));
}

// Smith's masking of GGX for one direction, exact: 2 |NoX| / (|NoX| + sqrt(a^2 + (1 - a^2) NoX^2)).
float smithG1GGX(float NoX, float a) {
    // Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces", eq 34
    float c = abs(NoX);
    return 2.0 * c / max(c + sqrt(a * a + (1.0 - a * a) * c * c), 1e-12);
}

// f |NoL| / (1 - F) of the solid's BTDF for a light below the surface (NoL < 0), V above it:
// the rough interface outside (index 1, V) | inside (index eta, L). `VoH` receives the V.h
// its Fresnel is taken at (the caller's Schlick or thin-film Fresnel).
float refractionBtdfCosineNoFresnel(vec3 N, vec3 V, vec3 L, float a, float eta, out float VoH) {
    // Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces", eq 21
    // with GGX D (eq 33), separable Smith G (eq 23, 34) and the half vector of eq 16,
    // h = -(V + eta L). The eta^2 of eq 21 is kept: the integral over L of f |NoL| is the
    // interface's transmittance (the radiance's eta^2 in and out of the part cancel).
    VoH = 0.0;
    float NoV = dot(N, V);
    float NoL = dot(N, L);
    if (NoL >= 0.0 || NoV <= 0.0) return 0.0;
    vec3 h = -(V + eta * L);
    float hh = dot(h, h);
    if (hh < 1e-12) return 0.0;
    vec3 H = h * inversesqrt(hh);
    if (dot(N, H) < 0.0) H = -H;
    float vh = dot(V, H);
    float LoH = dot(L, H);
    if (vh <= 0.0 || LoH >= 0.0) return 0.0;
    VoH = vh;
    float den = vh + eta * LoH;
    vec3 NxH = cross(N, H);  // 1 - NoH^2 without cancellation (narrow lobes, brdf.glsl)
    float D = D_GGX(saturate(dot(N, H)), a, dot(NxH, NxH));
    float G = smithG1GGX(NoV, a) * smithG1GGX(NoL, a);
    return vh * -LoH * eta * eta * G * D / (NoV * max(den * den, 1e-12));
}

// f |NoL| of the solid's BTDF with Schlick's Fresnel of F0: (1 - F(V.h)) times the above.
vec3 refractionBtdfCosine(vec3 N, vec3 V, vec3 L, float a, float eta, vec3 F0) {
    // Walter et al. 2007, eq 21 (refractionBtdfCosineNoFresnel), Schlick's F
    float VoH;
    float f = refractionBtdfCosineNoFresnel(N, V, L, a, eta, VoH);
    return (1.0 - F_Schlick(F0, VoH)) * f;
}

// f |NoL| / (1 - F) of the thin wall's BTDF for a light below the surface: the reflection
// lobe (GGX, Smith G) of L mirrored through the tangent plane. `VoH` receives the V.h of its
// Fresnel.
float thinWalledBtdfCosineNoFresnel(vec3 N, vec3 V, vec3 L, float a, out float VoH) {
    // matedit's thin-walled model (docs/shading.md, Transmission): the microfacet lobe of
    // Walter et al. 2007 eq 20 about the mirrored direction: a thin slab of two equal
    // rough faces, its spread taken as one face's
    VoH = 0.0;
    float NoV = dot(N, V);
    float NoL = dot(N, L);
    if (NoL >= 0.0 || NoV <= 0.0) return 0.0;
    vec3 Lm = L - 2.0 * NoL * N;
    vec3 H = normalize(V + Lm);
    VoH = saturate(dot(V, H));
    vec3 NxH = cross(N, H);  // 1 - NoH^2 without cancellation (narrow lobes, brdf.glsl)
    float D = D_GGX(saturate(dot(N, H)), a, dot(NxH, NxH));
    float G = smithG1GGX(NoV, a) * smithG1GGX(NoL, a);
    return D * G / (4.0 * NoV);
}

// f |NoL| of the thin wall's BTDF with Schlick's Fresnel of F0, weighted by 1 - F.
vec3 thinWalledBtdfCosine(vec3 N, vec3 V, vec3 L, float a, vec3 F0) {
    // matedit's thin-walled model (thinWalledBtdfCosineNoFresnel), Schlick's F
    float VoH;
    float f = thinWalledBtdfCosineNoFresnel(N, V, L, a, VoH);
    return (1.0 - F_Schlick(F0, VoH)) * f;
}

// The transmitted radiance under the prefiltered environment (split sum): what the
// specular reflection leaves, 1 - (F0 A + B) (`reflectedAlbedo`, its environment BRDF), of
// the environment's `prefiltered` radiance along the ray leaving the part, tinted.
vec3 transmissionRadiance(TransmissionLobe l, vec3 prefiltered, vec3 reflectedAlbedo) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 6-8: the reflected albedo F0 A + B;
    // the transmitted part takes the rest, as Filament's refraction does (Filament
    // Materials documentation, Transmission)
    return l.tint * (l.weight * (1.0 - reflectedAlbedo)) * prefiltered;
}
