// Gamma node.

void node_gamma(vec3 color, float gamma, out vec3 result) {
    // Power law x^gamma; negative components read 0 (pow is undefined there)
    result = pow(max(color, 0.0), vec3(gamma));
}
