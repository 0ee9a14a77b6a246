// Levels node: input black/white points, midtone gamma, output range.

void node_levels(vec3 color, float in_black, float in_white, float gamma, float out_black,
                 float out_white, out vec3 result) {
    // Image-editor levels: normalise to the input range (clamped), apply 1/gamma, remap
    float range = max(in_white - in_black, 1e-5);
    vec3 t = clamp((color - in_black) / range, 0.0, 1.0);
    t = pow(t, vec3(1.0 / max(gamma, 1e-3)));
    result = mix(vec3(out_black), vec3(out_white), t);
}
