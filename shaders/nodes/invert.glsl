// Invert node.

void node_invert(vec3 color, float amount, out vec3 result) {
    // Complement 1 - x, mixed in by amount
    result = mix(color, 1.0 - color, amount);
}
