// Fractal Noise 3D node: fBm of 3D gradient noise.
#include "noise_lib.glsl"

void node_fbm_3d(vec3 position, float scale, float octaves, float lacunarity, float gain,
                 float seed, out float value) {
    // Musgrave's fBm (Ebert et al. 2003), signed sum mapped to 0.5 +/- 0.5
    value = 0.5 + 0.5 * nodeFbm3(position * scale, octaves, lacunarity, gain, nodeSeed(seed));
}
