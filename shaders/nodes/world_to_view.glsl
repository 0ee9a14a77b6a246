// World to View node.
#include "space_lib.glsl"

void node_world_to_view(vec3 vector, out vec3 result) {
    // The camera rotation (right-handed view space, -z forward)
    result = nodeWorldToView() * vector;
}
