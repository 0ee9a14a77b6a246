// Anisotropic GGX (issue 23, beyond the talk): the base specular lobe with one roughness
// along a tangent direction and another across it. Everything here is reached only from
// `#if defined(MATERIAL_HAS_ANISOTROPY)` blocks of lights.glsl, lights_reference.glsl and
// surface.glsl: a material that does not write `anisotropy` compiles none of it.
// Convention (the field's documentation): the direction is the one the highlight stretches
// along, so the roughness along it, at, is the larger one. Physically that is ACROSS the
// grooves: brushing along a direction leaves grooves along it, whose normals tilt across it,
// so a brushed surface's highlight is stretched perpendicular to the brushing.
// Included by lights.glsl inside its #if, after common.glsl and brdf.glsl:
// its own includes of them are then already spliced (each file is spliced once), and they let
// the file compile alone. A file spliced FIRST inside an #if would be missing where it is off.
#include "common.glsl"
#include "brdf.glsl"

// Smallest alpha across the stretch: anisotropy 1 would make ab = 0, a mirror in one axis.
const float ANISOTROPY_MIN_ALPHA = 1e-3;

// The lobe's frame and roughnesses at one shading point.
struct AnisotropicLobe {
    vec3 T;            // unit, in the plane of N: the direction the highlight stretches along
    vec3 B;            // N x T
    float anisotropy;  // 0..1
    float at;          // alpha along T
    float ab;          // alpha along B
};

// The two alphas from the isotropic alpha and the anisotropy: at grows and ab shrinks by
// the same factor, so the lobe's solid angle (at ab) stays near a^2 at small anisotropy and
// anisotropy 0 is exactly the isotropic alpha. ab is kept at or above min(a, 1e-3).
void anisotropicAlphas(float a, float anisotropy, out float at, out float ab) {
    // Kulla and Conty 2017, "Revisiting Physically Based Shading at Imageworks", anisotropy:
    // at = a (1 + anisotropy), ab = a (1 - anisotropy)
    at = min(a * (1.0 + anisotropy), 1.0);
    ab = max(a * (1.0 - anisotropy), min(a, ANISOTROPY_MIN_ALPHA));
}

// The stretch direction in world space: the tangent-space direction (+X = T, +Y = B of the
// geometric normal's frame; z ignored) projected onto the plane of the shading normal N and
// normalised (Gram-Schmidt), so it stays a tangent after normal mapping. A direction with
// nothing left in the plane falls back to the projected mesh tangent, then to the projected
// bitangent turned a quarter (T and B are orthogonal: both cannot lie along N).
vec3 anisotropicTangent(vec3 direction, vec3 T, vec3 B, vec3 N) {
    // Gram-Schmidt against N, as Mikkelsen 2008, "Simulation of Wrinkled Surfaces Revisited"
    vec3 w = T * direction.x + B * direction.y;
    vec3 t = w - N * dot(N, w);
    float tt = dot(t, t);
    if (tt < 1e-12) {
        t = T - N * dot(N, T);
        tt = dot(t, t);
    }
    if (tt < 1e-12) {
        t = cross(B - N * dot(N, B), N);
        tt = dot(t, t);
    }
    return t * inversesqrt(max(tt, 1e-30));
}

// The lobe of a material at a point: alphas from a = roughness^2 and the world stretch
// direction; (T, B) is the geometric normal's tangent frame, N the shading normal.
AnisotropicLobe makeAnisotropicLobe(float a, float anisotropy, vec3 direction, vec3 T, vec3 B,
                                    vec3 N) {
    // Kulla and Conty 2017 (alphas); bitangent N x T' of the projected tangent
    AnisotropicLobe l;
    l.anisotropy = saturate(anisotropy);
    l.T = anisotropicTangent(direction, T, B, N);
    l.B = cross(N, l.T);
    anisotropicAlphas(a, l.anisotropy, l.at, l.ab);
    return l;
}

