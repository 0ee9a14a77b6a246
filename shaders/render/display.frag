// Display pass: linear HDR (optionally an accumulation to average) to the screen, or a
// heat map of the difference between two HDR images.
#include "output.glsl"
in vec2 v_ndc;
layout(location = 0) out vec4 fragColor;
uniform sampler2D uImage;      // linear HDR, or the accumulated sum
uniform sampler2D uReference;  // difference mode: the accumulated reference sum
uniform float uScale;          // 1 / frames accumulated in uImage
uniform float uReferenceScale; // 1 / frames accumulated in uReference
uniform float uExposure;
uniform int uMode;             // 0 image, 1 difference heat map
uniform float uHeatRange;      // difference that maps to the top of the heat map

vec3 heat(float t) {
    // A perceptually ordered ramp: black, blue, magenta, orange, yellow, white
    t = saturate(t);
    vec3 c0 = vec3(0.0, 0.0, 0.0);
    vec3 c1 = vec3(0.1, 0.1, 0.6);
    vec3 c2 = vec3(0.7, 0.1, 0.6);
    vec3 c3 = vec3(1.0, 0.5, 0.1);
    vec3 c4 = vec3(1.0, 1.0, 0.6);
    if (t < 0.25) return mix(c0, c1, t / 0.25);
    if (t < 0.5) return mix(c1, c2, (t - 0.25) / 0.25);
    if (t < 0.75) return mix(c2, c3, (t - 0.5) / 0.25);
    return mix(c3, c4, (t - 0.75) / 0.25);
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 a = texelFetch(uImage, p, 0).rgb * uScale;
    if (uMode == 1) {
        vec3 b = texelFetch(uReference, p, 0).rgb * uReferenceScale;
        float d = dot(abs(a - b), vec3(1.0 / 3.0));
        fragColor = vec4(heat(d / uHeatRange), 1.0);
    } else {
        fragColor = vec4(displayTransform(a, uExposure), 1.0);
    }
}
