// Deferred lighting: shadeSurface (surface.glsl: analytic lights, split-sum or reference IBL)
// applied to the G-buffer the material's GBUFFER entry wrote (shaders/entry/gbuffer.frag.glsl),
// in a full-screen pass. Linked once per variant, whatever the material.
//
// Anti-aliasing: the G-buffer is multisampled like the forward target, and the pass runs once a
// pixel. A pixel whose samples all hold the same values (inside a triangle, or all background)
// is shaded once; a pixel whose samples differ (a silhouette, or two triangles meeting) is
// shaded per sample from each sample's own values, uncovered samples taking the background,
// and the average is written. Every sample of the target gets the pixel's colour, so the
// resolve gives what the forward pass's resolve gives: the average of the samples' colours.
#include "surface.glsl"
#include "gbuffer.glsl"

in vec2 v_ndc;
layout(location = 0) out vec4 fragColor;
// the G-buffer, packed (shaders/gbuffer.glsl; layout: matedit/render/deferred.py)
uniform usampler2DMS uGBuffer0;  // world position (m, float32 bits), normal + coverage
uniform usampler2DMS uGBuffer1;  // halves: baseColor, metallic, emissive, cavity
uniform sampler2DMS uGBuffer2;   // roughness (float32)
uniform sampler2D uBackground;  // the environment behind the mesh, one sample a pixel
uniform vec3 uCameraPosition;   // eye in world space (m), FrameBlock's cameraPosition.xyz

#ifndef MATEDIT_GBUFFER_SAMPLES
#define MATEDIT_GBUFFER_SAMPLES 4
#endif

bool sameAsFirst(ivec2 p, int s) {
    // matedit deferred pass: exact equality of the stored bits (what the lighting reads)
    return texelFetch(uGBuffer0, p, s) == texelFetch(uGBuffer0, p, 0)
        && texelFetch(uGBuffer1, p, s) == texelFetch(uGBuffer1, p, 0)
        && texelFetch(uGBuffer2, p, s).r == texelFetch(uGBuffer2, p, 0).r;
}

bool isEdge(ivec2 p) {
    // matedit deferred pass: a pixel whose samples do not all agree
#ifdef MATEDIT_EDGES_ONCE
    return false;  // benchmarks/bench_render.py: the cost of lighting edges per sample
#endif
    for (int s = 1; s < MATEDIT_GBUFFER_SAMPLES; s++) {
        if (!sameAsFirst(p, s)) return true;
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
        fragColor = vec4(gbufferCovered(texelFetch(uGBuffer0, p, 0).w) ? shadeSample(p, 0)
                                                                       : background, 1.0);
        return;
    }
    vec3 sum = vec3(0.0);
    for (int s = 0; s < MATEDIT_GBUFFER_SAMPLES; s++) {
        sum += gbufferCovered(texelFetch(uGBuffer0, p, s).w) ? shadeSample(p, s) : background;
    }
    fragColor = vec4(sum / float(MATEDIT_GBUFFER_SAMPLES), 1.0);
}
