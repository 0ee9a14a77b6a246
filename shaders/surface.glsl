// The one shading evaluation: a MaterialAttributes lit by the lights block and the
// environment. The graph fills the struct; this file never sees nodes.
#include "common.glsl"
#include "material.glsl"
#include "lights_block.glsl"
#include "ibl_inputs.glsl"
#include "ibl.glsl"
#if defined(MATERIAL_HAS_SHEEN_COLOR)
// Only its own sheen.glsl is new to the assembly here (an include under #if must not be the
// first of a shared file, which the assembler splices once).
#include "sheen_shading.glsl"
#endif
#ifndef MATEDIT_SPLIT_SUM_ONLY
#include "lights_reference.glsl"
#if defined(MATERIAL_HAS_COAT) || defined(MATERIAL_HAS_SHEEN_COLOR) || defined(MATERIAL_HAS_ANISOTROPY) || defined(MATERIAL_HAS_SUBSURFACE) || defined(MATERIAL_HAS_THIN_FILM_THICKNESS) || defined(MATERIAL_HAS_TRANSMISSION)
// The reference of a material with lobes integrates the whole layered BRDF at once.
#define MATEDIT_LAYERED_REFERENCE
#include "reference_layered.glsl"
#endif
#endif

// The lobes a view shows: MATEDIT_LOBES is a mask of LOBE_* bits (unset: every lobe). The
// viewport's lobe views set it (base, coat, sheen, subsurface, specular only); each lobe's contribution,
// direct and image-based, is scaled by lobeOn of its bit.
#define LOBE_DIFFUSE 1
#define LOBE_SPECULAR 2
#define LOBE_COAT 4
#define LOBE_SHEEN 8
#define LOBE_EMISSIVE 16
#define LOBE_SUBSURFACE 32
#define LOBE_TRANSMISSION 64
#ifndef MATEDIT_LOBES
#define MATEDIT_LOBES 127
#endif

// 1 where the view shows the lobe, 0 where it hides it (a constant: the compiler folds it).
float lobeOn(int lobe) {
    // matedit lobe views (docs/shading.md, Lobe views)
    return (MATEDIT_LOBES & lobe) != 0 ? 1.0 : 0.0;
}

// Sum of all analytic lights of the block.
vec3 directLighting(ShadingContext s) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 9: lights add up
    vec3 sum = vec3(0.0);
    int n = lightCount();
    for (int i = 0; i < n; i++) {
        sum += evaluateLight(s, getLight(i));
    }
    return sum;
}

#ifndef MATEDIT_SPLIT_SUM_ONLY
// Sum of all analytic lights, sphere and tube lights by Monte Carlo over their shapes
// (reference mode; uIbl.params.z samples a frame, offset uIbl.sampleOffset.xy).
vec3 directLightingReference(ShadingContext s) {
    // matedit reference mode (lights_reference.glsl)
    uint count = uint(max(uIbl.params.z, 1.0));
    vec3 sum = vec3(0.0);
    int n = lightCount();
    for (int i = 0; i < n; i++) {
        sum += evaluateLightReference(s, getLight(i), count, uIbl.sampleOffset.xy);
    }
    return sum;
}
#endif

#if defined(MATERIAL_HAS_SUBSURFACE)
// The subsurface lobe's split-sum image-based light: the SH environment's wrapped irradiance
// at N and its irradiance about -N (subsurface.glsl, subsurfaceIrradiance).
vec3 subsurfaceImageBasedLighting(SubsurfaceLobe l, vec3 N) {
    // Ramamoorthi and Hanrahan 2001 eq 13 with the wrapped kernel's band factors
    vec3 sh[9];
    for (int i = 0; i < 9; i++) sh[i] = uIbl.sh[i].xyz;
    return subsurfaceIrradiance(l, wrappedIrradianceSH9(sh, N, l.wrap), irradianceSH9(sh, -N))
         * uIbl.params.y;
}
#endif

#if defined(MATERIAL_HAS_TRANSMISSION)
// The transmission's image-based light: the prefiltered environment along the ray leaving
// the part, at the material's roughness, times what the reflection leaves (transmission.glsl).
vec3 transmissionImageBasedLighting(TransmissionLobe l, vec3 N, vec3 reflectedAlbedo,
                                    float roughness, float thin) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 7 lookup along the refracted ray
    vec3 R = transmissionLookupRay(l, N, roughness, thin);
    vec3 prefiltered = prefilteredRadiance(uPrefilteredEnv, R,
                                           transmissionLookupRoughness(l, roughness, thin),
                                           uIbl.params.x);
    return transmissionRadiance(l, prefiltered, reflectedAlbedo) * uIbl.params.y;
}
#endif

