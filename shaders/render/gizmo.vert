// Light gizmos: small unlit shapes drawn in the light's colour.
layout(location = 0) in vec3 a_position;
uniform mat4 uViewProjection;
uniform mat4 uModel;
void main() {
    gl_Position = uViewProjection * uModel * vec4(a_position, 1.0);
}
