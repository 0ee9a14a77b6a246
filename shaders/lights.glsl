// Analytic lights: the Light struct, the windowed inverse-square falloff, and
// point, directional, sphere and tube lights (representative point method).
// Each light returns outgoing radiance: diffuse + specular, times NoL, colour and intensity.
#include "common.glsl"
#include "brdf.glsl"
#include "coat.glsl"

#define LIGHT_TYPE_POINT 0
#define LIGHT_TYPE_DIRECTIONAL 1
#define LIGHT_TYPE_SPHERE 2
#define LIGHT_TYPE_TUBE 3

// 1 cm in metres: the notes' "+1" in centimetre units, keeps the falloff finite at d = 0.
const float LIGHT_FALLOFF_EPS = 0.01;
// Smallest perceptual roughness analytic lights see: a mirror has no finite peak.
const float MIN_ANALYTIC_ROUGHNESS = 0.03;
#if defined(MATERIAL_HAS_ANISOTROPY)
#include "anisotropy.glsl"
#endif
#if defined(MATERIAL_HAS_SUBSURFACE)
#include "subsurface.glsl"
#endif
#if defined(MATERIAL_HAS_THIN_FILM_THICKNESS)
#include "thin_film.glsl"
#endif
#if defined(MATERIAL_HAS_TRANSMISSION)
#include "transmission.glsl"
#endif

struct Light {
    int type;               // LIGHT_TYPE_*
    vec3 position;          // world, metres (centre for sphere and tube)
    vec3 direction;         // directional: direction the light travels; tube: unit axis
    vec3 color;             // linear RGB
    float intensity;
    float influenceRadius;  // R of the window; falloff is 0 at and beyond it
    float sourceRadius;     // sphere and tube
    float sourceLength;     // tube
};

// What a light needs to know about the point being shaded.
struct ShadingContext {
    vec3 P;                 // position
    vec3 N;                 // unit shading normal
    vec3 V;                 // unit vector to the eye
    float NoV;              // saturated, clamped away from 0
    vec3 diffuseColor;
    vec3 F0;
    float roughness;        // clamped to MIN_ANALYTIC_ROUGHNESS
    float a;                // roughness^2
    float k;                // Schlick-Smith k for analytic lights
    vec3 specularScale;     // 1, or the multiple-scattering compensation (ibl.glsl)
#if defined(MATERIAL_HAS_COAT)
    CoatContext coat;       // the clear coat over the base (coat.glsl; set by shadeSurface)
#endif
#if defined(MATERIAL_HAS_ANISOTROPY)
    AnisotropicLobe aniso;  // anisotropic GGX (anisotropy.glsl), set by shadeSurface
#endif
#if defined(MATERIAL_HAS_SHEEN_COLOR)
    vec3 sheenColor;        // as drawn (lobe views); set by setupSheen (sheen_shading.glsl)
    float sheenRoughness;   // clamped to MIN_SHEEN_ROUGHNESS
    float sheenAlpha;
    float sheenMax;         // max component of the material's sheenColor
    float sheenScaleV;      // the base's albedo scaling towards the eye
#endif
#if defined(MATERIAL_HAS_SUBSURFACE)
    SubsurfaceLobe subsurface;  // the subsurface diffuse (subsurface.glsl), set by shadeSurface
#endif
#if defined(MATERIAL_HAS_THIN_FILM_THICKNESS)
    ThinFilm film;          // the thin film on the base (thin_film.glsl), set by shadeSurface
#endif
#if defined(MATERIAL_HAS_TRANSMISSION)
    TransmissionLobe transmission;  // specular transmission (transmission.glsl), by shadeSurface
#endif
};

