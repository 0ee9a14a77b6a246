// Spherical Gradient node: 1 at the centre, 0 at radius.

void node_spherical_gradient(vec2 uv, vec2 center, float radius, out float value) {
    // Linear fall-off of the distance to the centre
    value = clamp(1.0 - length(uv - center) / max(radius, 1e-6), 0.0, 1.0);
}
