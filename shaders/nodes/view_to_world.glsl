// View to World node.
#include "space_lib.glsl"

void node_view_to_world(vec3 vector, out vec3 result) {
    // The inverse camera rotation: its transpose
    result = transpose(nodeWorldToView()) * vector;
}
