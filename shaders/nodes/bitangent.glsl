// Bitangent node.
#include "space_lib.glsl"

void node_bitangent(out vec3 bitangent) {
    // Mikkelsen 2008: sign * (N x T)
    bitangent = nodeSurfaceBitangent();
}
