// Wave node: sine bands along an angle, distorted by noise.
#include "noise_lib.glsl"

void node_wave(vec2 uv, float frequency, float angle, float distortion, float detail_scale,
               out float value, out float saw) {
    // Blender-style wave texture (bands): phase along a direction plus fBm distortion;
    // the sine is taken of the phase reduced to one period, exact far from the origin
    float a = radians(angle);
    float x = dot(uv, vec2(cos(a), sin(a))) * frequency;
    x += distortion * nodeFbm2(uv * detail_scale, 3.0, 2.0, 0.5, 0u);
    saw = x - floor(x);
    value = 0.5 - 0.5 * cos(6.28318531 * saw);
}
