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

bool sameAsFirst(ivec2 p, int s) {
    // matedit deferred pass: the sample within the thresholds above of sample 0
    vec4 a3 = texelFetch(uGBuffer3, p, 0);
    vec4 b3 = texelFetch(uGBuffer3, p, s);
    if ((a3.w < 0.5) != (b3.w < 0.5)) return false;
    if (a3.w < 0.5) return true;
    if (distance(a3.xyz, b3.xyz) > EDGE_POSITION * distance(a3.xyz, uCameraPosition)) {
        return false;
    }
    vec4 a1 = texelFetch(uGBuffer1, p, 0);
    vec4 b1 = texelFetch(uGBuffer1, p, s);
    if (dot(a1.xyz, b1.xyz) < EDGE_NORMAL_COS || abs(a1.w - b1.w) > EDGE_VALUE) return false;
    vec4 d0 = abs(texelFetch(uGBuffer0, p, s) - texelFetch(uGBuffer0, p, 0));
    vec4 a2 = texelFetch(uGBuffer2, p, 0);
    vec4 d2 = abs(texelFetch(uGBuffer2, p, s) - a2);
    return all(lessThanEqual(d0, vec4(EDGE_VALUE)))
        && all(lessThanEqual(d2.rgb, EDGE_VALUE * max(vec3(1.0), abs(a2.rgb))))
        && d2.a <= EDGE_VALUE;
}

bool isEdge(ivec2 p) {
    // matedit deferred pass: a pixel whose samples do not all show the same surface
#ifdef MATEDIT_EDGES_ONCE
    return false;  // benchmarks/bench_render.py: the cost of lighting edges per sample
#endif
    // Inside one triangle every sample holds a copy of one fragment: equal positions (and
    // coverage) settle most pixels with one target's fetches.
    vec4 first = texelFetch(uGBuffer3, p, 0);
    bool copies = true;
    for (int s = 1; s < MATEDIT_GBUFFER_SAMPLES; s++) {
        copies = copies && texelFetch(uGBuffer3, p, s) == first;
    }
    if (copies) return false;
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
