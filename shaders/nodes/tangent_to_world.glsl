// Tangent to World node.
#include "space_lib.glsl"

void node_tangent_to_world(vec3 vector, out vec3 result) {
    // The TBN basis: x along T, y along B, z along N
    result = nodeSurfaceTangent() * vector.x + nodeSurfaceBitangent() * vector.y
           + g_surface.normal * vector.z;
}
