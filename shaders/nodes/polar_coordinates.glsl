// Polar Coordinates node.

void node_polar_coordinates(vec2 uv, vec2 center, out vec2 result) {
    // (atan2 in turns, radius) of the offset from the centre
    vec2 d = uv - center;
    bool at_centre = d.x == 0.0 && d.y == 0.0;
    result = vec2(at_centre ? 0.0 : fract(atan(d.y, d.x) * 0.15915494), length(d));
}
