// Object Position node.
#include "space_lib.glsl"

void node_object_position(out vec3 position) {
    // World position through the inverse model matrix
    position = (nodeWorldToObject() * vec4(g_surface.position, 1.0)).xyz;
}
