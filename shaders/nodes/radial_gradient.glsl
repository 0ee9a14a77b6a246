// Radial Gradient node: the angle about a centre, in turns.

void node_radial_gradient(vec2 uv, vec2 center, out float value) {
    // atan2 of the offset from the centre, as a fraction of a turn in [0, 1)
    vec2 d = uv - center;
    bool at_centre = d.x == 0.0 && d.y == 0.0;
    value = at_centre ? 0.0 : fract(atan(d.y, d.x) * 0.15915494);
}
