// Deferred lighting: shadeSurface (surface.glsl: analytic lights, split-sum or reference IBL)
// applied to the G-buffer the material's GBUFFER entry wrote (shaders/entry/gbuffer.frag.glsl),
// in a full-screen pass. Linked once per variant, whatever the material.
//
// Anti-aliasing: the G-buffer is multisampled like the forward target, and the pass runs once a
// pixel. A pixel whose samples all show the same surface (inside a triangle, all background, or
// two triangles of one smooth surface meeting in it: sameAsFirst) is shaded once from sample 0;
// a pixel whose samples differ (a silhouette, an occlusion edge, a crease, a material seam) is
// shaded per sample from each sample's own values, uncovered samples taking the background,
// and the average is written. Every sample of the target gets the pixel's colour. Lighting
// every triangle edge per sample, as the forward pass does, took a third of the whole frame
// on the sample sphere at 512 px, for differences of a fraction of a pixel's shading
// (tests/test_render_deferred.py states the bounds).
#include "surface.glsl"
#include "gbuffer.glsl"

in vec2 v_ndc;
layout(location = 0) out vec4 fragColor;
// the G-buffer, packed (shaders/gbuffer.glsl; layout: matedit/render/deferred.py)
uniform usampler2DMS uGBuffer0;  // world position (m, float32 bits), normal
uniform usampler2DMS uGBuffer1;  // halves: baseColor, metallic, emissive, cavity
uniform sampler2DMS uGBuffer2;   // roughness (float32), coverage (1 where drawn)
uniform sampler2D uBackground;  // the environment behind the mesh, one sample a pixel
uniform vec3 uCameraPosition;   // eye in world space (m), FrameBlock's cameraPosition.xyz

#ifndef MATEDIT_GBUFFER_SAMPLES
#define MATEDIT_GBUFFER_SAMPLES 4
#endif

// Two samples "show the same surface" when they agree on coverage and, where covered, their
// positions lie within EDGE_POSITION of the distance to the eye, their normals within
// EDGE_NORMAL_COS, and their material values within EDGE_VALUE (emissive: relative above 1).
// That is two triangles of one smooth surface meeting inside the pixel (each fragment shaded
// at the pixel centre, so they differ only by extrapolation): one shading of sample 0 stands
// for both, as a one-sample render would. Silhouettes, occlusion edges, creases and material
// seams differ by more and are shaded per sample. Thresholds: about a third of a pixel's
// footprint at 512 px and a 45-degree field of view, one degree, 1/512.
const float EDGE_POSITION = 5e-4;
const float EDGE_NORMAL_COS = 0.99985;
const float EDGE_VALUE = 1.0 / 512.0;

bool sameHalves(uint a, uint b, vec2 scale) {
    // two packed pairs of G-buffer values within EDGE_VALUE * scale of each other
    return all(lessThanEqual(abs(gbufferUnpackHalf2(a) - gbufferUnpackHalf2(b)),
                             EDGE_VALUE * scale));
}

// Sample 0's values, read once a pixel for the comparisons of the other samples with it.
struct FirstSample {
    uvec4 g0;
    uvec4 g1;
    vec2 g2;
    vec3 emissiveScale;  // the emissive comparison's scale: max(1, |emissive|)
};

bool sameAsFirst(ivec2 p, int s, FirstSample a) {
    // matedit deferred pass: the sample within the thresholds above of sample 0
    vec2 b2 = texelFetch(uGBuffer2, p, s).rg;
    bool covered = gbufferCovered(a.g2);
    if (covered != gbufferCovered(b2)) return false;
    if (!covered) return true;
    uvec4 b0 = texelFetch(uGBuffer0, p, s);
    vec3 P = uintBitsToFloat(a.g0.xyz);
    if (distance(P, uintBitsToFloat(b0.xyz)) > EDGE_POSITION * distance(P, uCameraPosition)
        || dot(gbufferUnpackNormal(a.g0.w), gbufferUnpackNormal(b0.w)) < EDGE_NORMAL_COS
        || abs(a.g2.x - b2.x) > EDGE_VALUE) {
        return false;
    }
    uvec4 b1 = texelFetch(uGBuffer1, p, s);
    return sameHalves(a.g1.x, b1.x, vec2(1.0)) && sameHalves(a.g1.y, b1.y, vec2(1.0))
        && sameHalves(a.g1.z, b1.z, a.emissiveScale.rg)
        && sameHalves(a.g1.w, b1.w, vec2(a.emissiveScale.b, 1.0));
}

bool isEdge(ivec2 p) {
    // matedit deferred pass: a pixel whose samples do not all show the same surface
#ifdef MATEDIT_EDGES_ONCE
    return false;  // benchmarks/bench_render.py: the cost of lighting edges per sample
#endif
    // Inside one triangle every sample holds a copy of one fragment: equal roughness and
    // coverage, and equal positions and normals where covered, settle most pixels.
    FirstSample a;
    a.g2 = texelFetch(uGBuffer2, p, 0).rg;
    a.g0 = texelFetch(uGBuffer0, p, 0);
    bool covered = gbufferCovered(a.g2);
    bool copies = true;
    for (int s = 1; s < MATEDIT_GBUFFER_SAMPLES; s++) {
        copies = copies && texelFetch(uGBuffer2, p, s).rg == a.g2
                 && (!covered || texelFetch(uGBuffer0, p, s) == a.g0);
    }
    if (copies) return false;
    a.g1 = texelFetch(uGBuffer1, p, 0);
    a.emissiveScale = max(vec3(1.0), abs(vec3(gbufferUnpackHalf2(a.g1.z),
                                              gbufferUnpackHalf2(a.g1.w).x)));
    for (int s = 1; s < MATEDIT_GBUFFER_SAMPLES; s++) {
        if (!sameAsFirst(p, s, a)) return true;
    }
    return false;
}

vec3 shadeSample(ivec2 p, int s) {
    // matedit deferred pass: the G-buffer's values back into shadeSurface's arguments
    uvec4 g0 = texelFetch(uGBuffer0, p, s);
    uvec4 g1 = texelFetch(uGBuffer1, p, s);
    vec3 P = uintBitsToFloat(g0.xyz);
    vec2 baseRG = gbufferUnpackHalf2(g1.x);
    vec2 baseBMetallic = gbufferUnpackHalf2(g1.y);
    vec2 emissiveRG = gbufferUnpackHalf2(g1.z);
    vec2 emissiveBCavity = gbufferUnpackHalf2(g1.w);
    MaterialAttributes m = defaultMaterialAttributes();
    m.baseColor = vec3(baseRG, baseBMetallic.x);
    m.metallic = baseBMetallic.y;
    m.roughness = texelFetch(uGBuffer2, p, s).r;
    m.emissive = vec3(emissiveRG, emissiveBCavity.x);
    m.cavity = emissiveBCavity.y;
    vec3 V = normalize(uCameraPosition - P);
    return shadeSurface(m, P, gbufferUnpackNormal(g0.w), V);
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 background = texelFetch(uBackground, p, 0).rgb;
    if (!isEdge(p)) {
        fragColor = vec4(gbufferCovered(texelFetch(uGBuffer2, p, 0).rg) ? shadeSample(p, 0)
                                                                        : background, 1.0);
        return;
    }
    vec3 sum = vec3(0.0);
    for (int s = 0; s < MATEDIT_GBUFFER_SAMPLES; s++) {
        sum += gbufferCovered(texelFetch(uGBuffer2, p, s).rg) ? shadeSample(p, s) : background;
    }
    fragColor = vec4(sum / float(MATEDIT_GBUFFER_SAMPLES), 1.0);
}
