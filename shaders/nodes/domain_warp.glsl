// Domain Warp node: uv displaced by fractal noise.
#include "noise_lib.glsl"

void node_domain_warp(vec2 uv, float scale, float strength, float octaves, float seed,
                      out vec2 uv_out) {
    // Quilez, "Domain warping" (2002): p + s (fbm(p), fbm(p + offset)), here with two
    // independently seeded fBm fields instead of an offset
    highp uint s = nodeSeed(seed) * 2u;
    vec2 p = uv * scale;
    vec2 d = vec2(nodeFbm2(p, octaves, 2.0, 0.5, s), nodeFbm2(p, octaves, 2.0, 0.5, s + 101u));
    uv_out = uv + strength * d;
}