ShadingContext makeShadingContext(vec3 P, vec3 N, vec3 V, vec3 diffuseColor, vec3 F0,
                                  float roughness) {
    // Karis 2013, "Real Shading in Unreal Engine 4": a = roughness^2, k = (roughness + 1)^2 / 8
    ShadingContext s;
    s.P = P;
    s.N = N;
    s.V = V;
    s.NoV = max(dot(N, V), 1e-4);
    s.diffuseColor = diffuseColor;
    s.F0 = F0;
    s.roughness = clamp(roughness, MIN_ANALYTIC_ROUGHNESS, 1.0);
    s.a = s.roughness * s.roughness;
    s.k = k_Analytic(s.roughness);
    s.specularScale = vec3(1.0);
#if defined(MATERIAL_HAS_ANISOTROPY)
    // isotropic until shadeSurface sets the material's direction and anisotropy
    s.aniso = makeAnisotropicLobe(s.a, 0.0, vec3(1.0, 0.0, 0.0), N, N, N);
#endif
#if defined(MATERIAL_HAS_SUBSURFACE)
    // none until shadeSurface sets the material's
    s.subsurface = makeSubsurfaceLobe(0.0, vec3(1.0), vec3(1.0), 1.0, 0.0, 1.0);
#endif
#if defined(MATERIAL_HAS_THIN_FILM_THICKNESS)
    s.film = makeThinFilm(0.0, 1.3, 1.0, F0);  // none until shadeSurface sets the material's
#endif
#if defined(MATERIAL_HAS_TRANSMISSION)
    // none until shadeSurface sets the material's
    s.transmission = makeTransmissionLobe(0.0, vec3(1.0), vec3(1.0), 0.0, 0.0, 1.5, 0.0, 0.0,
                                          N, V, 1.0);
#endif
    return s;
}

// The base specular's Fresnel at VoH: Schlick's (spherical-Gaussian weight), or the thin
// film's Airy reflectance where the material has a film there.
vec3 specularFresnel(ShadingContext s, float VoH) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 5; Belcour & Barla 2017 (thin_film.glsl)
#if defined(MATERIAL_HAS_THIN_FILM_THICKNESS)
    if (s.film.thickness > 0.0) return thinFilmFresnel(s.film, VoH);
#endif
    return F_Schlick(s.F0, VoH);
}

// The diffuse lobe's f NoL for a light of signed cosine NoL to the shading normal: Lambert
// of the clamped cosine, plus the subsurface lobe (wrapped, and transmitted from behind)
// where the material has one.
vec3 diffuseTowards(ShadingContext s, float NoL) {
    // Karis 2013, "Real Shading in Unreal Engine 4", diffuse BRDF: Lambert; the subsurface
    // diffuse of subsurface.glsl (docs/shading.md, Subsurface)
    vec3 diffuse = diffuseLobe(s.diffuseColor) * saturate(NoL);
#if defined(MATERIAL_HAS_SUBSURFACE)
    diffuse += subsurfaceCosine(s.subsurface, NoL);
#endif
    return diffuse;
}

#if defined(MATERIAL_HAS_SHEEN_COLOR)
// The sheen over the base, defined in sheen_shading.glsl (surface.glsl includes it, after the
// IBL inputs it reads).
vec3 sheenLayer(ShadingContext s, vec3 base, vec3 L, float cosine);
vec3 sheenLayerCosine(ShadingContext s, vec3 base, vec3 L);
#endif

// The smooth window that takes the falloff to exactly 0 at the influence radius.
float distanceWindow(float d, float influenceRadius) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 9: saturate(1 - (d / R)^4)^2
    float x = d / influenceRadius;
    float x2 = x * x;
    return sq(saturate(1.0 - x2 * x2));
}

// Windowed inverse-square falloff.
float distanceFalloff(float d, float influenceRadius) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 9, with eps = 1 cm in metres
    return distanceWindow(d, influenceRadius) / (d * d + LIGHT_FALLOFF_EPS * LIGHT_FALLOFF_EPS);
}

