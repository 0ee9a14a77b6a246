// Adds one resolved frame into the accumulation target (blending ONE, ONE).
in vec2 v_ndc;
layout(location = 0) out vec4 fragColor;
uniform sampler2D uFrame;
void main() {
    fragColor = vec4(texelFetch(uFrame, ivec2(gl_FragCoord.xy), 0).rgb, 1.0);
}
