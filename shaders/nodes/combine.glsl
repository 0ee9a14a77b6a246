// Combine node: vectors of two, three and four components from four scalars.

void node_combine(float x, float y, float z, float w, out vec2 xy, out vec3 xyz,
                  out vec4 xyzw) {
    // GLSL vector constructors
    xy = vec2(x, y);
    xyz = vec3(x, y, z);
    xyzw = vec4(x, y, z, w);
}