// Specular lobe times NoL towards the unit direction L.
vec3 specularTowards(ShadingContext s, vec3 L) {
    // Karis 2013, "Real Shading in Unreal Engine 4", specular D Vis F, times NoL
#if defined(MATERIAL_HAS_ANISOTROPY)
#if defined(MATERIAL_HAS_THIN_FILM_THICKNESS)
    if (s.film.thickness > 0.0) {
        // F0 = 1 makes the lobe's Schlick factor exactly 1; the film's reflectance at V.H
        vec3 hf = L + s.V;
        float VoHf = saturate(dot(s.V, hf * inversesqrt(max(dot(hf, hf), 1e-30))));
        return anisotropicSpecularTowards(s.aniso, s.N, s.V, s.NoV, vec3(1.0), L)
             * thinFilmFresnel(s.film, VoHf) * s.specularScale;
    }
#endif
    return anisotropicSpecularTowards(s.aniso, s.N, s.V, s.NoV, s.F0, L) * s.specularScale;
#endif
    float NoL = saturate(dot(s.N, L));
    // Below the horizon nothing is reflected. Nor where L = -V (a view from behind the
    // surface, a representative point straight behind the shading point): H is undefined.
    vec3 h = L + s.V;
    if (NoL <= 0.0 || dot(h, h) < 1e-12) return vec3(0.0);
    vec3 H = h * inversesqrt(max(dot(h, h), 1e-30));
    float NoH = saturate(dot(s.N, H));
    float VoH = saturate(dot(s.V, H));
    vec3 NxH = cross(s.N, H);
    float D = D_GGX(NoH, s.a, dot(NxH, NxH));
    return D * V_SchlickSmith(s.NoV, NoL, s.k) * specularFresnel(s, VoH) * NoL * s.specularScale;
}

// Point on a sphere closest to the reflection ray, as an unnormalised vector from P.
vec3 sphereRepresentativePoint(vec3 Lc, vec3 R, float sourceRadius) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 11: closest point on the sphere to R
    vec3 centerToRay = dot(Lc, R) * R - Lc;
    float t = saturate(sourceRadius / max(length(centerToRay), 1e-8));
    return Lc + centerToRay * t;
}

// Energy conservation of the widened highlight: (a / a')^2.
float sphereNormalization(float a, float sourceRadius, float d) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 10, 14: a' = saturate(a + sourceRadius / (2 d))
    float aPrime = saturate(a + sourceRadius / (MATEDIT_AREA_WIDEN_DIVISOR * max(d, 1e-8)));
    return sq(a / aPrime);
}

// Energy conservation of a line's highlight: a / a'_line.
float lineNormalization(float a, float sourceLength, float d) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 20 (form a / a'); a' as docs/shading.md#analytic-lights
    float aPrime = saturate(a + 0.5 * sourceLength / (MATEDIT_AREA_WIDEN_DIVISOR * max(d, 1e-8)));
    return a / aPrime;
}

vec3 pointLight(ShadingContext s, Light light) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 9: punctual light with windowed falloff
    vec3 Lc = light.position - s.P;
    float d = length(Lc);
    vec3 L = Lc / max(d, 1e-8);
    float NoL = saturate(dot(s.N, L));
    vec3 radiance = diffuseTowards(s, dot(s.N, L)) + specularTowards(s, L);
#if defined(MATERIAL_HAS_SHEEN_COLOR)
    radiance = sheenLayer(s, radiance, L, NoL);
#endif
#if defined(MATERIAL_HAS_COAT)
    radiance = coatLayer(s.coat, s.V, L, radiance);  // the base through the coat, its highlight
#endif
    return radiance * light.color * (light.intensity * distanceFalloff(d, light.influenceRadius));
}

vec3 directionalLight(ShadingContext s, Light light) {
    // Karis 2013, "Real Shading in Unreal Engine 4", punctual lights: directional, no falloff
    vec3 L = -light.direction;
    float NoL = saturate(dot(s.N, L));
    vec3 radiance = diffuseTowards(s, dot(s.N, L)) + specularTowards(s, L);
#if defined(MATERIAL_HAS_SHEEN_COLOR)
    radiance = sheenLayer(s, radiance, L, NoL);
#endif
#if defined(MATERIAL_HAS_COAT)
    radiance = coatLayer(s.coat, s.V, L, radiance);  // the base through the coat, its highlight
#endif
    return radiance * light.color * light.intensity;
}

