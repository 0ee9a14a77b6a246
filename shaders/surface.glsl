// The one shading evaluation: a MaterialAttributes lit by the lights block and the
// environment. The graph fills the struct; this file never sees nodes.
#include "common.glsl"
#include "material.glsl"
#include "lights_block.glsl"
#include "ibl_inputs.glsl"
#include "ibl.glsl"
#ifndef MATEDIT_SPLIT_SUM_ONLY
#include "lights_reference.glsl"
#endif

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

// Image-based lighting from the block's environment, split sum or reference by uIbl.params.w.
vec3 imageBasedLighting(vec3 N, vec3 V, vec3 diffuseColor, vec3 F0, float roughness,
                        vec3 specularScale) {
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
    vec3 R = reflect(-V, N);
    vec3 prefiltered = prefilteredRadiance(uPrefilteredEnv, R, roughness, uIbl.params.x);
    vec2 AB = environmentBRDF(uBrdfLut, NoV, roughness);
    vec3 color = diffuseIrradianceSH9(sh, N, diffuseColor)
               + splitSumSpecular(prefiltered, AB, F0) * specularScale;
    return color * uIbl.params.y;
}

// Linear HDR colour leaving P towards the eye; N is the world-space shading normal
// (tangentToWorldNormal of m.normal), V the unit vector to the eye.
vec3 shadeSurface(MaterialAttributes m, vec3 P, vec3 N, vec3 V) {
    // SHADING.md, output: (direct + ibl) * cavity + emissive
    vec3 diffuseColor = computeDiffuseColor(m.baseColor, m.metallic);
    vec3 F0 = computeF0(m.baseColor, m.metallic);
    float roughness = saturate(m.roughness);
    ShadingContext s = makeShadingContext(P, N, V, diffuseColor, F0, roughness);
#ifdef MATEDIT_ENERGY_COMPENSATION
    // Beyond the talk (off by default): multiple-scattering compensation of the specular,
    // the diffuse keeping what the specular leaves (ibl.glsl, energyCompensation)
    vec3 diffuseScale;
    energyCompensation(F0, environmentBRDF(uBrdfLut, saturate(dot(N, V)), roughness),
                       s.specularScale, diffuseScale);
    s.diffuseColor *= diffuseScale;
    diffuseColor *= diffuseScale;
#endif
    vec3 direct;
#ifndef MATEDIT_SPLIT_SUM_ONLY
    // uIbl.sampleOffset.z = 1: the area lights' reference (reference mode's frames)
    if (uIbl.sampleOffset.z > 0.5) direct = directLightingReference(s);
    else
#endif
    direct = directLighting(s);
    vec3 ibl = imageBasedLighting(N, V, diffuseColor, F0, roughness, s.specularScale);
    return (direct + ibl) * m.cavity + m.emissive;
}
