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

in vec2 v_ndc;
layout(location = 0) out vec4 fragColor;
uniform sampler2DMS uGBuffer0;  // baseColor, metallic
uniform sampler2DMS uGBuffer1;  // world-space shading normal, roughness
uniform sampler2DMS uGBuffer2;  // emissive, cavity
uniform sampler2DMS uGBuffer3;  // world position (m), coverage (1 where the mesh was drawn)
uniform sampler2D uBackground;  // the environment behind the mesh, one sample a pixel
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
    vec3 background = texelFetch(uBackground, p, 0).rgb;
    if (!isEdge(p)) {
        fragColor = vec4(texelFetch(uGBuffer3, p, 0).w < 0.5 ? background : shadeSample(p, 0),
                         1.0);
        return;
    }
    vec3 sum = vec3(0.0);
    for (int s = 0; s < MATEDIT_GBUFFER_SAMPLES; s++) {
        sum += texelFetch(uGBuffer3, p, s).w < 0.5 ? background : shadeSample(p, s);
    }
    fragColor = vec4(sum / float(MATEDIT_GBUFFER_SAMPLES), 1.0);
}
