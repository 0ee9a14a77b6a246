// Stripes node: band-limited parallel stripes.
#include "filter_lib.glsl"

void node_stripes(vec2 uv, float frequency, float width, float angle, float filter_width,
                  out float mask) {
    // A pulse train along the direction of angle, box-filtered over its pixel footprint
    float a = radians(angle);
    float x = dot(uv, vec2(cos(a), sin(a))) * frequency;
    mask = nodeFilteredPulse(x, width, fwidth(x) * filter_width);
}
