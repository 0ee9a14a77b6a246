// Smooth Min node: the minimum with a rounded join of radius smoothness.

void node_smooth_min(float a, float b, float smoothness, out float result) {
    // Quilez, "Smooth minimum" (polynomial): h = clamp(1/2 + (b - a) / 2k), mix - k h (1 - h)
    float k = max(smoothness, 1e-6);
    float h = clamp(0.5 + 0.5 * (b - a) / k, 0.0, 1.0);
    result = mix(b, a, h) - smoothness * h * (1.0 - h);
}

void node_smooth_min(vec2 a, vec2 b, vec2 smoothness, out vec2 result) {
    // Quilez, "Smooth minimum" (polynomial): h = clamp(1/2 + (b - a) / 2k), mix - k h (1 - h)
    vec2 k = max(smoothness, 1e-6);
    vec2 h = clamp(0.5 + 0.5 * (b - a) / k, 0.0, 1.0);
    result = mix(b, a, h) - smoothness * h * (1.0 - h);
}

void node_smooth_min(vec3 a, vec3 b, vec3 smoothness, out vec3 result) {
    // Quilez, "Smooth minimum" (polynomial): h = clamp(1/2 + (b - a) / 2k), mix - k h (1 - h)
    vec3 k = max(smoothness, 1e-6);
    vec3 h = clamp(0.5 + 0.5 * (b - a) / k, 0.0, 1.0);
    result = mix(b, a, h) - smoothness * h * (1.0 - h);
}

void node_smooth_min(vec4 a, vec4 b, vec4 smoothness, out vec4 result) {
    // Quilez, "Smooth minimum" (polynomial): h = clamp(1/2 + (b - a) / 2k), mix - k h (1 - h)
    vec4 k = max(smoothness, 1e-6);
    vec4 h = clamp(0.5 + 0.5 * (b - a) / k, 0.0, 1.0);
    result = mix(b, a, h) - smoothness * h * (1.0 - h);
}
