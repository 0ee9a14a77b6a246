// The reference mode's estimator for a material with lobes beyond the talk (clear coat,
// sheen, anisotropic GGX, subsurface): the whole layered BRDF, coat over sheen over base, exactly as the
// analytic lights layer it (lights.glsl: sheenLayer, then coatLayer), integrated against the
// unfiltered environment by the MIS estimator of ibl.glsl (one BRDF and one environment
// sample a step, balance heuristic). The BRDF sample picks one lobe (diffuse, base specular,
// sheen, coat, the subsurface's front and back) by chances from estimated lobe weights; its density is the whole mixture's.
// surface.glsl includes this file only where a lobe is compiled in and the reference is
// (MATEDIT_LAYERED_REFERENCE); a material without lobes keeps referenceEnvironmentIBL.
#include "common.glsl"
#include "ibl.glsl"
#include "lights.glsl"

#if defined(MATEDIT_LAYERED_REFERENCE)

// The layered surface: the shading context (its lobes), the base as ibl.glsl's reference
// surface (the material's unclamped roughness: the alpha floor is referenceAlpha's), and
// the chances of the lobes.
struct LayeredReference {
    ShadingContext s;
    ReferenceSurface base;
    float chance[6];  // base specular, diffuse, sheen, coat, subsurface front and back:
                      // one-sample model chances
};

// The base's two lobes in ibl.glsl's order (its specular first), so that a lobe at weight 0
// draws the base's own samples.
const int LAYER_SPECULAR = 0;
const int LAYER_DIFFUSE = 1;
const int LAYER_SHEEN = 2;
const int LAYER_COAT = 3;
// The subsurface lobe by two samplings: the cosine about N (its reflected part above the
// horizon) and the cosine about -N (its transmitted part, and the wrap below the horizon).
const int LAYER_SUBSURFACE = 4;
const int LAYER_SUBSURFACE_BACK = 5;
const int LAYER_COUNT = 6;

// The lobes' chances: each lobe's estimated reflectance towards the eye (luminance), the
// lobes under the coat and the sheen scaled by what those let through towards the eye.
LayeredReference makeLayeredReference(ShadingContext s, float roughness) {
    // Veach 1997, "Robust Monte Carlo Methods for Light Transport Simulation", 9.2.4:
    // one-sample model, a strategy chosen with probability c_i
    LayeredReference r;
    r.s = s;
    r.base = makeReferenceSurface(s.N, s.V, s.diffuseColor, s.F0, roughness, s.specularScale);
    const vec3 Y = vec3(0.2126, 0.7152, 0.0722);
    float NoV = saturate(dot(s.N, s.V));
    float under = 1.0;
    float w[LAYER_COUNT];
    w[LAYER_SHEEN] = 0.0;
    w[LAYER_COAT] = 0.0;
    w[LAYER_SUBSURFACE] = 0.0;
    w[LAYER_SUBSURFACE_BACK] = 0.0;
#if defined(MATERIAL_HAS_COAT)
    under *= dot(coatTransmittance(s.coat, s.coat.NoV), Y);
    w[LAYER_COAT] = coatFresnel(s.coat, s.coat.NoV) * s.coat.scale;
#endif
#if defined(MATERIAL_HAS_SHEEN_COLOR)
    // the sheen's albedo E(NoV) from its albedo scaling 1 - max3(c) E
    float E = s.sheenMax > 0.0 ? (1.0 - s.sheenScaleV) / s.sheenMax : 0.0;
    w[LAYER_SHEEN] = under * dot(s.sheenColor, Y) * E;
    under *= s.sheenScaleV;
#endif
#if defined(MATERIAL_HAS_SUBSURFACE)
    // the subsurface's albedo split: above the horizon (1 - T)(1 - b), below T + (1 - T) b,
    // b = w^2 / (1 + w)^2 the wrapped cosine's share below the horizon
    SubsurfaceLobe sl = s.subsurface;
    vec3 wrapBelow = sl.wrap * sl.wrap / ((1.0 + sl.wrap) * (1.0 + sl.wrap));
    vec3 front = (1.0 - sl.transmittance) * (1.0 - wrapBelow);
    w[LAYER_SUBSURFACE] = under * dot(sl.color * front, Y);
    w[LAYER_SUBSURFACE_BACK] = under * dot(sl.color * (1.0 - front), Y);
#endif
    w[LAYER_DIFFUSE] = under * dot(s.diffuseColor, Y);
    w[LAYER_SPECULAR] = under * dot(F_SchlickExact(s.F0, NoV) * s.specularScale, Y);
    float total = 0.0;
    for (int i = 0; i < LAYER_COUNT; i++) total += w[i];
    for (int i = 0; i < LAYER_COUNT; i++) {
        r.chance[i] = total > 0.0 ? w[i] / total : 1.0 / float(LAYER_COUNT);
    }
    return r;
}

