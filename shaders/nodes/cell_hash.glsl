// Random per Cell node: a random value and colour per integer cell.
#include "noise_lib.glsl"

void node_cell_hash(vec2 cell, float seed, out float value, out vec3 color) {
    // Jarzynski & Olano 2020: nested pcg of floor(cell)
    highp uint h = nodeHashCell2(ivec2(floor(cell)), nodeSeed(seed));
    highp uint h2 = nodeHashPcg(h);
    highp uint h3 = nodeHashPcg(h2);
    value = nodeHashUnit(h);
    color = vec3(nodeHashUnit(h), nodeHashUnit(h2), nodeHashUnit(h3));
}
