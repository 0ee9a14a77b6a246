// World to Tangent node.
#include "space_lib.glsl"

void node_world_to_tangent(vec3 vector, out vec3 result) {
    // Projection on the orthonormal TBN basis (its transpose is its inverse)
    result = vec3(dot(vector, nodeSurfaceTangent()), dot(vector, nodeSurfaceBitangent()),
                  dot(vector, g_surface.normal));
}
