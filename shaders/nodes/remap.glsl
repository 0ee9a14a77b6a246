// Remap node: linear map of [in_min, in_max] onto [out_min, out_max], unclamped.
// An empty input range divides by zero (the GPU's infinity), as the Divide node does.

void node_remap(float value, float in_min, float in_max, float out_min, float out_max,
                out float result) {
    // Linear interpolation of the normalised position t = (value - in_min) / (in_max - in_min)
    result = out_min + (value - in_min) / (in_max - in_min) * (out_max - out_min);
}

void node_remap(vec2 value, vec2 in_min, vec2 in_max, vec2 out_min, vec2 out_max,
                out vec2 result) {
    // Linear interpolation of the normalised position t = (value - in_min) / (in_max - in_min)
    result = out_min + (value - in_min) / (in_max - in_min) * (out_max - out_min);
}

void node_remap(vec3 value, vec3 in_min, vec3 in_max, vec3 out_min, vec3 out_max,
                out vec3 result) {
    // Linear interpolation of the normalised position t = (value - in_min) / (in_max - in_min)
    result = out_min + (value - in_min) / (in_max - in_min) * (out_max - out_min);
}

void node_remap(vec4 value, vec4 in_min, vec4 in_max, vec4 out_min, vec4 out_max,
                out vec4 result) {
    // Linear interpolation of the normalised position t = (value - in_min) / (in_max - in_min)
    result = out_min + (value - in_min) / (in_max - in_min) * (out_max - out_min);
}
