// Gradient Noise node: 2D Perlin-style noise over uv.
#include "noise_lib.glsl"

void node_gradient_noise(vec2 uv, float scale, float seed, out float value) {
    // Perlin 2002 gradient noise at uv * scale (integer-hashed lattice)
    value = nodeGradientNoise2(uv * scale, nodeSeed(seed));
}
