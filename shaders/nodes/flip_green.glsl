// Flip Green node.

void node_flip_green(vec3 normal, out vec3 result) {
    // DirectX (+Y down) and OpenGL (+Y up) normal maps differ in the sign of Y
    result = vec3(normal.x, -normal.y, normal.z);
}