#if defined(MATERIAL_HAS_ANISOTROPY)
// The anisotropic split sum's prefiltered radiance: the taps' lookups (anisotropy.glsl,
// anisotropicTapDirection), weighted and normalised by their weights' sum.
vec3 anisotropicPrefilteredRadiance(samplerCube prefilteredEnv, AnisotropicLobe l, vec3 N,
                                    vec3 V, float roughness, float mipCount) {
    // matedit anisotropic split sum (docs/shading.md, Anisotropy) of Karis 2013's eq 7 lookup
    vec3 tapSum = vec3(0.0);
    float weightSum = 0.0;
    float tapRoughness = anisotropicTapRoughness(l, roughness);
    for (int i = 0; i < ANISOTROPY_IBL_TAPS; i++) {
        vec3 R = anisotropicTapDirection(l, N, V, i);
        float w = anisotropicTapWeight(N, R, i);
        tapSum += w * prefilteredRadiance(prefilteredEnv, R, tapRoughness, mipCount);
        weightSum += w;
    }
    return tapSum / weightSum;
}
#endif

// Image-based lighting from the block's environment, split sum or reference by uIbl.params.w.
vec3 imageBasedLighting(vec3 N, vec3 V, vec3 diffuseColor, vec3 F0, float roughness,
                        vec3 specularScale
#if defined(MATERIAL_HAS_ANISOTROPY)
                        , AnisotropicLobe aniso  // the split sum's taps (anisotropy.glsl)
#endif
#if defined(MATERIAL_HAS_THIN_FILM_THICKNESS)
                        , ThinFilm film  // the split sum's F0 term (thin_film.glsl)
#endif
                        ) {
    // Karis 2013, "Real Shading in Unreal Engine 4", image-based lighting (eq 6-8, reference)
    int mode = int(uIbl.params.w + 0.5);
    if (mode == IBL_MODE_NONE) return vec3(0.0);
#ifndef MATEDIT_SPLIT_SUM_ONLY
    // The reference estimator is a large loop; the preview's split-sum programs leave it out.
    if (mode == IBL_MODE_REFERENCE) {
        // BRDF and environment sampling, balance heuristic (ibl.glsl, referenceEnvironmentIBL)
        uint count = uint(max(uIbl.params.z, 1.0));
        ReferenceSurface rs = makeReferenceSurface(N, V, diffuseColor, F0, roughness,
                                                   specularScale);
        return referenceEnvironmentIBL(uEnvironment, uEnvDistribution, rs, count,
                                       uIbl.sampleOffset.xy) * uIbl.params.y;
    }
#endif
    vec3 sh[9];
    for (int i = 0; i < 9; i++) sh[i] = uIbl.sh[i].xyz;
    float NoV = saturate(dot(N, V));
#if defined(MATERIAL_HAS_ANISOTROPY)
    // anisotropic split sum: narrow lookups spread along the lobe's long axis
    // (anisotropy.glsl, anisotropicTapDirection; docs/shading.md, Anisotropy)
    vec3 prefiltered = anisotropicPrefilteredRadiance(uPrefilteredEnv, aniso, N, V, roughness,
                                                      uIbl.params.x);
#else
    vec3 R = reflect(-V, N);
    vec3 prefiltered = prefilteredRadiance(uPrefilteredEnv, R, roughness, uIbl.params.x);
#endif
    vec2 AB = environmentBRDF(uBrdfLut, NoV, roughness);
#if defined(MATERIAL_HAS_ANISOTROPY)
    // the anisotropic lobe's own scale and bias of F0: the isotropic LUT plus the table's
    // change (anisotropy.glsl, matedit/ibl/anisotropy_lut.py); nothing at anisotropy 0
    if (aniso.anisotropy > 0.0) {
        AB += anisotropicEnvironmentBRDF(uAnisotropyLut, NoV, roughness, aniso.anisotropy,
                                         anisotropicViewCos2(aniso, N, V));
    }
#endif
#if defined(MATERIAL_HAS_THIN_FILM_THICKNESS)
    // The film's Airy reflectance at N.V in place of the F0 term, F_film(NoV) A + B, as glTF
    // KHR_materials_iridescence's split sum (docs/shading.md, Thin film)
    if (film.thickness > 0.0) F0 = thinFilmFresnel(film, NoV);
#endif
    vec3 color = diffuseIrradianceSH9(sh, N, diffuseColor)
               + splitSumSpecular(prefiltered, AB, F0) * specularScale;
    return color * uIbl.params.y;
}