#if defined(MATERIAL_HAS_ANISOTROPY)
// The sphere light's representative direction (unnormalised, from P) for the anisotropic
// lobe: the disc point closest to the mirror direction R in the lobe's metric. Where R
// points away from the light (R.Ln <= 0) the talk's closest point to the ray is kept.
vec3 anisotropicSphereRepresentativePoint(AnisotropicLobe l, vec3 Lc, vec3 R,
                                          float sourceRadius) {
    // matedit anisotropic representative point (docs/shading.md, Anisotropy), of Karis 2013,
    // "Real Shading in Unreal Engine 4", eq 11 (the point of the light closest to R)
    float d = length(Lc);
    vec3 Ln = Lc / max(d, 1e-8);
    float RoL = dot(R, Ln);
    if (RoL <= 1e-8) return sphereRepresentativePoint(Lc, R, sourceRadius);
    vec3 e1, e2;
    anisotropicLightFrame(l, Ln, e1, e2);
    vec3 o = R / RoL - Ln;
    float rho = sourceRadius * inversesqrt(max(d * d - sourceRadius * sourceRadius, 1e-16));
    vec2 p = anisotropicDiscPoint(vec2(dot(o, e1), dot(o, e2)), rho, sq(l.ab / l.at));
    return Ln + p.x * e1 + p.y * e2;
}
#endif

vec3 sphereLight(ShadingContext s, Light light) {
    // Karis 2013, "Real Shading in Unreal Engine 4", sphere lights: representative point
    vec3 Lc = light.position - s.P;
    float d = length(Lc);
    float falloff = distanceFalloff(d, light.influenceRadius);
    // Diffuse: the irradiance of a point light at the centre.
    float NoLc = saturate(dot(s.N, Lc / max(d, 1e-8)));
    vec3 diffuse = diffuseTowards(s, dot(s.N, Lc / max(d, 1e-8)));
    // Specular: the point of the sphere closest to the reflection ray, energy renormalised.
    vec3 R = reflect(-s.V, s.N);
#if defined(MATERIAL_HAS_ANISOTROPY)
    // the point closest to R in the lobe's metric (anisotropy 0: the talk's, bit for bit)
    vec3 specular;
    if (s.aniso.anisotropy > 0.0) {
        vec3 La = normalize(anisotropicSphereRepresentativePoint(s.aniso, Lc, R,
                                                                 light.sourceRadius));
        specular = specularTowards(s, La)
                 * anisotropicSphereNormalization(s.aniso, s.V, La, light.sourceRadius, d);
    } else {
        vec3 L = normalize(sphereRepresentativePoint(Lc, R, light.sourceRadius));
        specular = specularTowards(s, L) * sphereNormalization(s.a, light.sourceRadius, d);
    }
#else
    vec3 L = normalize(sphereRepresentativePoint(Lc, R, light.sourceRadius));
    vec3 specular = specularTowards(s, L) * sphereNormalization(s.a, light.sourceRadius, d);
#endif
#if defined(MATERIAL_HAS_SHEEN_COLOR)
    // Sheen: a wide lobe, taken towards the centre like the diffuse (sheen_shading.glsl).
    diffuse = sheenLayer(s, diffuse + specular, Lc / max(d, 1e-8), NoLc);
    specular = vec3(0.0);
#endif
#if defined(MATERIAL_HAS_COAT)
    // The base through the coat towards the centre; the coat's highlight by its own
    // representative point (its reflection vector) and widening (its alpha).
    vec3 Lcoat = normalize(sphereRepresentativePoint(Lc, reflect(-s.V, s.coat.N),
                                                     light.sourceRadius));
    return ((diffuse + specular) * coatTransmittance(s.coat, dot(s.coat.N, Lc) / max(d, 1e-8))
            + coatSpecularTowards(s.coat, s.V, Lcoat)
              * sphereNormalization(s.coat.a, light.sourceRadius, d))
           * light.color * (light.intensity * falloff);
#endif
    return (diffuse + specular) * light.color * (light.intensity * falloff);
}

// The segment's mean cosine to N of its two ends' directions (signed: below the horizon
// negative), the numerator of the tube's irradiance.
float tubeCosine(vec3 N, vec3 L0, vec3 L1) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 16: (N.L0 / |L0| + N.L1 / |L1|) / 2
    return dot(N, L0) / (2.0 * length(L0)) + dot(N, L1) / (2.0 * length(L1));
}

