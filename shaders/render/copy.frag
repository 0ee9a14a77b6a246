// One-sample texture into every sample of the bound target, pixel for pixel: the deferred
// preview's background where its lighting pass does not reach (matedit/render/scene.py).
in vec2 v_ndc;
layout(location = 0) out vec4 fragColor;
uniform sampler2D uSource;
void main() {
    fragColor = vec4(texelFetch(uSource, ivec2(gl_FragCoord.xy), 0).rgb, 1.0);
}
