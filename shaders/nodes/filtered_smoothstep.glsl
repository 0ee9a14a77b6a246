// Filtered Smooth Step node: smoothstep widened by the pixel footprint.

void node_filtered_smoothstep(float edge0, float edge1, float value, float filter_width,
                              out float result) {
    // Hermite ramp over [edge0 - w/2, edge1 + w/2], w the footprint of value; a hard
    // step when the widened ramp is empty
    float w = fwidth(value) * filter_width;
    float a = edge0 - 0.5 * w;
    float b = edge1 + 0.5 * w;
    float t = b > a ? clamp((value - a) / (b - a), 0.0, 1.0) : step(edge0, value);
    result = t * t * (3.0 - 2.0 * t);
}