// The denominator of the tube's irradiance, |L0||L1| + L0.L1 + 2 eps^2.
float tubeDenominator(vec3 L0, vec3 L1) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 16, eps^2 terms as in eq 9
    // |L0||L1| + L0.L1 cancels when P lies near the segment between its ends (L0, L1
    // opposed); there use the equal |L0 x L1|^2 / (|L0||L1| - L0.L1), which does not.
    float l0l1 = length(L0) * length(L1);
    float d01 = dot(L0, L1);
    vec3 c = cross(L0, L1);
    float den = d01 >= 0.0 ? l0l1 + d01 : dot(c, c) / (l0l1 - d01);
    float eps2 = LIGHT_FALLOFF_EPS * LIGHT_FALLOFF_EPS;
    return den + 2.0 * eps2;
}

// Average irradiance factor of a segment from L0 to L1 (unnormalised, from P), without the window.
float tubeIrradiance(vec3 N, vec3 L0, vec3 L1) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 16, eps^2 terms as in eq 9
    return 2.0 * saturate(tubeCosine(N, L0, L1)) / tubeDenominator(L0, L1);
}

// Point of a segment closest to the reflection ray, as an unnormalised vector from P.
vec3 tubeRepresentativePoint(vec3 L0, vec3 L1, vec3 R) {
    // Karis 2013, "Real Shading in Unreal Engine 4", eq 19: shortest distance to the ray
    vec3 Ld = L1 - L0;
    float RoLd = dot(R, Ld);
    float t = (dot(R, L0) * RoLd - dot(L0, Ld)) / max(dot(Ld, Ld) - RoLd * RoLd, 1e-12);
    return L0 + saturate(t) * Ld;
}

#if defined(MATERIAL_HAS_ANISOTROPY)
// The tube's point on its segment L0 L1 (from P) for the anisotropic lobe: the segment's
// gnomonic image (about its centre's direction) is a segment g0 g1; its point closest to the
// mirror direction's image o in the lobe's metric is a clamped quadratic minimum, s; the
// segment parameter of that direction is t = s z0 / (s z0 + (1 - s) z1) (z = L.Ln: the
// gnomonic image is projective in t). Where R points away, the talk's closest point to the ray.
vec3 anisotropicTubeRepresentativePoint(AnisotropicLobe l, vec3 L0, vec3 L1, vec3 R) {
    // matedit anisotropic representative point (docs/shading.md, Anisotropy), of Karis 2013,
    // "Real Shading in Unreal Engine 4", eq 19 (the point of the segment closest to R)
    vec3 Lc = 0.5 * (L0 + L1);
    vec3 Ln = Lc / max(length(Lc), 1e-8);
    float z0 = dot(L0, Ln);
    float z1 = dot(L1, Ln);
    float RoL = dot(R, Ln);
    if (RoL <= 1e-8 || z0 <= 1e-8 || z1 <= 1e-8) return tubeRepresentativePoint(L0, L1, R);
    vec3 e1, e2;
    anisotropicLightFrame(l, Ln, e1, e2);
    vec3 g0 = L0 / z0;
    vec3 dl = L1 / z1 - g0;
    vec3 og = R / RoL - g0;
    float q = sq(l.ab / l.at);
    float dl1 = dot(dl, e1);
    float dl2 = dot(dl, e2);
    float num = q * dot(og, e1) * dl1 + dot(og, e2) * dl2;
    float den = q * dl1 * dl1 + dl2 * dl2;
    float s = saturate(num / max(den, 1e-30));
    float t = s * z0 / max(s * z0 + (1.0 - s) * z1, 1e-30);
    return L0 + t * (L1 - L0);
}
#endif

