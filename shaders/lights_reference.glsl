// Reference for the area lights: Monte Carlo integration of the full BRDF over the light's
// shape, to compare the representative-point approximations against (reference mode).
//
// Emitters: a sphere of radius r with uniform radiance Le = I / (pi r^2) (its irradiance is
// the point light's, which the model uses for diffuse); a tube is a capsule (segment of
// length l, radius r) of uniform radiance Le = I / (2 r l + pi r^2) (its broadside projected
// area; l -> 0 gives the sphere); a tube of radius 0 is a line whose elements radiate like a
// thin cylinder's, intensity (I / l) sin(psi) per length. The distance window of the model
// (at the centre's distance) multiplies all of them.
// Estimators: the sphere's cone of directions sampled uniformly, the capsule's surface by
// area, each combined with GGX half-vector sampling by the balance heuristic (multiple
// importance sampling, Veach 1997): light sampling serves wide lobes and the diffuse, GGX
// sampling the narrow highlights inside a large light.
#include "common.glsl"
#include "brdf.glsl"
#include "sampling.glsl"
#include "lights.glsl"

// f(l, v) N.l of the whole BRDF (Lambert + specular lobe) towards the unit direction L.
// The specular lobe is specularTowards', anisotropic GGX where the material writes
// anisotropy (MATERIAL_HAS_ANISOTROPY, anisotropy.glsl).
vec3 brdfCosine(ShadingContext s, vec3 L) {
    // Karis 2013, "Real Shading in Unreal Engine 4": diffuse + D Vis F, times NoL
    // the diffuse of the signed cosine: the subsurface lobe's wrap and transmission reach
    // below the horizon (lights.glsl diffuseTowards)
    vec3 base = diffuseTowards(s, dot(s.N, L)) + specularTowards(s, L);
#if defined(MATERIAL_HAS_SHEEN_COLOR)
    base = sheenLayerCosine(s, base, L);  // the sheen over the base (sheen_shading.glsl)
#endif
#if defined(MATERIAL_HAS_COAT)
    // the base (and its sheen) through the clear coat, plus the coat's lobe (coat.glsl)
    base = coatLayer(s.coat, s.V, L, base);
#endif
    return base;
}

// Solid-angle density of the direction L under GGX half-vector sampling around N.
float ggxDirectionPdf(ShadingContext s, vec3 L) {
    // Walter et al. 2007, "Microfacet Models for Refraction": p(l) = D(h) NoH / (4 VoH)
#if defined(MATERIAL_HAS_ANISOTROPY)
    return ggxAnisotropicDirectionPdf(s.aniso, s.N, s.V, L);
#endif
    return ggxReflectionPdf(s.N, s.V, L, s.a);
}

// A GGX-sampled direction for the point Xi (may lie below the horizon).
vec3 ggxSampleDirection(ShadingContext s, vec2 Xi) {
    // Karis 2013, ImportanceSampleGGX, then L = 2 (V.H) H - V
#if defined(MATERIAL_HAS_ANISOTROPY)
    return ggxAnisotropicSampleDirection(s.aniso, s.N, s.V, Xi);
#endif
    vec3 H = importanceSampleGGX(Xi, s.a, s.N);
    return 2.0 * dot(s.V, H) * H - s.V;
}

// The second point set of the pair: the same Hammersley point, coordinates swapped and
// shifted, so light and BRDF samples are not aligned.
vec2 companionPoint(vec2 u) {
    // Cranley-Patterson rotation of the swapped point
    return fract(u.yx + vec2(0.5, 0.25));
}

vec3 referenceSphereLight(ShadingContext s, Light light, uint count, vec2 offset) {
    // Monte Carlo over the sphere's cone of directions, MIS with GGX sampling
    vec3 Lc = light.position - s.P;
    float d = length(Lc);
    float r = light.sourceRadius;
    if (r <= 0.0 || d <= r * 1.0001) return sphereLight(s, light);
    vec3 axis = Lc / d;
    float cosMax = sqrt(max(0.0, 1.0 - sq(r / d)));
    float lightPdf = 1.0 / (2.0 * PI * (1.0 - cosMax));
    vec3 T;
    vec3 B;
    tangentFrame(axis, T, B);
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < count; i++) {
        vec2 u = rotatedHammersley(i, count, offset);
        float cosT = 1.0 - u.y * (1.0 - cosMax);
        float sinT = sqrt(max(0.0, 1.0 - cosT * cosT));
        float phi = 2.0 * PI * u.x;
        vec3 L = T * (sinT * cos(phi)) + B * (sinT * sin(phi)) + axis * cosT;
        sum += brdfCosine(s, L) / (lightPdf + ggxDirectionPdf(s, L));
        vec3 Lb = ggxSampleDirection(s, companionPoint(u));
        if (dot(Lb, axis) >= cosMax && dot(s.N, Lb) > 0.0) {
            sum += brdfCosine(s, Lb) / (lightPdf + ggxDirectionPdf(s, Lb));
        }
    }
    float Le = light.intensity * distanceWindow(d, light.influenceRadius) / (PI * r * r);
    return light.color * Le * sum / float(count);
}

