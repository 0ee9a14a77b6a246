// Normalize node: unit vector along the input; the zero vector stays zero.

void node_normalize(float value, out float result) {
    // GLSL normalize(float) is x / |x|, i.e. the sign; sign(0) = 0 keeps zero
    result = sign(value);
}

void node_normalize(vec2 value, out vec2 result) {
    // GLSL normalize as v * inversesqrt(dot(v, v)); zero stays zero instead of NaN
    float len2 = dot(value, value);
    result = len2 > 0.0 ? value * inversesqrt(len2) : value;
}

void node_normalize(vec3 value, out vec3 result) {
    // GLSL normalize as v * inversesqrt(dot(v, v)); zero stays zero instead of NaN
    float len2 = dot(value, value);
    result = len2 > 0.0 ? value * inversesqrt(len2) : value;
}

void node_normalize(vec4 value, out vec4 result) {
    // GLSL normalize as v * inversesqrt(dot(v, v)); zero stays zero instead of NaN
    float len2 = dot(value, value);
    result = len2 > 0.0 ? value * inversesqrt(len2) : value;
}
