// Texture Coordinate node: the mesh's UV set 0, tiled and offset.
#include "context.glsl"

void node_texcoord(vec2 tiling, vec2 offset, out vec2 uv) {
    // Affine UV transform: scale about the origin, then shift (UE4 TexCoord tiling)
    uv = g_surface.uv * tiling + offset;
}
