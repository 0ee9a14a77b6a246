// Gradient Noise 3D node: Perlin-style noise over a 3D position.
#include "noise_lib.glsl"

void node_gradient_noise_3d(vec3 position, float scale, float seed, out float value) {
    // Perlin 2002 improved noise at position * scale (integer-hashed lattice)
    value = nodeGradientNoise3(position * scale, nodeSeed(seed));
}