// Linear HDR colour leaving P towards the eye; N is the world-space shading normal
// (tangentToWorldNormal of m.normal), V the unit vector to the eye, and (T, B, Ng) the
// orthonormal tangent frame of the geometric normal Ng, which the coat's normal and the
// anisotropic highlight's direction are given in.
vec3 shadeSurface(MaterialAttributes m, vec3 P, vec3 N, vec3 V, vec3 Ng, vec3 T, vec3 B) {
    // docs/shading.md#the-material-model: (direct + ibl) * cavity + emissive
    vec3 diffuseColor = computeDiffuseColor(m.baseColor, m.metallic);
    vec3 F0 = materialF0(m);
#if defined(MATERIAL_HAS_COAT)
    // Under the coat the base's interface is base | coat: its F0 against the coat's IOR.
    F0 = mix(F0, f0UnderCoat(F0, m.coatIor), saturate(m.coat));
#endif
    float roughness = saturate(m.roughness);
    ShadingContext s = makeShadingContext(P, N, V, diffuseColor, F0, roughness);
#if defined(MATERIAL_HAS_COAT)
    // The coat's normal is given in the geometric normal's frame, not the base's normal map.
    vec3 Nc = Ng;
#if defined(MATERIAL_HAS_COAT_NORMAL)
    Nc = tangentToWorldNormal(m.coatNormal, T, B, Ng);
#endif
    s.coat = makeCoatContext(Nc, V, m.coat, m.coatRoughness, MIN_ANALYTIC_ROUGHNESS,
                             m.coatColor, m.coatIor, lobeOn(LOBE_COAT));
#endif
#if defined(MATERIAL_HAS_ANISOTROPY)
    // anisotropic GGX: the material's direction (tangent space of (T, B, Ng)) in N's plane
    s.aniso = makeAnisotropicLobe(s.a, m.anisotropy, m.anisotropyDirection, T, B, N);
#endif
#if defined(MATERIAL_HAS_SUBSURFACE)
    // The subsurface diffuse (subsurface.glsl) takes its weight's share of the Lambert lobe.
    s.subsurface = makeSubsurfaceLobe(m.subsurface, m.subsurfaceColor, m.subsurfaceRadius,
                                      m.thickness, m.metallic, lobeOn(LOBE_SUBSURFACE));
    s.diffuseColor *= 1.0 - saturate(m.subsurface);
    diffuseColor *= 1.0 - saturate(m.subsurface);
#endif
#if defined(MATERIAL_HAS_THIN_FILM_THICKNESS)
    // The thin film on the base, under the coat where there is one: its outside medium the
    // coat's IOR by the coat's weight; the base's IOR from its F0 against air (thin_film.glsl)
    float filmOutside = 1.0;
#if defined(MATERIAL_HAS_COAT)
    filmOutside = mix(1.0, m.coatIor, saturate(m.coat));
#endif
    s.film = makeThinFilm(m.thinFilmThickness, m.thinFilmIor, filmOutside, materialF0(m));
#endif
#if defined(MATERIAL_HAS_TRANSMISSION)
    // Specular transmission (transmission.glsl): the diffuse keeps 1 - transmission; the
    // transmitted part takes what the specular reflection leaves, 1 - (F0 A + B), with the
    // film's reflectance at N.V in place of F0 where there is one (as imageBasedLighting).
#if defined(MATERIAL_THIN_WALLED)
    const float thinWalled = 1.0;
#else
    const float thinWalled = 0.0;
#endif
    s.transmission = makeTransmissionLobe(m.transmission, m.transmissionColor,
                                          m.attenuationColor, m.attenuationDistance,
                                          m.thickness, m.ior, m.metallic, thinWalled, N, V,
                                          lobeOn(LOBE_TRANSMISSION));
    vec2 transmissionAB = environmentBRDF(uBrdfLut, saturate(dot(N, V)), roughness);
    vec3 transmissionF0 = F0;
#if defined(MATERIAL_HAS_THIN_FILM_THICKNESS)
    if (s.film.thickness > 0.0) transmissionF0 = thinFilmFresnel(s.film, saturate(dot(N, V)));
#endif
    vec3 transmissionReflected = saturate(transmissionF0 * transmissionAB.x + transmissionAB.y);
    s.diffuseColor *= 1.0 - saturate(m.transmission);
    diffuseColor *= 1.0 - saturate(m.transmission);
#if defined(MATERIAL_HAS_SUBSURFACE)
    s.subsurface.color *= 1.0 - saturate(m.transmission);
#endif
#endif
#ifdef MATEDIT_ENERGY_COMPENSATION
    // Beyond the talk (off by default): multiple-scattering compensation of the specular,
    // the diffuse keeping what the specular leaves (ibl.glsl, energyCompensation)
    vec3 diffuseScale;
    energyCompensation(F0, environmentBRDF(uBrdfLut, saturate(dot(N, V)), roughness),
                       s.specularScale, diffuseScale);
    s.diffuseColor *= diffuseScale;
    diffuseColor *= diffuseScale;
#if defined(MATERIAL_HAS_SUBSURFACE)
    s.subsurface.color *= diffuseScale;  // a diffuse lobe too
#endif
#if defined(MATERIAL_HAS_TRANSMISSION)
    // the split sum's transmission takes what the compensated reflection leaves
    transmissionReflected = saturate(transmissionReflected * s.specularScale);
#endif
#endif
#if MATEDIT_LOBES != 127
    // A lobe view: the base's diffuse and specular shown or hidden (every light and the IBL
    // read them through diffuseColor and specularScale).
    s.diffuseColor *= lobeOn(LOBE_DIFFUSE);
    diffuseColor *= lobeOn(LOBE_DIFFUSE);
    s.specularScale *= lobeOn(LOBE_SPECULAR);
#endif
#if defined(MATERIAL_HAS_SHEEN_COLOR)
    // The sheen over the base (sheen_shading.glsl): every light layers it; the IBL's base
    // is scaled by the view's albedo scaling and the sheen's own term added.
    setupSheen(s, m.sheenColor, m.sheenRoughness, m.sheenColor * lobeOn(LOBE_SHEEN));
#endif
    vec3 direct;
#ifndef MATEDIT_SPLIT_SUM_ONLY
    // uIbl.sampleOffset.z = 1: the area lights' reference (reference mode's frames)
    if (uIbl.sampleOffset.z > 0.5) direct = directLightingReference(s);
    else
#endif
    direct = directLighting(s);
#if defined(MATEDIT_LAYERED_REFERENCE)
    // Reference mode with lobes: the whole layered BRDF by one MIS estimator
    // (reference_layered.glsl); the split sum layers its lobes' lookups below.
    bool layeredReference = int(uIbl.params.w + 0.5) == IBL_MODE_REFERENCE;
#else
    const bool layeredReference = false;
#endif
    vec3 ibl;
#if defined(MATEDIT_LAYERED_REFERENCE)
    if (layeredReference) {
        uint count = uint(max(uIbl.params.z, 1.0));
        ibl = layeredEnvironmentIBL(uEnvironment, uEnvDistribution,
                                    makeLayeredReference(s, roughness), count,
                                    uIbl.sampleOffset.xy) * uIbl.params.y;
#if defined(MATERIAL_HAS_TRANSMISSION)
        // the transmitted part by sampling the BTDF (reference_layered.glsl)
        ibl += transmissionEnvironmentIBL(uEnvironment, uEnvDistribution, s, roughness,
                                          count, uIbl.sampleOffset.xy) * uIbl.params.y;
#endif
    }
#endif
    if (!layeredReference) {
        ibl = imageBasedLighting(N, V, diffuseColor, F0, roughness, s.specularScale
#if defined(MATERIAL_HAS_ANISOTROPY)
                                 , s.aniso
#endif
#if defined(MATERIAL_HAS_THIN_FILM_THICKNESS)
                                 , s.film
#endif
                                 );
#if defined(MATERIAL_HAS_SUBSURFACE)
        // The subsurface diffuse's, part of the base (under the sheen and the coat).
        if (int(uIbl.params.w + 0.5) == IBL_MODE_SPLIT_SUM) {
            ibl += subsurfaceImageBasedLighting(s.subsurface, N);
        }
#endif
#if defined(MATERIAL_HAS_TRANSMISSION)
        // The transmitted environment, part of the base (docs/shading.md, Transmission); the
        // reference mode samples the BTDF above, a split-sum-only program looks it up here.
        if (int(uIbl.params.w + 0.5) != IBL_MODE_NONE) {
            ibl += transmissionImageBasedLighting(s.transmission, N, transmissionReflected,
                                                  roughness, thinWalled);
        }
#endif
#if defined(MATERIAL_HAS_SHEEN_COLOR)
        // The base's IBL is linear in its diffuse colour and specular scale: scaling the sum
        // is scaling both by the view's albedo scaling.
        ibl = ibl * s.sheenScaleV + sheenImageBasedLighting(s);
#endif
#if defined(MATERIAL_HAS_COAT)
        // The coat's image-based light, and the base's seen through it (coat.glsl).
        if (int(uIbl.params.w + 0.5) == IBL_MODE_SPLIT_SUM) {
            ibl = coatImageBasedLighting(s.coat, V, ibl, uPrefilteredEnv, uBrdfLut,
                                         uIbl.params.x, uIbl.params.y);
        }
#endif
    }
    return (direct + ibl) * m.cavity + m.emissive * lobeOn(LOBE_EMISSIVE);
}

// The talk's shading where no tangent frame is known (the deferred pass; materials with lobes
// beyond the talk take the forward path): any frame around N.
vec3 shadeSurface(MaterialAttributes m, vec3 P, vec3 N, vec3 V) {
    // matedit: the talk's model reads no tangent frame, so any one will do (sampling.glsl)
    vec3 T;
    vec3 B;
    tangentFrame(N, T, B);
    return shadeSurface(m, P, N, V, N, T, B);
}
