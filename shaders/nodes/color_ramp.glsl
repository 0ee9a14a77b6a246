// Colour Ramp node: a value through up to six (position, colour) stops.

void node_color_ramp(float value, float stops, float position0, float position1,
                     float position2, float position3, float position4, float position5,
                     vec3 color0, vec3 color1, vec3 color2, vec3 color3, vec3 color4,
                     vec3 color5, out vec3 color) {
    // Piecewise-linear interpolation between sorted stops: start at stop 0, then for
    // each further stop in use mix towards it by the clamped position between its
    // neighbours (a zero-width gap is a hard step)
    float p[6] = float[6](position0, position1, position2, position3, position4, position5);
    vec3 c[6] = vec3[6](color0, color1, color2, color3, color4, color5);
    int n = int(clamp(floor(stops), 2.0, 6.0));
    color = c[0];
    for (int k = 1; k < 6; ++k) {
        if (k >= n) {
            break;
        }
        float gap = p[k] - p[k - 1];
        float t = gap > 0.0 ? clamp((value - p[k - 1]) / gap, 0.0, 1.0) : step(p[k], value);
        color = mix(color, c[k], t);
    }
}
