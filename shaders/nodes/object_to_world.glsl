// Object to World node.
#include "space_lib.glsl"

void node_object_to_world(vec3 vector, out vec3 result) {
    // A direction through the model matrix's linear part
    result = nodeObjectToWorld() * vector;
}