// f(l, v) N.l of the layered BRDF towards L: the base (Lambert plus GGX, anisotropic where
// the material is) scaled by the sheen's albedo scaling plus the sheen, all seen through the
// coat plus the coat's own lobe (lights.glsl's order for one light).
vec3 layeredBrdfCosine(LayeredReference r, vec3 L) {
    // Filament Materials documentation, "Clear coat"; glTF KHR_materials_sheen albedo scaling
    ShadingContext s = r.s;
    vec3 f;
    // A half vector below a lobe's normal (V under that normal's horizon: normal maps) gets
    // none of the lobe, as referenceBrdfCosine: its sampling cannot reach it, and D's
    // cross-product form would be unbounded there (H = -N) with a density of 0.
    vec3 H = normalize(L + s.V);
    // the base specular's Fresnel: Schlick's of F0, or the thin film's Airy reflectance at
    // V.H with the lobe's own Fresnel made exactly 1 by F0 = 1 (thin_film.glsl)
    vec3 specF0 = s.F0;
    vec3 filmF = vec3(1.0);
#if defined(MATERIAL_HAS_THIN_FILM_THICKNESS)
    if (s.film.thickness > 0.0) {
        specF0 = vec3(1.0);
        filmF = thinFilmFresnel(s.film, saturate(dot(s.V, H)));
    }
#endif
#if defined(MATERIAL_HAS_ANISOTROPY)
    float NoL = dot(s.N, L);
    f = NoL > 0.0 ? s.diffuseColor * (INV_PI * NoL) : vec3(0.0);
    if (NoL > 0.0 && dot(s.N, H) > 0.0) {
        f += anisotropicBrdfCosineIBL(s.aniso, s.N, s.V, specF0, L) * s.specularScale * filmF;
    }
#else
    ReferenceSurface rb = r.base;
    rb.F0 = specF0;
    rb.specularScale *= filmF;
    f = referenceBrdfCosine(rb, L);
#endif
#if defined(MATERIAL_HAS_SUBSURFACE)
    f += subsurfaceCosine(s.subsurface, dot(s.N, L));  // part of the base (lights.glsl)
#endif
#if defined(MATERIAL_HAS_SHEEN_COLOR)
    f = f * sheenBaseScale(s, saturate(dot(s.N, L)))
      + sheenBrdfCosine(s.N, s.V, L, s.sheenColor, s.sheenAlpha);
#endif
#if defined(MATERIAL_HAS_COAT)
    f *= coatTransmittance(s.coat, dot(s.coat.N, L));
    if (dot(s.coat.N, H) > 0.0) f += vec3(coatBrdfCosine(s.coat, s.V, L));
#endif
    return f;
}

// Solid-angle density of L under lobe `lobe`'s own sampling (0 for a lobe not compiled in).
float layeredLobePdf(LayeredReference r, int lobe, vec3 L) {
    // Walter et al. 2007 for the GGX lobes, cos / pi for the diffuse
    ShadingContext s = r.s;
    if (lobe == LAYER_DIFFUSE) return max(dot(s.N, L), 0.0) * INV_PI;
    if (lobe == LAYER_SPECULAR) {
#if defined(MATERIAL_HAS_ANISOTROPY)
        return anisotropicPdfIBL(s.aniso, s.N, s.V, L);
#else
        return referenceGgxPdf(r.base, L);
#endif
    }
#if defined(MATERIAL_HAS_SHEEN_COLOR)
    if (lobe == LAYER_SHEEN) return sheenSamplePdf(s.N, L);
#endif
#if defined(MATERIAL_HAS_COAT)
    if (lobe == LAYER_COAT) return coatPdf(s.coat, s.V, L);
#endif
#if defined(MATERIAL_HAS_SUBSURFACE)
    if (lobe == LAYER_SUBSURFACE) return max(dot(s.N, L), 0.0) * INV_PI;
    if (lobe == LAYER_SUBSURFACE_BACK) return max(-dot(s.N, L), 0.0) * INV_PI;
#endif
    return 0.0;
}

// Solid-angle density of L under layeredBrdfSample: sum of chance_i p_i(L).
float layeredBrdfPdf(LayeredReference r, vec3 L) {
    // the one-sample mixture's density (Veach 1997, 9.2.4)
    float p = 0.0;
    for (int i = 0; i < LAYER_COUNT; i++) p += r.chance[i] * layeredLobePdf(r, i, L);
    return p;
}

