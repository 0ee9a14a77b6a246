// GGX prefiltering of one mip of the specular environment (split sum, left factor).
// Faces uFaceBase, uFaceBase + 1, ... lie side by side in the target, uSize texels wide each.
//
// Karis 2013, "Real Shading in Unreal Engine 4", PrefilterEnvMap: N = V = R. With N = V every
// sample's L, NoL and pdf are the same in N's tangent frame whatever N is, so they come from a
// table made once a mip (matedit/ibl/gpu.py, ggx_sample_table); the source mip of each sample
// follows from its pdf and the texel solid angle at L (filtered importance sampling, Colbert
// and Krivanek, GPU Gems 3, ch. 20), of which only the texel's max |L|^3 depends on N.
#include "common.glsl"
#include "sampling.glsl"
#include "bake/cubemap.glsl"

#define TABLE_ROWS 1024

uniform samplerCube uSource;   // the environment, with a full mip chain
uniform float uMaxSourceLod;   // its last mip level
uniform int uFaceBase;         // the face at x = 0
uniform int uSize;             // face size of the mip being written
uniform int uCount;            // table rows used, at most TABLE_ROWS
uniform float uScale;          // 1 / (sum of NoL over the whole sample set)

// Row i: (L.x, L.y, L.z = NoL, lod of the sample where the source texel is a face centre's),
// L in the frame (T, B, N) of tangentFrame.
layout(std140) uniform SampleTable {
    vec4 uTable[TABLE_ROWS];
};

out vec4 fragColor;

void main() {
    int column = int(gl_FragCoord.x) / uSize;
    vec2 st = vec2(gl_FragCoord.x - float(column * uSize), gl_FragCoord.y) / float(uSize);
    vec3 N = normalize(cubeFaceDirection(uFaceBase + column, st));
    vec3 T;
    vec3 B;
    tangentFrame(N, T, B);
    vec3 sum = vec3(0.0);
    for (int i = 0; i < uCount; ++i) {
        vec4 s = uTable[i];
        vec3 L = T * s.x + B * s.y + N * s.z;
        // cubeTexelSolidAngle(L, size) = 4 ma^3 / size^2: its 0.5 log2 apart from the table's
        vec3 aL = abs(L);
        float ma = max(aL.x, max(aL.y, aL.z));
        float lod = clamp(s.w - 1.5 * log2(ma), 0.0, uMaxSourceLod);
        sum += textureLod(uSource, L, lod).rgb * s.z;
    }
    fragColor = vec4(sum * uScale, 1.0);
}