// Anisotropic GGX, 1 / (pi at ab (ToH^2/at^2 + BoH^2/ab^2 + NoH^2)^2), multiplied through
// by ab^2: (ab / at) ab^2 / (pi (ToH^2 ab^2/at^2 + BoH^2 + NoH^2 ab^2)^2). ToH and BoH are
// used directly: BoH^2 from |N x H|^2 - ToH^2 cancels catastrophically when ab << at. At
// at = ab it is D_GGX's own arithmetic on |N x H|^2 (the isotropic value bit for bit).
float D_GGXAnisotropic(float NoH, float ToH, float BoH, float oneMinusNoH2, float at,
                       float ab) {
    // Burley 2012, "Physically-Based Shading at Disney", appendix B.2, eq 13 (GTR2 aniso)
    float ab2 = ab * ab;
    float d = at == ab ? oneMinusNoH2 + NoH * NoH * ab2
                       : ToH * ToH * (ab2 / (at * at)) + BoH * BoH + NoH * NoH * ab2;
    return (ab / at) * (ab2 / (PI * d * d));
}

// Roughness of the lobe projected on the plane of N and the direction X:
// sqrt(cos^2(phi) at^2 + sin^2(phi) ab^2), phi the azimuth of X from T, written
// sqrt(ab^2 + (at^2 - ab^2) cos^2(phi)) so at = ab gives sqrt(a^2) = a exactly.
// oneMinusNoX2 = |N x X|^2; at the normal (no azimuth) cos^2 is bounded by 1.
float projectedAlpha(float at, float ab, float ToX, float oneMinusNoX2) {
    // Heitz 2014, "Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs",
    // eq 80 (anisotropic GGX: Lambda of the projected roughness alpha_o)
    float cos2 = min(ToX * ToX / max(oneMinusNoX2, 1e-12), 1.0);
    return sqrt(ab * ab + (at * at - ab * ab) * cos2);
}

// Schlick-Smith visibility with its own k for each direction (the k of that direction's
// projected roughness): G1(V) G1(L) / (4 NoV NoL) with the NoV NoL folded out.
float V_SchlickSmithAnisotropic(float NoV, float NoL, float kV, float kL) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 4, with Heitz 2014's projected
    // roughness per direction (eq 80)
    float gv = NoV * (1.0 - kV) + kV;
    float gl = NoL * (1.0 - kL) + kL;
    return 0.25 / (gv * gl);
}

// k for analytic lights from a projected alpha: the talk's (roughness + 1)^2 / 8 with the
// perceptual roughness sqrt(alpha_o); at anisotropy 0 sqrt(a) is the roughness itself.
float k_AnalyticProjected(float alphaO) {
    // Karis 2013, eq 4 (Disney's remapping) of Heitz 2014's projected roughness (eq 80)
    return k_Analytic(sqrt(alphaO));
}

// The terms both forms of the lobe share at H = normalize(L + V): D, VoH and the projected
// alphas of V and L (each direction's k is the caller's: analytic lights remap it).
float anisotropicLobeTerms(AnisotropicLobe l, vec3 N, vec3 V, vec3 L, out float VoH,
                           out float alphaV, out float alphaL) {
    // Burley 2012 appendix B.2 eq 13 (D); Heitz 2014 eq 80 (projected roughness)
    vec3 h = L + V;
    vec3 H = h * inversesqrt(max(dot(h, h), 1e-30));
    float NoH = saturate(dot(N, H));
    VoH = saturate(dot(V, H));
    vec3 NxH = cross(N, H);
    vec3 NxV = cross(N, V);
    vec3 NxL = cross(N, L);
    alphaV = projectedAlpha(l.at, l.ab, dot(l.T, V), dot(NxV, NxV));
    alphaL = projectedAlpha(l.at, l.ab, dot(l.T, L), dot(NxL, NxL));
    return D_GGXAnisotropic(NoH, dot(l.T, H), dot(l.B, H), dot(NxH, NxH), l.at, l.ab);
}