// A direction from one lobe chosen by Xi.x (then stretched back to [0, 1) for that lobe);
// `pdf` receives layeredBrdfPdf of it, or 0 where the chosen lobe's own density there is 0.
// That happens where V is below a GGX lobe's normal (interpolated or mapped normals): a half
// vector H with V.H < 0 reflects V to an L whose half vector is -H, which the lobe's
// density (and that of the mixture's other lobes) does not count as drawn from H. Such a
// draw is a failed sample: counted, it would be weighted by the other lobes' densities
// alone (near 0 there), a firefly and a bias; dropped, the drawn directions' density is
// exactly chance_i p_i summed, so the estimator stays unbiased.
vec3 layeredBrdfSample(LayeredReference r, vec2 Xi, out float pdf) {
    // Veach 1997, 9.2.4: choose strategy i with chance c_i, sample it, density sum c_j p_j
    ShadingContext s = r.s;
    int lobe = LAYER_COUNT - 1;
    float start = 0.0;
    for (int i = 0; i < LAYER_COUNT - 1; i++) {
        if (Xi.x < start + r.chance[i]) { lobe = i; break; }
        start += r.chance[i];
    }
    vec2 X = vec2(min((Xi.x - start) / max(r.chance[lobe], 1e-20), 0.99999994), Xi.y);
    X.x = max(X.x, 0.0);
    vec3 L;
    float unused;
    if (lobe == LAYER_SPECULAR) {
#if defined(MATERIAL_HAS_ANISOTROPY)
        L = anisotropicSampleIBL(s.aniso, s.N, s.V, X, unused);
#else
        L = referenceGgxSample(r.base, X);
#endif
    } else if (lobe == LAYER_DIFFUSE) {
        L = importanceSampleCosine(X, s.N);
    } else if (lobe == LAYER_SHEEN) {
#if defined(MATERIAL_HAS_SHEEN_COLOR)
        L = sheenSampleDirection(X, s.N, unused);
#else
        L = importanceSampleCosine(X, s.N);  // chance 0 without a sheen
#endif
    } else if (lobe == LAYER_COAT) {
#if defined(MATERIAL_HAS_COAT)
        L = coatSampleDirection(s.coat, s.V, X, unused);
#else
        L = importanceSampleCosine(X, s.N);  // chance 0 without a coat
#endif
    } else if (lobe == LAYER_SUBSURFACE) {
        L = importanceSampleCosine(X, s.N);  // chance 0 without a subsurface lobe
    } else {
        L = importanceSampleCosine(X, -s.N);  // the back: chance 0 without one
    }
    pdf = layeredLobePdf(r, lobe, L) > 0.0 ? layeredBrdfPdf(r, L) : 0.0;
    return L;
}

// The layered BRDF's reflected radiance under `env` (distribution `dist`): per sample one
// direction from layeredBrdfSample and one from the environment, balance heuristic.
vec3 layeredEnvironmentIBL(samplerCube env, sampler2D dist, LayeredReference r,
                           uint sampleCount, vec2 offset) {
    // Veach 1997, ch. 9: sum over strategies of f L / (p_brdf + p_env), one sample of each
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < sampleCount; i++) {
        vec2 Xi = rotatedHammersley(i, sampleCount, offset);
        float pb;
        vec3 Lb = layeredBrdfSample(r, Xi, pb);
        if (pb > 0.0) {
            vec3 f = layeredBrdfCosine(r, Lb);
            sum += f * textureLod(env, Lb, 0.0).rgb / (pb + environmentPdf(dist, Lb));
        }
        float pe;
        vec3 Le = sampleEnvironmentDirection(dist, environmentSamplePoint(Xi), pe);
        if (pe > 0.0) {
            vec3 f = layeredBrdfCosine(r, Le);
            sum += f * textureLod(env, Le, 0.0).rgb / (pe + layeredBrdfPdf(r, Le));
        }
    }
    return sum / float(sampleCount);
}

