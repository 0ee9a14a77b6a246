// Split node: the components of a float or vector; components it lacks read 0.

void node_split(float value, out float x, out float y, out float z, out float w) {
    // Missing components read 0 (not GLSL's vec4(v) splat, which would repeat the float)
    x = value;
    y = 0.0;
    z = 0.0;
    w = 0.0;
}

void node_split(vec2 value, out float x, out float y, out float z, out float w) {
    // Missing components read 0
    x = value.x;
    y = value.y;
    z = 0.0;
    w = 0.0;
}

void node_split(vec3 value, out float x, out float y, out float z, out float w) {
    // Missing components read 0
    x = value.x;
    y = value.y;
    z = value.z;
    w = 0.0;
}

void node_split(vec4 value, out float x, out float y, out float z, out float w) {
    // All four components present
    x = value.x;
    y = value.y;
    z = value.z;
    w = value.w;
}
