// Linear to sRGB node.

void node_linear_to_srgb(vec3 color, out vec3 result) {
    // IEC 61966-2-1 inverse EOTF, linear segment below 0.0031308
    vec3 c = max(color, 0.0);
    vec3 lo = c * 12.92;
    vec3 hi = 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055;
    result = mix(hi, lo, vec3(lessThanEqual(c, vec3(0.0031308))));
}
