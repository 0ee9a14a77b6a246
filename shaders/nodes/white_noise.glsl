// White Noise node: a random value per distinct input, from its bits.
#include "noise_lib.glsl"

void node_white_noise(vec3 input_value, float seed, out float value, out vec3 color) {
    // Jarzynski & Olano 2020: nested pcg of the input's IEEE-754 bit patterns
    highp uvec3 b = floatBitsToUint(input_value);
    highp uint s = nodeSeed(seed);
    highp uint h = nodeHashPcg(b.x + nodeHashPcg(b.y + nodeHashPcg(b.z + s)));
    highp uint h2 = nodeHashPcg(h);
    highp uint h3 = nodeHashPcg(h2);
    value = nodeHashUnit(h);
    color = vec3(nodeHashUnit(h), nodeHashUnit(h2), nodeHashUnit(h3));
}
