// sRGB to Linear node.

void node_srgb_to_linear(vec3 color, out vec3 result) {
    // IEC 61966-2-1 sRGB EOTF, linear segment below 0.04045
    vec3 c = max(color, 0.0);
    vec3 lo = c / 12.92;
    vec3 hi = pow((c + 0.055) / 1.055, vec3(2.4));
    result = mix(hi, lo, vec3(lessThanEqual(c, vec3(0.04045))));
}
