// Filtered Step node: an anti-aliased threshold.
#include "filter_lib.glsl"

void node_filtered_step(float edge, float value, float filter_width, out float result) {
    // Box-filtered step over the pixel footprint of value (fwidth)
    result = nodeFilteredStep(edge, value, fwidth(value) * filter_width);
}