#if defined(MATERIAL_HAS_TRANSMISSION)
#if defined(MATERIAL_THIN_WALLED)
// Solid-angle density of L (below the surface) under the thin wall's BTDF sampling: the
// GGX normal m = normalize(V + L'), L' = L mirrored through the tangent plane, drawn by
// D (N.m), the reflection's Jacobian 1 / (4 V.m).
float thinWalledBtdfPdf(vec3 N, vec3 V, vec3 L, float a) {
    // Walter et al. 2007, "Microfacet Models for Refraction", eq 14 and 38, of the mirror
    vec3 Lm = L - 2.0 * dot(N, L) * N;
    vec3 h = V + Lm;
    float hh = dot(h, h);
    if (dot(N, L) >= 0.0 || hh < 1e-12) return 0.0;
    vec3 m = h * inversesqrt(hh);
    float VoM = dot(V, m);
    float NoM = dot(N, m);
    if (VoM <= 0.0 || NoM <= 0.0) return 0.0;
    vec3 NxM = cross(N, m);
    return D_GGX(NoM, a, dot(NxM, NxM)) * NoM / (4.0 * VoM);
}
#endif

// The transmitted radiance under the unfiltered environment `env` (distribution `dist`), by
// sampling the BTDF: a GGX microfacet normal m (density D |N.m|), then the view ray refracted
// through m (solid; the environment looked up along its exit from the sphere,
// transmission.glsl) or reflected about m and mirrored through the tangent plane
// (thin-walled, exactly the lobe the lights use). Thin walls add one environment sample a
// step, combined with the BTDF's by the balance heuristic (the direction seen is the
// direction inside); a solid's seen direction is its exit from the sphere, which has no
// closed-form inverse, so it samples the BTDF alone. The reflection is the layered
// estimator's; this one takes the transmitted part.
vec3 transmissionEnvironmentIBL(samplerCube env, sampler2D dist, ShadingContext s,
                                float roughness, uint sampleCount, vec2 offset) {
    // Walter et al. 2007, "Microfacet Models for Refraction through Rough Surfaces", eq 35-41:
    // with m drawn by D |N.m| the weight f |N.L| / p is (1 - F) G |V.m| / (|N.V| |N.m|), for
    // the refraction (the Jacobian of eq 17 cancels) and the mirrored reflection alike;
    // Veach 1997, ch. 9, the balance heuristic
    TransmissionLobe l = s.transmission;
    float NoV = dot(s.N, s.V);
    if (NoV <= 0.0 || l.weight <= 0.0) return vec3(0.0);
    float a = max(roughness * roughness, 1e-4);
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < sampleCount; i++) {
        vec2 Xi = rotatedHammersley(i, sampleCount, fract(offset + vec2(0.5, 0.25)));
#if defined(MATERIAL_THIN_WALLED)
        // the environment's sample (MIS): f |N.L| of the BTDF at the reference's alpha
        float pe;
        vec3 Le = sampleEnvironmentDirection(dist, environmentSamplePoint(Xi), pe);
        if (pe > 0.0 && dot(s.N, Le) < 0.0) {
            float VoHe;
            float fe = thinWalledBtdfCosineNoFresnel(s.N, s.V, Le, a, VoHe);
            sum += (1.0 - specularFresnel(s, VoHe)) * transmissionLayers(s, Le)
                 * (fe / (pe + thinWalledBtdfPdf(s.N, s.V, Le, a)))
                 * textureLod(env, Le, 0.0).rgb;
        }
#endif
        vec3 H = importanceSampleGGX(Xi, a, s.N);
        float VoH = dot(s.V, H);
        float NoH = dot(s.N, H);
        if (VoH <= 0.0 || NoH <= 0.0) continue;
#if defined(MATERIAL_THIN_WALLED)
        vec3 R = 2.0 * VoH * H - s.V;
        vec3 L = R - 2.0 * dot(s.N, R) * s.N;
        vec3 dir = L;
#else
        vec3 L = refractClamped(-s.V, H, 1.0 / l.eta);
        vec3 dir = transmissionSphereExit(s.N, L, l.eta);
#endif
        float NoL = dot(s.N, L);
        if (NoL >= 0.0) continue;
        float G = smithG1GGX(NoV, a) * smithG1GGX(NoL, a);
        float w = G * VoH / (NoV * NoH);
#if defined(MATERIAL_THIN_WALLED)
        // the balance heuristic's share of the BTDF's sample, p_b / (p_b + p_e); all of it
        // where the environment cannot draw L (p_e = 0)
        float pb = thinWalledBtdfPdf(s.N, s.V, L, a);
        float peL = environmentPdf(dist, L);
        if (peL > 0.0) w *= pb / (pb + peL);
#endif
        // the base's Fresnel (or the film's) and the layers over it, as the lights'
        // transmissionTowards (lights.glsl)
        sum += (1.0 - specularFresnel(s, VoH)) * transmissionLayers(s, L) * w
             * textureLod(env, dir, 0.0).rgb;
    }
    return sum * l.tint * (l.weight / float(sampleCount));
}
#endif

#endif
