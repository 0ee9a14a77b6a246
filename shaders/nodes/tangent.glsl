// Tangent node.
#include "space_lib.glsl"

void node_tangent(out vec3 tangent) {
    // Gram-Schmidt orthogonalised mesh tangent (Mikkelsen 2008)
    tangent = nodeSurfaceTangent();
}
