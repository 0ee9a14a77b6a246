// The deferred preview's G-buffer encoding: the GBUFFER entry (entry/gbuffer.frag.glsl) packs
// with these, the lighting pass (render/lighting.frag) unpacks; the layout and the precision of
// each field: matedit/render/deferred.py. packHalf2x16 is GLSL 4.20 / ESSL 3.00: at GLSL 3.30
// the includer's prelude enables GL_ARB_shading_language_packing (matedit.glsl.include.
// PACKING_EXTENSION); the rest is GLSL 3.30.

const float GBUFFER_HALF_MAX = 65504.0;  // the largest finite half

// Two values as halves (11-bit significand: relative error at most 2^-11), clamped to the
// finite half range so that a large emissive does not become infinity.
uint gbufferPackHalf2(float a, float b) {
    return packHalf2x16(clamp(vec2(a, b), -GBUFFER_HALF_MAX, GBUFFER_HALF_MAX));
}

vec2 gbufferUnpackHalf2(uint bits) {
    return unpackHalf2x16(bits);
}

// A unit vector, octahedral-encoded (Cigolle et al. 2014, "A Survey of Efficient
// Representations for Independent Unit Vectors"), 16 bits a coordinate (round(e * 32767),
// as packSnorm2x16) offset to 1..65535.
uint gbufferPackNormal(vec3 n) {
    n /= max(abs(n.x) + abs(n.y) + abs(n.z), 1e-30);
    vec2 e = n.xy;
    if (n.z < 0.0) {
        e = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    }
    uvec2 q = uvec2(round(clamp(e, -1.0, 1.0) * 32767.0) + 32768.0);
    return q.x | (q.y << 16);
}

vec3 gbufferUnpackNormal(uint bits) {
    vec2 e = (vec2(float(bits & 0xFFFFu), float(bits >> 16)) - 32768.0) / 32767.0;
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    if (n.z < 0.0) {
        n.xy = (1.0 - abs(n.yx)) * vec2(e.x >= 0.0 ? 1.0 : -1.0, e.y >= 0.0 ? 1.0 : -1.0);
    }
    return normalize(n);
}

// Whether the material was drawn at a sample: the coverage channel of gbuffer2, 1 where drawn,
// cleared to 0 (a float target: GL leaves clearing an integer one by glClear undefined, so
// the integer targets' values at an uncovered sample are never read).
bool gbufferCovered(vec2 roughnessCoverage) {
    return roughnessCoverage.y > 0.5;
}
