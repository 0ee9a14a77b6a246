// Rotate UV node.

void node_rotate_uv(vec2 uv, float angle, vec2 pivot, out vec2 result) {
    // 2D rotation matrix about the pivot, counter-clockwise in degrees
    float a = radians(angle);
    float c = cos(a);
    float s = sin(a);
    vec2 d = uv - pivot;
    result = pivot + vec2(c * d.x - s * d.y, s * d.x + c * d.y);
}
