// Rings node: concentric sine rings about a centre, distorted by noise.
#include "noise_lib.glsl"

void node_rings(vec2 uv, vec2 center, float frequency, float distortion, float detail_scale,
                out float value, out float saw) {
    // Blender-style wave texture (rings): phase from the distance to the centre plus fBm
    float x = length(uv - center) * frequency;
    x += distortion * nodeFbm2(uv * detail_scale, 3.0, 2.0, 0.5, 7u);
    saw = x - floor(x);
    value = 0.5 - 0.5 * cos(6.28318531 * saw);
}
