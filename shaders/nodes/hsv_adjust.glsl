// HSV Adjust node: hue rotation, saturation and value scaling.
#include "color_lib.glsl"

void node_hsv_adjust(vec3 color, float hue, float saturation, float value, out vec3 result) {
    // Smith 1978 hexcone HSV: rotate hue (turns), scale S (clamped to [0, 1]) and V
    vec3 hsv = nodeRgbToHsv(color);
    hsv.x = fract(hsv.x + hue);
    hsv.y = clamp(hsv.y * saturation, 0.0, 1.0);
    hsv.z = hsv.z * value;
    result = nodeHsvToRgb(hsv);
}
