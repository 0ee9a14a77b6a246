// Environment BRDF LUT (split sum, right factor): A in R, B in G; x = NoV, y = roughness.
// Third (blue) channel: the Charlie sheen's directional albedo and DFG term, integrateSheen.
// The quadrature is explained in matedit/ibl/lut.py; with LUT_HAMMERSLEY defined, the notes'
// plain Monte Carlo estimator is used instead (kept for comparison).
#include "common.glsl"
#include "sampling.glsl"
#include "sheen.glsl"

#ifndef S_NODES
#define S_NODES 4
#endif
#ifndef PHI_NODES
#define PHI_NODES 8
#endif

uniform int uSize;
uniform int uPanels;               // panels along s = ln tan(theta_h), shared by both segments
uniform float uNodeS[S_NODES];     // Gauss-Legendre nodes on [0, 1] for one panel ...
uniform float uWeightS[S_NODES];   // ... and their weights (sum 1)
uniform float uNodePhi[PHI_NODES]; // Gauss-Legendre nodes and weights on [0, 1] for phi
uniform float uWeightPhi[PHI_NODES];
uniform int uSamples;              // LUT_HAMMERSLEY only

out vec4 fragColor;

// Half-width of the s range kept around ln(a), in which the GGX sampling density 2u(1-u)
// holds all but exp(-2 * SPAN) of its mass.
const float S_SPAN = 8.0;

float bakeG1(float x, float k) {
    // Schlick-Smith, Karis 2013 eq 4
    return x / (x * (1.0 - k) + k);
}

// Accumulate the split-sum terms of one half vector (theta_h given by cos/sin, azimuth phi).
void addSample(float NoV, float sinV, float cosT, float sinT, float phi, float k, float w,
               inout vec2 AB) {
    // Karis 2013, IntegrateBRDF: G_Vis = G VoH / (NoH NoV), Fc = (1 - VoH)^5 exact
    float VoH = sinV * sinT * cos(phi) + NoV * cosT;
    float NoL = max(2.0 * VoH * cosT - NoV, 0.0);
    float Gvis = bakeG1(NoL, k) * bakeG1(NoV, k) * VoH / (cosT * NoV);
    float Fc = pow5(1.0 - VoH);
    AB += w * Gvis * vec2(1.0 - Fc, Fc);
}

vec2 integrateQuadrature(float NoV, float roughness) {
    float a = roughness * roughness;
    float a2 = a * a;
    float k = 0.5 * a;
    float sinV = sqrt(max(1.0 - NoV * NoV, 0.0));
    float thetaV = atan(sinV, NoV);
    // H at angle theta_h reflects V below the horizon for no azimuth when theta_h < th1,
    // for some when th1 < theta_h < th2, for every azimuth beyond th2.
    float th1 = 0.25 * PI - 0.5 * thetaV;
    float th2 = 0.25 * PI + 0.5 * thetaV;
    float sLo = log(a) - S_SPAN;
    float sHi = log(a) + S_SPAN;
    float s1 = log(tan(th1));
    float s2 = log(tan(th2));
    float a0 = sLo;
    float a1 = min(s1, sHi);
    float b0 = max(s1, sLo);
    float b1 = min(s2, sHi);
    float lenA = max(a1 - a0, 0.0);
    float lenB = max(b1 - b0, 0.0);
    int pa = int(floor(float(uPanels) * lenA / max(lenA + lenB, 1e-20) + 0.5));
    if (lenA > 0.0) pa = max(pa, 1);
    if (lenB > 0.0) pa = min(pa, uPanels - 1);
    int pb = uPanels - pa;
    vec2 AB = vec2(0.0);
    for (int p = 0; p < uPanels; ++p) {
        bool partial = p >= pa;
        float h = partial ? lenB / float(max(pb, 1)) : lenA / float(max(pa, 1));
        float p0 = partial ? b0 + float(p - pa) * h : a0 + float(p) * h;
        // Panels that end on a kink (s1 or s2, where the azimuth range starts to shrink or
        // vanishes) use s = p0 + h y^2 (or its mirror), which makes the sqrt-like kink smooth.
        bool kinkLeft = partial && p == pa && b0 == s1;
        bool kinkRight = partial ? (p == uPanels - 1 && b1 == s2) : (p == pa - 1 && a1 == s1);
        for (int j = 0; j < S_NODES; ++j) {
            float y = uNodeS[j];
            float ds = uWeightS[j] * h;
            float s;
            if (kinkLeft && kinkRight) {
                s = p0 + h * 0.5 * (1.0 - cos(PI * y));
                ds *= 0.5 * PI * sin(PI * y);
            } else if (kinkLeft) {
                s = p0 + h * y * y;
                ds *= 2.0 * y;
            } else if (kinkRight) {
                s = p0 + h * (1.0 - (1.0 - y) * (1.0 - y));
                ds *= 2.0 * (1.0 - y);
            } else {
                s = p0 + h * y;
            }
            // GGX sampling: u = t^2 / (a^2 + t^2) with t = tan(theta_h) = e^s, so du = 2 u (1 - u) ds.
            float t = exp(s);
            float t2 = t * t;
            float u = t2 / (a2 + t2);
            float wS = 2.0 * u * (a2 / (a2 + t2)) * ds;
            float cosT = inversesqrt(1.0 + t2);
            float sinT = t * cosT;
            float phiMax = PI;
            if (partial) {
                // NoL > 0  <=>  cos(phi) > (NoV / (2 NoH) - NoV NoH) / (sinV sinT)
                float cos2T = (1.0 - t2) / (1.0 + t2);
                float c0 = -NoV * cos2T / (2.0 * cosT * max(sinV * sinT, 1e-30));
                phiMax = acos(clamp(c0, -1.0, 1.0));
            }
            // Azimuths phi and -phi give the same terms: integrate [0, phiMax], weight 1 / pi.
            for (int q = 0; q < PHI_NODES; ++q) {
                float phi = phiMax * uNodePhi[q];
                float w = wS * uWeightPhi[q] * phiMax / PI;
                addSample(NoV, sinV, cosT, sinT, phi, k, w, AB);
            }
        }
    }
    return AB;
}

