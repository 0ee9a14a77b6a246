// Display transform: exposure, ACES filmic tone curve, sRGB encoding.
// Comparisons between shading modes happen before this, on linear HDR values.
#include "common.glsl"

// Scale linear HDR radiance by 2^EV.
vec3 applyExposure(vec3 color, float exposureEV) {
    // Photographic exposure value: each stop doubles the scene's brightness
    return color * exp2(exposureEV);
}

// ACES filmic tone curve fitted by a rational function, output in [0, 1].
vec3 tonemapACES(vec3 x) {
    // Narkowicz 2015, "ACES Filmic Tone Mapping Curve": (x (a x + b)) / (x (c x + d) + e)
    const float a = 2.51;
    const float b = 0.03;
    const float c = 2.43;
    const float d = 0.59;
    const float e = 0.14;
    // The curve reaches 1 near x = 7.2; bounding x at 1e4 changes no output and keeps the
    // squares finite for any input, an infinity included.
    x = min(max(x, vec3(0.0)), vec3(1e4));
    return saturate((x * (a * x + b)) / (x * (c * x + d) + e));
}

// sRGB opto-electronic transfer function, per channel, input in [0, 1].
float linearToSRGB(float c) {
    // IEC 61966-2-1 (sRGB): 12.92 c below 0.0031308, else 1.055 c^(1/2.4) - 0.055
    c = saturate(c);
    return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

vec3 linearToSRGB(vec3 c) {
    // IEC 61966-2-1 (sRGB), per channel
    return vec3(linearToSRGB(c.r), linearToSRGB(c.g), linearToSRGB(c.b));
}

// The whole display transform: exposure, tone curve, sRGB.
vec3 displayTransform(vec3 hdr, float exposureEV) {
    // docs/shading.md#display: 2^exposure, ACES fit (Narkowicz 2015), sRGB encode
    return linearToSRGB(tonemapACES(applyExposure(hdr, exposureEV)));
}