vec3 tubeLight(ShadingContext s, Light light) {
    // Karis 2013, "Real Shading in Unreal Engine 4", tube lights: eq 16 diffuse, eq 19 specular
    vec3 Lc = light.position - s.P;
    float d = length(Lc);
    vec3 halfAxis = 0.5 * light.sourceLength * light.direction;
    vec3 L0 = Lc - halfAxis;
    vec3 L1 = Lc + halfAxis;
    float window = distanceWindow(d, light.influenceRadius);
    vec3 diffuse = diffuseLobe(s.diffuseColor) * tubeIrradiance(s.N, L0, L1);
#if defined(MATERIAL_HAS_SUBSURFACE)
    // the subsurface lobe of the segment's signed mean cosine (wrapped and transmitted)
    diffuse += subsurfaceCosine(s.subsurface, tubeCosine(s.N, L0, L1))
             * (2.0 / tubeDenominator(L0, L1));
#endif
    // Specular: the sphere step around the closest point on the segment; our choice of
    // falloff is the inverse square to that point (the tube's limit is the sphere light).
    vec3 R = reflect(-s.V, s.N);
#if defined(MATERIAL_HAS_ANISOTROPY)
    // the points closest to R in the lobe's metric (anisotropy 0: the talk's, bit for bit)
    vec3 Lp;
    float dp;
    vec3 L;
    float energy;
    if (s.aniso.anisotropy > 0.0) {
        Lp = anisotropicTubeRepresentativePoint(s.aniso, L0, L1, R);
        dp = length(Lp);
        L = normalize(anisotropicSphereRepresentativePoint(s.aniso, Lp, R, light.sourceRadius));
        energy = anisotropicTubeNormalization(s.aniso, s.N, s.V, L, light.direction,
                                              light.sourceLength, d, light.sourceRadius, dp);
    } else {
        Lp = tubeRepresentativePoint(L0, L1, R);
        dp = length(Lp);
        L = normalize(sphereRepresentativePoint(Lp, R, light.sourceRadius));
        energy = lineNormalization(s.a, light.sourceLength, d)
               * sphereNormalization(s.a, light.sourceRadius, dp);
    }
#else
    vec3 Lp = tubeRepresentativePoint(L0, L1, R);
    float dp = length(Lp);
    vec3 L = normalize(sphereRepresentativePoint(Lp, R, light.sourceRadius));
    float energy = lineNormalization(s.a, light.sourceLength, d)
                 * sphereNormalization(s.a, light.sourceRadius, dp);
#endif
    float eps2 = LIGHT_FALLOFF_EPS * LIGHT_FALLOFF_EPS;
    vec3 specular = specularTowards(s, L) * (energy / (dp * dp + eps2));
#if defined(MATERIAL_HAS_SHEEN_COLOR)
    // Sheen: a wide lobe, towards the centre times the segment's irradiance, like the diffuse.
    vec3 Lcn = Lc / max(d, 1e-8);
    diffuse = sheenLayer(s, diffuse + specular, Lcn, tubeIrradiance(s.N, L0, L1));
    specular = vec3(0.0);
#endif
#if defined(MATERIAL_HAS_COAT)
    // The base through the coat towards the centre; the coat's highlight by the same steps
    // along its own reflection vector, with its own alpha.
    vec3 Rc = reflect(-s.V, s.coat.N);
    vec3 Lpc = tubeRepresentativePoint(L0, L1, Rc);
    float dpc = length(Lpc);
    vec3 Lcoat = normalize(sphereRepresentativePoint(Lpc, Rc, light.sourceRadius));
    float coatEnergy = lineNormalization(s.coat.a, light.sourceLength, d)
                     * sphereNormalization(s.coat.a, light.sourceRadius, dpc);
    return ((diffuse + specular) * coatTransmittance(s.coat, dot(s.coat.N, Lc) / max(d, 1e-8))
            + coatSpecularTowards(s.coat, s.V, Lcoat) * (coatEnergy / (dpc * dpc + eps2)))
           * light.color * (light.intensity * window);
#endif
    return (diffuse + specular) * light.color * (light.intensity * window);
}

#if defined(MATERIAL_HAS_TRANSMISSION)
#if defined(MATERIAL_HAS_SHEEN_COLOR)
float sheenBaseScale(ShadingContext s, float NoL);  // sheen_shading.glsl
#endif

