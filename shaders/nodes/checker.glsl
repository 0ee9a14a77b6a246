// Checker node: a two-colour checkerboard, `scale` squares per UV unit.

void node_checker(vec2 uv, float scale, vec3 color_a, vec3 color_b, out vec3 color,
                  out float mask) {
    // Parity of the integer cell, (floor(u s) + floor(v s)) mod 2: 0 -> color_a, 1 -> color_b
    vec2 cell = floor(uv * scale);
    mask = mod(cell.x + cell.y, 2.0);
    color = mix(color_a, color_b, mask);
}
