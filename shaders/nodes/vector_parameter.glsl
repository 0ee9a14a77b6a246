// Vector Parameter node: the uniform's value, whole and as xyz.

void node_vector_parameter(vec4 value, out vec4 result, out vec3 xyz) {
    // Pass-through of the vec4 uniform the compiler binds to `value`
    result = value;
    xyz = value.xyz;
}
