// Resample an environment (equirect image or another cube map) onto the faces of a cube map,
// averaging a uSuper x uSuper grid of samples per output texel so a larger source is not aliased.
// Faces uFaceBase, uFaceBase + 1, ... lie side by side in the target, uSize texels wide each.
#include "common.glsl"
#include "bake/cubemap.glsl"

#ifdef SOURCE_CUBE
uniform samplerCube uSource;
#else
uniform sampler2D uSource;
#endif
uniform int uFaceBase;
uniform int uSize;
uniform int uSuper;

out vec4 fragColor;

vec3 sourceRadiance(vec3 d) {
#ifdef SOURCE_CUBE
    return textureLod(uSource, d, 0.0).rgb;
#else
    // matedit/ibl/cubemap.py, equirect convention: +Y up, image centre looks down -Z, row 0 at the zenith.
    d = normalize(d);
    float u = 0.5 + atan(d.x, -d.z) / (2.0 * PI);
    float v = acos(clamp(d.y, -1.0, 1.0)) / PI;
    // Rows are uploaded top row first, so texture t == v.
    return textureLod(uSource, vec2(u, v), 0.0).rgb;
#endif
}

void main() {
    int column = int(gl_FragCoord.x) / uSize;
    int face = uFaceBase + column;
    vec2 texel = floor(gl_FragCoord.xy) - vec2(float(column * uSize), 0.0);
    vec3 sum = vec3(0.0);
    for (int j = 0; j < uSuper; ++j) {
        for (int i = 0; i < uSuper; ++i) {
            vec2 st = (texel + (vec2(i, j) + 0.5) / float(uSuper)) / float(uSize);
            sum += sourceRadiance(cubeFaceDirection(face, st));
        }
    }
    fragColor = vec4(sum / float(uSuper * uSuper), 1.0);
}
