// Cellular Noise 3D node: Worley noise over a 3D position.
#include "noise_lib.glsl"

void node_cellular_noise_3d(vec3 position, float scale, float jitter, float seed,
                            out float f1, out float f2, out float edge, out float cell_id) {
    // Worley 1996: F1, F2 and F2 - F1 over the 3 x 3 x 3 neighbourhood
    nodeCellular3(position * scale, jitter, nodeSeed(seed), f1, f2, cell_id);
    edge = f2 - f1;
}
