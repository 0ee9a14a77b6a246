// Luminance node: Rec. 709 luminance of a linear colour.
#include "color_lib.glsl"

void node_luminance(vec3 color, out float value) {
    // ITU-R BT.709: Y = 0.2126 R + 0.7152 G + 0.0722 B (linear)
    value = nodeLuminance(color);
}