// Anisotropic D Vis F NoL towards the unit direction L for analytic lights (Fresnel by the
// spherical Gaussian, k remapped): the form of lights.glsl's specularTowards, same H.
vec3 anisotropicSpecularTowards(AnisotropicLobe l, vec3 N, vec3 V, float NoV, vec3 F0, vec3 L) {
    // Burley 2012 appendix B.2 eq 13 (D); Heitz 2014 eq 80 with Karis 2013 eq 4 (Vis); eq 5 (F)
    float NoL = saturate(dot(N, L));
    vec3 h = L + V;  // L = -V: H undefined, nothing reflected (as lights.glsl)
    if (NoL <= 0.0 || dot(h, h) < 1e-12) return vec3(0.0);
    float VoH, alphaV, alphaL;
    float D = anisotropicLobeTerms(l, N, V, L, VoH, alphaV, alphaL);
    float kV = k_AnalyticProjected(alphaV);
    float kL = k_AnalyticProjected(alphaL);
    return D * V_SchlickSmithAnisotropic(NoV, NoL, kV, kL) * F_Schlick(F0, VoH) * NoL;
}

// The bent reflection vector (Filament's anisotropic IBL lookup; benchmarks/bench_aniso_ibl.py
// compares the split sum's taps below with it; the area lights use the metric points of
// lights.glsl, anisotropicSphereRepresentativePoint):
// the "anisotropic normal" is V with its component across the stretch (along B) removed,
// the normal a lobe infinitely long along T would reflect V about; N is bent towards it by
// the anisotropy. An approximation: it moves the lookup along the stretch, it does not
// widen it (the prefiltered lookup stays isotropic).
vec3 anisotropicReflection(AnisotropicLobe l, vec3 N, vec3 V) {
    // Revie 2011, "Implementing Fur Using Deferred Shading" (GPU Pro 2) and McAuley 2015,
    // "Rendering the World of Far Cry 4", as Filament's documentation (anisotropic IBL):
    // n_a = (B x V) x B, bent = normalize(mix(N, n_a, anisotropy)), R = reflect(-V, bent)
    // At anisotropy 0 the bent normal is N itself, not renormalised: today's R bit for bit.
    if (l.anisotropy <= 0.0) return reflect(-V, N);
    vec3 anisotropicNormal = cross(cross(l.B, V), l.B);
    vec3 bent = mix(N, anisotropicNormal, l.anisotropy);
    float bb = dot(bent, bent);
    bent = bb > 1e-12 ? bent * inversesqrt(bb) : N;
    return reflect(-V, bent);
}

// The anisotropic split sum's prefiltered radiance: the lobe, long along T, is read as
// ANISOTROPY_IBL_TAPS narrow lobes (alpha ab, isotropic) whose half vectors are spread
// along T, H_i = normalize(N + s_i w T), each looked up along its own reflection reflect(-V,
// H_i) and weighted by unit-roughness GGX's slope density (1 + s_i^2)^-2, faded out as its
// reflection nears N's horizon (what the lobe reflects from under the surface is masked:
// the environment BRDF counts that loss, the prefiltered value is the visible taps' mean);
// the weights are normalised to 1 (the furnace is the environment BRDF's alone). w =
// sqrt(at^2 - ab^2): the spread the narrow lobes' width leaves to be made up (widths of
// convolved lobes add in squares), so at = ab (anisotropy 0) puts every tap on N and the sum
// is the isotropic lookup.
const int ANISOTROPY_IBL_TAPS = 3;
// A tap's weight falls linearly to its floor as N.R_i goes from this to 0; the floor keeps a
// sum whose taps are all under the horizon (a back-facing shading normal) their mean.
const float ANISOTROPY_TAP_HORIZON_FADE = 0.25;
const float ANISOTROPY_TAP_MIN_WEIGHT = 1e-3;

// Slope offset of tap i along T, in units of the spread w: -0.8, 0, 0.8.
float anisotropicTapOffset(int i) {
    // matedit anisotropic split sum (docs/shading.md, Anisotropy; benchmarks/bench_aniso_ibl.py)
    return 0.8 * float(i - 1);
}

// The direction tap i reads: V reflected about H_i = normalize(N + s_i w T) (scaled to N's
// length, so a tap with no offset reflects about N itself, bit for bit).
vec3 anisotropicTapDirection(AnisotropicLobe l, vec3 N, vec3 V, int i) {
    // matedit anisotropic split sum (docs/shading.md, Anisotropy)
    float w = sqrt(max(l.at * l.at - l.ab * l.ab, 0.0));
    vec3 h = N + (anisotropicTapOffset(i) * w) * l.T;
    return reflect(-V, h * (length(N) / length(h)));
}

