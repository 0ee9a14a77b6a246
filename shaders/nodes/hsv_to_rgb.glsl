// HSV to RGB node.
#include "color_lib.glsl"

void node_hsv_to_rgb(vec3 hsv, out vec3 color) {
    // Hocevar 2012 branchless conversion (Smith 1978's hexcone model)
    color = nodeHsvToRgb(hsv);
}
