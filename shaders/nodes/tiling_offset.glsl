// Tiling and Offset node.

void node_tiling_offset(vec2 uv, vec2 tiling, vec2 offset, out vec2 result) {
    // Affine UV transform: scale about the origin, then shift
    result = uv * tiling + offset;
}