// Distance along the unit ray from the origin to its first hit with the capsule around the
// segment pa-pb of radius r; -1 when it misses. `n` receives the outward normal there.
float capsuleHit(vec3 rd, vec3 pa, vec3 pb, float r, out vec3 n) {
    // Ray against the cylinder's side (a quadratic in t, kept where the foot lies between the
    // ends), else against the end sphere on the side the ray approaches from.
    vec3 ba = pb - pa;
    vec3 oa = -pa;
    float baba = dot(ba, ba);
    float bard = dot(ba, rd);
    float baoa = dot(ba, oa);
    float rdoa = dot(rd, oa);
    float oaoa = dot(oa, oa);
    float qa = baba - bard * bard;
    float qb = baba * rdoa - baoa * bard;
    float qc = baba * oaoa - baoa * baoa - r * r * baba;
    float disc = qb * qb - qa * qc;
    n = vec3(0.0);
    if (disc < 0.0) return -1.0;
    vec3 c;
    if (qa > 1e-12) {
        float t = (-qb - sqrt(disc)) / qa;
        float y = baoa + t * bard;
        if (t > 0.0 && y > 0.0 && y < baba) {
            n = (t * rd - (pa + ba * (y / baba))) / r;
            return t;
        }
        c = y <= 0.0 ? pa : pb;
    } else {  // along the axis: the nearer end
        c = dot(pa, rd) < dot(pb, rd) ? pa : pb;
    }
    float b = dot(rd, -c);
    float h = b * b - (dot(c, c) - r * r);
    if (h < 0.0) return -1.0;
    float t = -b - sqrt(h);
    if (t <= 0.0) return -1.0;
    n = (t * rd - c) / r;
    return t;
}

vec3 referenceTubeLight(ShadingContext s, Light light, uint count, vec2 offset) {
    // Monte Carlo over the capsule's surface (by area) or along the line, MIS with GGX
    vec3 Lc = light.position - s.P;
    float d = length(Lc);
    float len = light.sourceLength;
    float r = light.sourceRadius;
    if (len <= 0.0) return r > 0.0 ? referenceSphereLight(s, light, count, offset)
                                    : pointLight(s, light);
    vec3 axis = light.direction;
    vec3 pa = Lc - 0.5 * len * axis;
    vec3 pb = Lc + 0.5 * len * axis;
    float window = distanceWindow(d, light.influenceRadius);
    vec3 T;
    vec3 B;
    tangentFrame(axis, T, B);
    vec3 sum = vec3(0.0);
    if (r <= 0.0) {
        // a line: t uniform along it (pdf 1 / len), intensity (I / len) sin(psi) per length
        for (uint i = 0u; i < count; i++) {
            vec2 u = rotatedHammersley(i, count, offset);
            vec3 X = pa + (u.x * len) * axis;
            float dist2 = dot(X, X);
            vec3 L = X * inversesqrt(dist2);
            float sinPsi = length(cross(L, axis));
            sum += brdfCosine(s, L) * (sinPsi / dist2);
        }
        return light.color * (light.intensity * window) * sum / float(count);
    }
    // inside the capsule: no reference, the model's value
    vec3 foot = pa + axis * clamp(dot(-pa, axis), 0.0, len);
    if (dot(foot, foot) <= r * r) return tubeLight(s, light);
    float sideArea = 2.0 * PI * r * len;
    float area = sideArea + 4.0 * PI * r * r;
    for (uint i = 0u; i < count; i++) {
        vec2 u = rotatedHammersley(i, count, offset);
        float pick = u.x * area;
        float phi = 2.0 * PI * u.y;
        vec3 n;
        vec3 X;
        if (pick < sideArea) {
            n = T * cos(phi) + B * sin(phi);
            X = pa + axis * (len * pick / sideArea) + r * n;
        } else {
            float z = 1.0 - 2.0 * (pick - sideArea) / (area - sideArea);
            float rho = sqrt(max(0.0, 1.0 - z * z));
            n = T * (rho * cos(phi)) + B * (rho * sin(phi)) + axis * z;
            X = (z >= 0.0 ? pb : pa) + r * n;
        }
        float dist2 = dot(X, X);
        vec3 L = X * inversesqrt(dist2);
        float cosL = -dot(n, L);
        if (cosL > 0.0) {  // back-facing points are hidden by the capsule itself
            float lightPdf = dist2 / (cosL * area);
            sum += brdfCosine(s, L) / (lightPdf + ggxDirectionPdf(s, L));
        }
        vec3 Lb = ggxSampleDirection(s, companionPoint(u));
        if (dot(s.N, Lb) > 0.0) {
            vec3 nb;
            float t = capsuleHit(Lb, pa, pb, r, nb);
            float cosB = -dot(nb, Lb);
            if (t > 0.0 && cosB > 0.0) {
                float lightPdf = t * t / (cosB * area);
                sum += brdfCosine(s, Lb) / (lightPdf + ggxDirectionPdf(s, Lb));
            }
        }
    }
    float Le = light.intensity * window / (2.0 * r * len + PI * r * r);
    return light.color * Le * sum / float(count);
}

// One light's reflected radiance: Monte Carlo for sphere and tube lights, exact for the
// punctual ones (they are what they are).
vec3 evaluateLightReference(ShadingContext s, Light light, uint count, vec2 offset) {
    // matedit reference mode: see the top of this file
    if (light.type == LIGHT_TYPE_SPHERE) return referenceSphereLight(s, light, count, offset);
    if (light.type == LIGHT_TYPE_TUBE) return referenceTubeLight(s, light, count, offset);
    return evaluateLight(s, light);
}