// The weight of tap i reading R (not normalised: the caller divides by the taps' sum):
// (1 + s_i^2)^-2 times max(saturate(N.R / fade), floor).
float anisotropicTapWeight(vec3 N, vec3 R, int i) {
    // GGX's slope density at unit roughness, Walter et al. 2007, eq 33 with Heitz 2014, eq 9:
    // P22(s) = 1 / (pi (1 + s^2)^2); the horizon fade is matedit's (docs/shading.md)
    float fade = max(saturate(dot(N, R) / ANISOTROPY_TAP_HORIZON_FADE), ANISOTROPY_TAP_MIN_WEIGHT);
    return fade / sq(1.0 + sq(anisotropicTapOffset(i)));
}

// The roughness the taps are prefiltered at: the narrow alpha's, sqrt(ab); the material's
// own IBL roughness at anisotropy 0 (ab is made from the analytic lights' clamped one).
float anisotropicTapRoughness(AnisotropicLobe l, float roughness) {
    // Karis 2013, eq 7: the prefiltered mips are indexed by roughness = sqrt(alpha)
    return l.anisotropy > 0.0 ? sqrt(l.ab) : roughness;
}

// The anisotropic split sum's environment BRDF: the change (dA, dB) of the isotropic LUT's
// scale and bias of F0 for the anisotropic lobe, tabulated (matedit/ibl/anisotropy_lut.py)
// over NoV, roughness (x, y: texel centres, as the isotropic LUT), the anisotropy (nodes
// i / (ANISOTROPY_LUT_NODES - 1)) and |cos| of V's azimuth from T (nodes j / (slabs - 1));
// z holds ANISOTROPY_LUT_NODES anisotropy texels for each |cos| node. Three-linear inside
// a slab (the anisotropy coordinate stays on its texel centres), linear between two slabs.
const int ANISOTROPY_LUT_NODES = 13;

// cos^2 of V's azimuth from T (the table's fourth axis), as projectedAlpha forms it.
float anisotropicViewCos2(AnisotropicLobe l, vec3 N, vec3 V) {
    // matedit anisotropic environment BRDF (docs/shading.md, Anisotropy)
    vec3 NxV = cross(N, V);
    float ToV = dot(l.T, V);
    return min(ToV * ToV / max(dot(NxV, NxV), 1e-12), 1.0);
}

vec2 anisotropicEnvironmentBRDF(highp sampler3D lut, float NoV, float roughness,
                                float anisotropy, float cos2) {
    // Karis 2013's split sum (environment BRDF) of the Burley 2012 / Heitz 2014 lobe,
    // tabulated by matedit (docs/shading.md, Anisotropy)
    float depth = float(textureSize(lut, 0).z);
    float nA = float(ANISOTROPY_LUT_NODES);
    float nC = depth / nA;
    float c = sqrt(saturate(cos2)) * (nC - 1.0);
    float m0 = min(floor(c), nC - 1.0);
    float m1 = min(m0 + 1.0, nC - 1.0);
    float za = saturate(anisotropy) * (nA - 1.0) + 0.5;
    vec2 d0 = texture(lut, vec3(NoV, roughness, (m0 * nA + za) / depth)).rg;
    vec2 d1 = texture(lut, vec3(NoV, roughness, (m1 * nA + za) / depth)).rg;
    return mix(d0, d1, c - m0);
}

// --- Sphere and tube lights (benchmarks/LIGHTS_ENERGY.md, "The anisotropic lobe") ---------
// The representative point is the point of the light that brings H closest to N in the
// lobe's own metric, (T.H / at)^2 + (B.H / ab)^2, not in angle: a lobe 19 times narrower
// across than along loses most of its highlight when the point is off by a fraction of ab
// across, and costs almost nothing when it is off along. The light is read in the gnomonic
// projection about the direction Ln of its centre (X / (X.Ln) - Ln, the plane tangent to
// the unit sphere of directions at Ln): there the sphere is an exact disc of radius
// r / sqrt(d^2 - r^2) and the segment an exact segment, and offsets of L there move H by
// half as much along the same axes (e1 ~ T, e2 ~ B), so the metric is diag(1/at^2, 1/ab^2)
// up to a common scale. The mirror reflection R (where H = N) is the target; the bent
// reflection below is kept for the split sum's benchmark, not for the lights.

