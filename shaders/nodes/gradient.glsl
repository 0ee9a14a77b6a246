// Gradient node: a linear ramp over the UV square along an angle (degrees, counter-clockwise
// from +u). The ramp is fitted to the square: the corner furthest behind reads 0, the one
// furthest ahead reads 1, at any angle; outside the square it clamps.

void node_gradient(vec2 uv, float angle, out float value) {
    // Projection onto d = (cos a, sin a) about the square's centre; the unit square's
    // projection onto d has length |cos a| + |sin a|, which maps it onto [0, 1]
    float a = radians(angle);
    vec2 d = vec2(cos(a), sin(a));
    float extent = abs(d.x) + abs(d.y);
    value = clamp(dot(uv - 0.5, d) / extent + 0.5, 0.0, 1.0);
}
