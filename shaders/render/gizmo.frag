// Light gizmos: flat emissive colour (linear HDR).
layout(location = 0) out vec4 fragColor;
uniform vec3 uColor;
void main() {
    fragColor = vec4(uColor, 1.0);
}
