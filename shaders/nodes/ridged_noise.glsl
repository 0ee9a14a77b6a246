// Ridged Noise node: ridged multifractal of 2D gradient noise.
#include "noise_lib.glsl"

void node_ridged_noise(vec2 uv, float scale, float octaves, float lacunarity, float gain,
                       float seed, out float value) {
    // Musgrave, in Ebert et al. 2003, ch. 16: ridges (1 - |n|)^2 per octave, summed with
    // amplitudes gain^k and divided by their sum (in [0, 1])
    float n = clamp(octaves, 1.0, float(NODE_FBM_MAX_OCTAVES));
    highp uint s = nodeSeed(seed);
    float sum = 0.0;
    float norm = 0.0;
    float amplitude = 1.0;
    vec2 q = uv * scale;
    for (int k = 0; k < NODE_FBM_MAX_OCTAVES; ++k) {
        float w = clamp(n - float(k), 0.0, 1.0) * amplitude;
        if (w <= 0.0) {
            break;
        }
        float r = 1.0 - abs(nodeGradientNoise2(q, s + uint(k)));
        sum += w * r * r;
        norm += w;
        amplitude *= gain;
        q *= lacunarity;
    }
    value = norm > 0.0 ? sum / norm : 0.0;
}
