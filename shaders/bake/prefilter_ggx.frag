// GGX prefiltering of one face of one mip of the specular environment (split sum, left factor).
#include "common.glsl"
#include "sampling.glsl"
#include "bake/cubemap.glsl"

uniform samplerCube uSource;   // the environment, with a full mip chain
uniform float uSourceSize;     // face size of the source's level 0
uniform float uMaxSourceLod;   // its last mip level
uniform float uLodBias;        // extra blur in source mips (filtered importance sampling)
uniform int uFace;
uniform int uSize;             // face size of the mip being written
uniform float uRoughness;      // perceptual roughness of this mip
uniform int uSamples;

out vec4 fragColor;

float bakeD_GGX(float NoH, float a) {
    // Karis 2013, eq 3: GGX / Trowbridge-Reitz, a = roughness^2
    float a2 = a * a;
    float d = NoH * NoH * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

void main() {
    // Karis 2013, "Real Shading in Unreal Engine 4", PrefilterEnvMap (N = V = R), with the source
    // mip chosen from each sample's pdf and texel solid angle (Colbert and Krivanek, GPU Gems 3, ch. 20)
    vec2 st = gl_FragCoord.xy / float(uSize);
    vec3 N = normalize(cubeFaceDirection(uFace, st));
    vec3 V = N;
    float a = uRoughness * uRoughness;
    uint n = uint(uSamples);
    vec3 sum = vec3(0.0);
    float weight = 0.0;
    for (uint i = 0u; i < n; ++i) {
        vec3 H = importanceSampleGGX(hammersley(i, n), a, N);
        float VoH = dot(V, H);
        vec3 L = 2.0 * VoH * H - V;
        float NoL = dot(N, L);
        if (NoL > 0.0) {
            // pdf of L = D NoH / (4 VoH), and NoH == VoH here because N == V
            float pdf = 0.25 * bakeD_GGX(VoH, a);
            float omegaS = 1.0 / (float(n) * pdf);
            float omegaP = cubeTexelSolidAngle(L, uSourceSize);
            float lod = clamp(0.5 * log2(omegaS / omegaP) + uLodBias, 0.0, uMaxSourceLod);
            sum += textureLod(uSource, L, lod).rgb * NoL;
            weight += NoL;
        }
    }
    fragColor = vec4(sum / max(weight, 1e-20), 1.0);
}
