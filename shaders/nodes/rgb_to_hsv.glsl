// RGB to HSV node.
#include "color_lib.glsl"

void node_rgb_to_hsv(vec3 color, out vec3 hsv) {
    // Hocevar 2012 branchless conversion (Smith 1978's hexcone model)
    hsv = nodeRgbToHsv(color);
}
