// Fractal Noise node: fBm of 2D gradient noise.
#include "noise_lib.glsl"

void node_fbm(vec2 uv, float scale, float octaves, float lacunarity, float gain, float seed,
              out float value) {
    // Musgrave's fBm (Ebert et al. 2003), signed sum mapped to 0.5 +/- 0.5
    value = 0.5 + 0.5 * nodeFbm2(uv * scale, octaves, lacunarity, gain, nodeSeed(seed));
}
