// Cellular Noise node: 2D Worley noise with a filtered border mask.
#include "noise_lib.glsl"
#include "filter_lib.glsl"

void node_cellular_noise(vec2 uv, float scale, float jitter, float edge_width, float seed,
                         float filter_width, out float f1, out float f2, out float edge,
                         out float cell_id, out float edges) {
    // Worley 1996: F1, F2 and F2 - F1 (zero on the borders between cells); the border mask
    // is 1 - step(edge_width, F2 - F1), box-filtered over the footprint of F2 - F1
    nodeCellular2(uv * scale, jitter, nodeSeed(seed), f1, f2, cell_id);
    edge = f2 - f1;
    edges = 1.0 - nodeFilteredStep(edge_width, edge, fwidth(edge) * filter_width);
}
