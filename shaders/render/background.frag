// The environment behind the preview, optionally blurred by sampling a rougher prefiltered mip.
#include "common.glsl"
in vec2 v_ndc;
layout(location = 0) out vec4 fragColor;
uniform mat4 uInvViewProjection;
uniform samplerCube uEnvironmentCube;
uniform float uLod;
uniform float uIntensity;
void main() {
    vec4 far = uInvViewProjection * vec4(v_ndc, 1.0, 1.0);
    vec4 near = uInvViewProjection * vec4(v_ndc, -1.0, 1.0);
    vec3 dir = normalize(far.xyz / far.w - near.xyz / near.w);
    fragColor = vec4(textureLod(uEnvironmentCube, dir, uLod).rgb * uIntensity, 1.0);
}