// What the transmitted light keeps of the layers over the base towards L (below the
// surface): the sheen's albedo scaling and the coat's transmittance, as the base's
// reflection has them, the light's cosine taken mirrored (-N.L): it crosses the layers once
// where it enters the part (behind) and once where it leaves towards the eye.
vec3 transmissionLayers(ShadingContext s, vec3 L) {
    // glTF KHR_materials_sheen albedo scaling (sheen_shading.glsl, sheenBaseScale); the coat's
    // (1 - Fc(V)) (1 - Fc(L)) coatColor (coat.glsl, coatTransmittance)
    vec3 k = vec3(1.0);
#if defined(MATERIAL_HAS_SHEEN_COLOR)
    k *= sheenBaseScale(s, -dot(s.N, L));
#endif
#if defined(MATERIAL_HAS_COAT)
    k *= coatTransmittance(s.coat, -dot(s.coat.N, L));
#endif
    return k;
}

// f |NoL| of the transmission lobe towards L (below the surface), thin-walled or solid,
// its Fresnel the base specular's (Schlick's, or the thin film's: 1 - F is what it lets
// through), through the layers over the base.
vec3 transmissionTowards(ShadingContext s, vec3 L) {
    // Walter et al. 2007 (transmission.glsl): the solid's BTDF, or the thin wall's
    float VoH;
#if defined(MATERIAL_THIN_WALLED)
    float f = thinWalledBtdfCosineNoFresnel(s.N, s.V, L, s.a, VoH);
#else
    float f = refractionBtdfCosineNoFresnel(s.N, s.V, L, s.a, s.transmission.eta, VoH);
#endif
    return (1.0 - specularFresnel(s, VoH)) * f * s.transmission.tint * s.transmission.weight
         * transmissionLayers(s, L);
}

// Radiance transmitted towards V from a light behind the surface: each type as its
// specular, with the transmitted view ray (s.transmission.inside) in place of the reflected
// one for the sphere's and the tube's representative points.
vec3 transmissionLight(ShadingContext s, Light light) {
    // Karis 2013, "Real Shading in Unreal Engine 4", representative point (eq 10-11, 16-20)
    // of the view ray through the part (docs/shading.md, Transmission)
    vec3 ray = s.transmission.inside;
    if (light.type == LIGHT_TYPE_DIRECTIONAL) {
        return transmissionTowards(s, -light.direction) * light.color * light.intensity;
    }
    vec3 Lc = light.position - s.P;
    float d = length(Lc);
    if (light.type == LIGHT_TYPE_SPHERE) {
        vec3 L = normalize(sphereRepresentativePoint(Lc, ray, light.sourceRadius));
        return transmissionTowards(s, L) * sphereNormalization(s.a, light.sourceRadius, d)
             * light.color * (light.intensity * distanceFalloff(d, light.influenceRadius));
    }
    if (light.type == LIGHT_TYPE_TUBE) {
        vec3 halfAxis = 0.5 * light.sourceLength * light.direction;
        vec3 Lp = tubeRepresentativePoint(Lc - halfAxis, Lc + halfAxis, ray);
        float dp = length(Lp);
        vec3 L = normalize(sphereRepresentativePoint(Lp, ray, light.sourceRadius));
        float energy = lineNormalization(s.a, light.sourceLength, d)
                     * sphereNormalization(s.a, light.sourceRadius, dp);
        float eps2 = LIGHT_FALLOFF_EPS * LIGHT_FALLOFF_EPS;
        return transmissionTowards(s, L) * (energy / (dp * dp + eps2)) * light.color
             * (light.intensity * distanceWindow(d, light.influenceRadius));
    }
    return transmissionTowards(s, Lc / max(d, 1e-8)) * light.color
         * (light.intensity * distanceFalloff(d, light.influenceRadius));
}
#endif

// Radiance reflected towards V from one light, by type.
vec3 evaluateLight(ShadingContext s, Light light) {
    // Karis 2013, "Real Shading in Unreal Engine 4", dispatch over the light types
#if defined(MATERIAL_HAS_TRANSMISSION)
    vec3 through = transmissionLight(s, light);  // from behind the surface
#else
    const vec3 through = vec3(0.0);
#endif
    if (light.type == LIGHT_TYPE_DIRECTIONAL) return directionalLight(s, light) + through;
    if (light.type == LIGHT_TYPE_SPHERE) return sphereLight(s, light) + through;
    if (light.type == LIGHT_TYPE_TUBE) return tubeLight(s, light) + through;
    return pointLight(s, light) + through;
}
