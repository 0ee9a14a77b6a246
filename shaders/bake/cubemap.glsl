// Cube map face geometry for the IBL bakes; the numpy twin is matedit/ibl/cubemap.py.

// Unnormalised direction through face coordinates st in [0, 1]^2 of face 0..5 (+X -X +Y -Y +Z -Z).
vec3 cubeFaceDirection(int face, vec2 st) {
    // OpenGL 4.5 core, table 8.19 (cube map face selection), inverted
    vec2 c = 2.0 * st - 1.0;
    if (face == 0) return vec3(1.0, -c.y, -c.x);
    if (face == 1) return vec3(-1.0, -c.y, c.x);
    if (face == 2) return vec3(c.x, 1.0, c.y);
    if (face == 3) return vec3(c.x, -1.0, -c.y);
    if (face == 4) return vec3(c.x, -c.y, 1.0);
    return vec3(-c.x, -c.y, -1.0);
}

// Solid angle of a cube texel of a size x size face, seen in unit direction L.
float cubeTexelSolidAngle(vec3 L, float size) {
    // A texel of side 2 / size on the plane |x| = 1 at distance 1 / ma subtends (2 / size)^2 ma^3.
    vec3 aL = abs(L);
    float ma = max(aL.x, max(aL.y, aL.z));
    return 4.0 * ma * ma * ma / (size * size);
}
