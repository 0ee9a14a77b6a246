// Shared colour helpers (not a node kind): HSV conversions and luminance.

vec3 nodeRgbToHsv(vec3 c) {
    // Hocevar, "Fast branchless RGB to HSV conversion in GLSL" (2012); hue in turns
    vec4 k = vec4(0.0, -1.0 / 3.0, 2.0 / 3.0, -1.0);
    vec4 p = c.g < c.b ? vec4(c.bg, k.wz) : vec4(c.gb, k.xy);
    vec4 q = c.r < p.x ? vec4(p.xyw, c.r) : vec4(c.r, p.yzx);
    float d = q.x - min(q.w, q.y);
    float e = 1.0e-10;
    return vec3(abs(q.z + (q.w - q.y) / (6.0 * d + e)), d / (q.x + e), q.x);
}

vec3 nodeHsvToRgb(vec3 c) {
    // Hocevar 2012: hue as three offset triangle waves, then saturation and value
    vec4 k = vec4(1.0, 2.0 / 3.0, 1.0 / 3.0, 3.0);
    vec3 p = abs(fract(c.xxx + k.xyz) * 6.0 - k.www);
    return c.z * mix(k.xxx, clamp(p - k.xxx, 0.0, 1.0), c.y);
}

float nodeLuminance(vec3 c) {
    // ITU-R BT.709 luma coefficients on linear RGB
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}