// The light's tangent-plane frame at Ln: e1 the lobe's T projected, e2 = Ln x e1; where T
// lies along Ln (a grazing light along the stretch), B projected gives the frame instead.
void anisotropicLightFrame(AnisotropicLobe l, vec3 Ln, out vec3 e1, out vec3 e2) {
    // matedit anisotropic representative point (docs/shading.md, Anisotropy)
    vec3 t = l.T - Ln * dot(l.T, Ln);
    float tt = dot(t, t);
    if (tt < 1e-12) {
        vec3 b = l.B - Ln * dot(l.B, Ln);
        e2 = b * inversesqrt(max(dot(b, b), 1e-30));
        e1 = cross(e2, Ln);
        return;
    }
    e1 = t * inversesqrt(tt);
    e2 = cross(Ln, e1);
}

// The point of the disc |p| <= rho (gnomonic plane, frame e1 e2) closest to o in the metric
// q p1^2 + p2^2, q = (ab / at)^2: o itself inside; outside, the boundary point p = rho u with
// q (o1 - rho u1) = mu u1, o2 - rho u2 = mu u2 (Lagrange), u1 = q o1 / (mu + q rho), u2 =
// o2 / (mu + rho), |u| = 1. The root mu of G(mu) = |(q o1, o2) / (mu + (q, 1) rho)|^-1 = 1 is
// found by Newton on G, which is exactly linear at q = 1 and nearly so elsewhere, from the
// lower bound |(q o1, o2)| - rho: ANISOTROPY_LIGHT_NEWTON_STEPS steps give the exact
// minimiser's energy to 1 % (benchmarks/LIGHTS_ENERGY.md).
const int ANISOTROPY_LIGHT_NEWTON_STEPS = 2;

vec2 anisotropicDiscPoint(vec2 o, float rho, float q) {
    // matedit anisotropic representative point (docs/shading.md, Anisotropy): closest point
    // of a disc in an elliptic metric, as the closest point of an ellipse (Lagrange), Newton
    if (dot(o, o) <= rho * rho) return o;
    float A = q * o.x;
    float C = o.y;
    float mu = max(sqrt(A * A + C * C) - rho, 0.0);
    for (int i = 0; i < ANISOTROPY_LIGHT_NEWTON_STEPS; i++) {
        float da = mu + q * rho;
        float dc = mu + rho;
        float S = max(A * A / (da * da) + C * C / (dc * dc), 1e-30);
        float dG = (A * A / (da * da * da) + C * C / (dc * dc * dc)) / (S * sqrt(S));
        mu = max(mu + (1.0 - inversesqrt(S)) / max(dG, 1e-30), 0.0);
    }
    vec2 u = vec2(A / (mu + q * rho), C / (mu + rho));
    float uu = dot(u, u);
    return uu > 0.0 ? u * (rho * inversesqrt(uu)) : vec2(0.0);
}

// The representative points themselves are in lights.glsl (after the talk's, their
// fallback): anisotropicSphereRepresentativePoint, anisotropicTubeRepresentativePoint.

