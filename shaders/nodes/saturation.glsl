// Saturation node.
#include "color_lib.glsl"

void node_saturation(vec3 color, float amount, out vec3 result) {
    // Mix from the Rec. 709 luminance grey (0) to the colour (1), extrapolating beyond
    result = mix(vec3(nodeLuminance(color)), color, amount);
}