vec2 integrateHammersley(float NoV, float roughness) {
    // Karis 2013, "Real Shading in Unreal Engine 4", IntegrateBRDF
    float a = roughness * roughness;
    float k = 0.5 * a;
    vec3 V = vec3(sqrt(1.0 - NoV * NoV), 0.0, NoV);
    vec3 N = vec3(0.0, 0.0, 1.0);
    uint n = uint(uSamples);
    vec2 AB = vec2(0.0);
    for (uint i = 0u; i < n; ++i) {
        vec3 H = importanceSampleGGX(hammersley(i, n), a, N);
        float VoH = saturate(dot(V, H));
        vec3 L = 2.0 * dot(V, H) * H - V;
        float NoL = saturate(L.z);
        float NoH = saturate(H.z);
        if (NoL > 0.0) {
            float Gvis = bakeG1(NoL, k) * bakeG1(NoV, k) * VoH / (NoH * NoV);
            float Fc = pow5(1.0 - VoH);
            AB += Gvis * vec2(1.0 - Fc, Fc);
        }
    }
    return AB / float(n);
}

// Gauss-Legendre panels of the sheen quadrature along y, where NoL = y^2, and sets of
// PHI_NODES nodes in phi.
const int SHEEN_PANELS = 8;
const int SHEEN_PHI_SETS = 2;

// Directional albedo of the white Charlie sheen (sheen.glsl's D_Charlie V_Charlie), the blue
// channel: E(NoV) = integral over L of D V NoL. The integrand is smooth in L but, for a small
// alpha, peaked where NoL and NoV both approach 0 (half vectors near the tangent plane):
// NoL = y^2 puts the nodes there (dNoL = 2 y dy), and azimuths phi and -phi are equal, so
// phi runs over [0, pi] with weight 2. Uses the same 4- and 8-point rules as A and B (two
// sets of PHI_NODES in phi): 32 x 16 evaluations a texel, independent of uSamples, within
// 5e-5 of a 384 x 64 rule over the 128 x 128 LUT.
float integrateSheen(float NoV, float roughness) {
    // Estevez and Kulla 2017, "Production Friendly Microfacet Sheen BRDF" (Charlie D and the
    // fitted Lambda); alpha = clamp(roughness, MIN_SHEEN_ROUGHNESS, 1)^2 (sheen.glsl)
    float alpha = sheenAlpha(roughness);
    float sinV = sqrt(max(1.0 - NoV * NoV, 0.0));
    float lambdaV = sheenLambda(NoV, alpha);
    float E = 0.0;
    float h = 1.0 / float(SHEEN_PANELS);
    for (int p = 0; p < SHEEN_PANELS; ++p) {
        for (int j = 0; j < S_NODES; ++j) {
            float y = (float(p) + uNodeS[j]) * h;
            float NoL = y * y;
            float wy = uWeightS[j] * h * 2.0 * y;
            float sinL = sqrt(max(1.0 - NoL * NoL, 0.0));
            // V NoL = G2 / (4 NoV): finite as NoL -> 0
            float visNoL = 1.0 / ((1.0 + lambdaV + sheenLambda(NoL, alpha)) * 4.0 * NoV);
            for (int q = 0; q < SHEEN_PHI_SETS * PHI_NODES; ++q) {
                float phi = PI * (float(q / PHI_NODES) + uNodePhi[q % PHI_NODES])
                          / float(SHEEN_PHI_SETS);
                float wphi = uWeightPhi[q % PHI_NODES] / float(SHEEN_PHI_SETS) * 2.0 * PI;
                // |V + L|^2 = 2 + 2 V.L; NoH^2 = (NoV + NoL)^2 / |V + L|^2
                float VoL = NoV * NoL + sinV * sinL * cos(phi);
                float sin2h = 1.0 - sq(NoV + NoL) / max(2.0 + 2.0 * VoL, 1e-12);
                E += wy * wphi * D_Charlie(sin2h, alpha) * visNoL;
            }
        }
    }
    return E;
}

void main() {
    float NoV = gl_FragCoord.x / float(uSize);
    float roughness = gl_FragCoord.y / float(uSize);
#ifdef LUT_HAMMERSLEY
    vec2 AB = integrateHammersley(NoV, roughness);
#else
    vec2 AB = integrateQuadrature(NoV, roughness);
#endif
    fragColor = vec4(AB, integrateSheen(NoV, roughness), 1.0);
}