// The light's widening along T and B in H space. A disc of radius w (in H, the talk's
// r / (DIVISOR d)) seen by V: L moving in the plane of V and L moves H by half as much, L
// moving across that plane by 1 / (2 V.H), so the disc is an ellipse in H, w in the plane
// and w / V.H across it (45 degrees between N and the light: 1.41 w across). Its support
// along T and B: sqrt(w^2 (X.e_in)^2 + (w / V.H)^2 (X.e_perp)^2), e_perp the tangent
// direction across the plane (its share of V x L on T and B). V along L, or a plane of V
// and L along the surface: w on both axes. The narrow alpha is as small as this difference.
void anisotropicWidening(AnisotropicLobe l, vec3 V, vec3 L, float widen, out float wT,
                         out float wB) {
    // matedit anisotropic widening (docs/shading.md, Anisotropy): the Jacobian of H = (V + L)
    // / |V + L| (Walter et al. 2007, eq 14's 1 / (4 V.H) is its determinant) on Karis 2013's
    // widening, eq 14
    vec3 h = V + L;
    float c = max(dot(V, h) * inversesqrt(max(dot(h, h), 1e-30)), 1e-4);
    vec3 e = cross(V, L);
    float pT = dot(e, l.T);
    float pB = dot(e, l.B);
    float pp = pT * pT + pB * pB;
    float cT2 = 0.0;
    float cB2 = 0.0;
    float noPlane = 1.0;
    if (pp >= 1e-12) {
        cT2 = pT * pT / pp;
        cB2 = pB * pB / pp;
        noPlane = 0.0;
    }
    float ic2 = 1.0 / (c * c);
    wT = widen * sqrt(cB2 + cT2 * ic2 + noPlane);
    wB = widen * sqrt(cT2 + cB2 * ic2 + noPlane);
}

// Energy kept by a sphere light's widened anisotropic highlight: each alpha is widened by
// the disc's support along its axis (anisotropicWidening of the talk's w = r / (DIVISOR d)),
// a' = saturate(a + w_axis), and the peak of D, 1 / (pi at ab), is renormalised by
// (at ab) / (at' ab'). The form is Steiner's for the lobe's ellipse grown by the disc: its
// area pi at ab grows by (perimeter) w + pi w^2, the perimeter of a flat ellipse ~ pi (at + ab).
float anisotropicSphereNormalization(AnisotropicLobe l, vec3 V, vec3 L, float sourceRadius,
                                     float d) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 10, 14, applied per axis
    float wT, wB;
    anisotropicWidening(l, V, L, sourceRadius / (MATEDIT_AREA_WIDEN_DIVISOR * max(d, 1e-8)),
                        wT, wB);
    return (l.at * l.ab) / (saturate(l.at + wT) * saturate(l.ab + wB));
}

// Energy kept by a tube's highlight: the lobe's ellipse grown by the capsule, a segment of
// half-length wl = 0.5 l / (DIVISOR d) and a disc of w = r / (DIVISOR dp) widened as the
// sphere's (Steiner again: the segment adds 2 wl times the grown ellipse's width across it,
// 2 (a_across + w_across), a_across the projected alpha across the axis). Normalised as the
// sphere: (at ab) / (at' ab' + wl' (a_across + w_across)), wl' = min(wl, 1 - a_axis): the
// talk's clamp of the line's widened alpha at 1. Along a principal axis without the disc
// this is the talk's a / a' of the projected alpha along the axis.
float anisotropicTubeNormalization(AnisotropicLobe l, vec3 N, vec3 V, vec3 L, vec3 axis,
                                   float sourceLength, float d, float sourceRadius, float dp) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 10, 14, 20, of the lobe's extents
    // along and across the axis (Heitz 2014 eq 80's projected alpha)
    vec3 NxA = cross(N, axis);
    vec3 across = NxA;
    vec3 NxC = cross(N, across);
    float aAxis = projectedAlpha(l.at, l.ab, dot(l.T, axis), dot(NxA, NxA));
    float aAcross = projectedAlpha(l.at, l.ab, dot(l.T, across), dot(NxC, NxC));
    float wT, wB;
    anisotropicWidening(l, V, L, sourceRadius / (MATEDIT_AREA_WIDEN_DIVISOR * max(dp, 1e-8)),
                        wT, wB);
    float wAcross = projectedAlpha(wT, wB, dot(l.T, across), dot(NxC, NxC));
    float wl = min(0.5 * sourceLength / (MATEDIT_AREA_WIDEN_DIVISOR * max(d, 1e-8)),
                   max(1.0 - aAxis, 0.0));
    return (l.at * l.ab)
           / (saturate(l.at + wT) * saturate(l.ab + wB) + wl * (aAcross + wAcross));
}

