// Deferred lighting: shadeSurface (surface.glsl: analytic lights, split-sum or reference IBL)
// applied to the G-buffer the material's GBUFFER entry wrote (shaders/entry/gbuffer.frag.glsl),
// in a full-screen pass. Linked once per variant, whatever the material.
//
// Anti-aliasing: the G-buffer is multisampled like the forward target. A pixel whose samples
// all hold the same values (the interior of a triangle) is shaded once and written to every
// sample, as a forward fragment would be; a pixel whose samples differ (a silhouette, or two
// triangles meeting) is left to the MATEDIT_PER_SAMPLE variant, which runs per sample
// (ARB_sample_shading's gl_SampleID) and shades each covered sample from its own values. So
// every sample receives the colour the forward pass gives it; uncovered samples keep the
// background drawn before.
#include "surface.glsl"

in vec2 v_ndc;
layout(location = 0) out vec4 fragColor;
uniform sampler2DMS uGBuffer0;  // baseColor, metallic
uniform sampler2DMS uGBuffer1;  // world-space shading normal, roughness
uniform sampler2DMS uGBuffer2;  // emissive, cavity
uniform sampler2DMS uGBuffer3;  // world position (m), coverage (1 where the mesh was drawn)
uniform vec3 uCameraPosition;   // eye in world space (m), FrameBlock's cameraPosition.xyz

#ifndef MATEDIT_GBUFFER_SAMPLES
#define MATEDIT_GBUFFER_SAMPLES 4
#endif

bool sameAsFirst(ivec2 p, int s) {
    // matedit deferred pass: exact equality, the values are float32 copies
    return texelFetch(uGBuffer0, p, s) == texelFetch(uGBuffer0, p, 0)
        && texelFetch(uGBuffer1, p, s) == texelFetch(uGBuffer1, p, 0)
        && texelFetch(uGBuffer2, p, s) == texelFetch(uGBuffer2, p, 0)
        && texelFetch(uGBuffer3, p, s) == texelFetch(uGBuffer3, p, 0);
}

bool isEdge(ivec2 p) {
    // matedit deferred pass: a pixel whose samples do not all agree
    for (int s = 1; s < MATEDIT_GBUFFER_SAMPLES; s++) {
        if (!sameAsFirst(p, s)) return true;
    }
    return false;
}

vec3 shadeSample(ivec2 p, int s) {
    // matedit deferred pass: the G-buffer's values back into shadeSurface's arguments
    vec4 g0 = texelFetch(uGBuffer0, p, s);
    vec4 g1 = texelFetch(uGBuffer1, p, s);
    vec4 g2 = texelFetch(uGBuffer2, p, s);
    vec3 P = texelFetch(uGBuffer3, p, s).xyz;
    MaterialAttributes m = defaultMaterialAttributes();
    m.baseColor = g0.rgb;
    m.metallic = g0.a;
    m.roughness = g1.a;
    m.emissive = g2.rgb;
    m.cavity = g2.a;
    vec3 V = normalize(uCameraPosition - P);
    return shadeSurface(m, P, g1.xyz, V);
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
#ifdef MATEDIT_PER_SAMPLE
    int s = gl_SampleID;
    if (!isEdge(p) || texelFetch(uGBuffer3, p, s).w < 0.5) discard;
    fragColor = vec4(shadeSample(p, s), 1.0);
#else
    if (texelFetch(uGBuffer3, p, 0).w < 0.5 || isEdge(p)) discard;
    fragColor = vec4(shadeSample(p, 0), 1.0);
#endif
}
