// World to Object node.
#include "space_lib.glsl"

void node_world_to_object(vec3 vector, out vec3 result) {
    // A direction through the inverse model matrix's linear part
    result = mat3(nodeWorldToObject()) * vector;
}