// Anisotropic GGX half vector for a uniform point Xi, in the lobe's frame (T, B, N): a
// slope drawn from unit-roughness GGX (tan = sqrt(y / (1 - y))) and stretched by (at, ab).
// Its density is D(H) NoH.
vec3 importanceSampleGGXAnisotropic(vec2 Xi, float at, float ab, vec3 N, vec3 T, vec3 B) {
    // Burley 2012, "Physically-Based Shading at Disney", appendix B.2, eq 16:
    // h = normalize(sqrt(y / (1 - y)) (at cos(2 pi x) T + ab sin(2 pi x) B) + N)
    float phi = 2.0 * PI * Xi.x;
    float tanTheta = sqrt(Xi.y / max(1.0 - Xi.y, 1e-12));
    vec3 h = tanTheta * (at * cos(phi) * T + ab * sin(phi) * B) + N;
    return normalize(h);
}

// Solid-angle density of L under anisotropic GGX half-vector sampling: D(H) NoH / (4 VoH).
float ggxAnisotropicDirectionPdf(AnisotropicLobe l, vec3 N, vec3 V, vec3 L) {
    // Walter et al. 2007, "Microfacet Models for Refraction", eq 14 and 38: p(l) = p(h) / (4 VoH)
    vec3 H;
    float VoH, NoH, oneMinusNoH2;
    if (!reflectionHalfVector(N, V, L, H, VoH, NoH, oneMinusNoH2)) return 0.0;
    float D = D_GGXAnisotropic(NoH, dot(l.T, H), dot(l.B, H), oneMinusNoH2, l.at, l.ab);
    return D * NoH / (4.0 * VoH);
}

// An anisotropic-GGX-sampled direction for the point Xi (may lie below the horizon).
vec3 ggxAnisotropicSampleDirection(AnisotropicLobe l, vec3 N, vec3 V, vec2 Xi) {
    // Burley 2012 appendix B.2 eq 16, then L = 2 (V.H) H - V
    vec3 H = importanceSampleGGXAnisotropic(Xi, l.at, l.ab, N, l.T, l.B);
    return 2.0 * dot(V, H) * H - V;
}

// --- For the image-based reference (its estimator adds these mechanically) --------------

// f(l, v) NoL of the anisotropic lobe as the IBL reference integrates it: k = alpha_o / 2
// per direction (the talk's IBL k of the projected roughness) and the exact Fresnel power.
vec3 anisotropicBrdfCosineIBL(AnisotropicLobe l, vec3 N, vec3 V, vec3 F0, vec3 L) {
    // Burley 2012 B.2 eq 13; Heitz 2014 eq 80 with Karis 2013 eq 4 (k = alpha / 2); Schlick 1994
    float NoL = saturate(dot(N, L));
    vec3 h = L + V;  // L = -V: H undefined, nothing reflected
    if (NoL <= 0.0 || dot(h, h) < 1e-12) return vec3(0.0);
    float NoV = max(dot(N, V), 1e-4);
    float VoH, alphaV, alphaL;
    float D = anisotropicLobeTerms(l, N, V, L, VoH, alphaV, alphaL);
    float kV = k_IBL(alphaV);
    float kL = k_IBL(alphaL);
    return D * V_SchlickSmithAnisotropic(NoV, NoL, kV, kL) * F_SchlickExact(F0, VoH) * NoL;
}

// An importance-sampled direction of the anisotropic lobe and its solid-angle density.
vec3 anisotropicSampleIBL(AnisotropicLobe l, vec3 N, vec3 V, vec2 Xi, out float pdf) {
    // Burley 2012 appendix B.2 eq 16; Walter et al. 2007 eq 14, 38
    vec3 L = ggxAnisotropicSampleDirection(l, N, V, Xi);
    pdf = ggxAnisotropicDirectionPdf(l, N, V, L);
    return L;
}

// Solid-angle density of L under anisotropicSampleIBL.
float anisotropicPdfIBL(AnisotropicLobe l, vec3 N, vec3 V, vec3 L) {
    // Walter et al. 2007, "Microfacet Models for Refraction", eq 14 and 38
    return ggxAnisotropicDirectionPdf(l, N, V, L);
}
