// Thin-film iridescence: a dielectric film of thickness d (nm) and IOR n2 on the base, its
// reflectance the Airy sum of the two interfaces (outside | film, film | base) in place of
// the base specular's Fresnel. Evaluated as glTF KHR_materials_iridescence does: Belcour &
// Barla 2017's Fourier form of the Airy sum, each order against the CIE XYZ sensitivities
// fitted by Gaussians (analytically), then XYZ to linear Rec.709; but with the first
// THIN_FILM_ORDERS orders where the extension keeps two (docs/shading.md, Thin film).
// Included by lights.glsl under MATERIAL_HAS_THIN_FILM_THICKNESS (docs/shading.md, Thin film).
#include "common.glsl"

// The film at a point: thickness 0 is no film (the plain Fresnel, exactly).
struct ThinFilm {
    float thickness;   // nm
    float ior;         // the film's
    float outsideIor;  // the medium above it: 1, or the coat's where there is one
    vec3 baseIor;      // the base's (conductors too), from its F0 against air
};

// The IOR of an interface against air with reflectance F0 at normal incidence, the inverse
// of F0 = ((n - 1) / (n + 1))^2; F0 kept below 1 (a finite IOR).
vec3 thinFilmIorOfF0(vec3 F0) {
    // glTF KHR_materials_iridescence, "Fresnel0ToIor": n = (1 + sqrt F0) / (1 - sqrt F0)
    vec3 s = sqrt(clamp(F0, 0.0, 0.9999));
    return (1.0 + s) / (1.0 - s);
}

// Reflectance at normal incidence of the interface between IORs n and nOut.
vec3 thinFilmF0OfIor(vec3 n, float nOut) {
    // Fresnel at normal incidence ((n - nOut) / (n + nOut))^2 (glTF KHR_materials_ior)
    vec3 r = (n - nOut) / (n + nOut);
    return r * r;
}

// Schlick's Fresnel with the exact fifth power, as the extension's Airy evaluation uses.
vec3 thinFilmSchlick(vec3 F0, float c) {
    // Schlick 1994, "An Inexpensive BRDF Model for Physically-based Rendering"
    float x = 1.0 - c;
    float x2 = x * x;
    return F0 + (1.0 - F0) * (x2 * x2 * x);
}

// The film for the material's fields; F0 is the base's against air (metals' base colour).
ThinFilm makeThinFilm(float thickness, float ior, float outsideIor, vec3 F0) {
    // glTF KHR_materials_iridescence: the base's IOR from its F0 (conductors included)
    ThinFilm f;
    f.thickness = max(thickness, 0.0);
    f.ior = ior;
    f.outsideIor = outsideIor;
    f.baseIor = thinFilmIorOfF0(F0);
    return f;
}

// The spectral sensitivity's Fourier term: the XYZ colour-matching functions (fitted by
// Gaussians in wavenumber) integrated against cos(2 pi opd / lambda + shift), at optical
// path difference opd (nm), each of X, Y, Z with its own phase shift, in linear Rec.709.
vec3 thinFilmSensitivity(float opd, vec3 shift) {
    // Belcour & Barla 2017, "A Practical Extension to Microfacet Theory for the Modeling of
    // Varying Iridescence", sec. 4 and supplemental (the Gaussian fit); its constants as
    // glTF KHR_materials_iridescence tabulates them; XYZ to Rec.709 of IEC 61966-2-1
    float phase = 2.0 * PI * opd * 1e-9;
    vec3 amp = vec3(5.4856e-13, 4.4201e-13, 5.2481e-13);
    vec3 mean = vec3(1.6810e6, 1.7953e6, 2.2084e6);
    vec3 var = vec3(4.3278e9, 9.3046e9, 6.6121e9);
    vec3 xyz = amp * sqrt(2.0 * PI * var) * cos(mean * phase + shift) * exp(-var * phase * phase);
    // X's second (blue) lobe
    xyz.x += 9.7470e-14 * sqrt(2.0 * PI * 4.5282e9) * cos(2.2399e6 * phase + shift.x)
           * exp(-4.5282e9 * phase * phase);
    xyz /= 1.0685e-7;
    return vec3(3.2404542 * xyz.x - 1.5371385 * xyz.y - 0.4985314 * xyz.z,
                -0.9692660 * xyz.x + 1.8760108 * xyz.y + 0.0415560 * xyz.z,
                0.0556434 * xyz.x - 0.2040259 * xyz.y + 1.0572252 * xyz.z);
}

// The film's reflectance towards cosTheta1 (the cosine to the normal, or V.H of a
// microfacet), linear Rec.709: the Airy sum's mean R12 + T121^2 R23 / (1 - R12 R23) plus
// its first THIN_FILM_ORDERS orders m of amplitude (R_s - T121) r123^m against the
// sensitivities. Two orders (the extension's) leave up to 0.095 at grazing angles over a
// metal, where r123 is large; twelve leave 7e-4 (tests/test_lobe_thin_film.py).
const int THIN_FILM_ORDERS = 12;

vec3 thinFilmFresnel(ThinFilm f, float cosTheta1) {
    // Belcour & Barla 2017, eq. 10-13 (Fourier form of the Airy sum), as evaluated by glTF
    // KHR_materials_iridescence (Schlick interfaces, per-channel phase shifts)
    float c1 = clamp(cosTheta1, 0.0, 1.0);
    // the film fades to the outside medium over its first 0.03 nm (no film at 0)
    float n2 = mix(f.outsideIor, f.ior, smoothstep(0.0, 0.03, f.thickness));
    float ratio = f.outsideIor / n2;
    float cos2Sq = 1.0 - ratio * ratio * (1.0 - c1 * c1);
    if (cos2Sq <= 0.0) return vec3(1.0);  // total internal reflection into the film
    float c2 = sqrt(cos2Sq);
    // outside | film: the amplitude's phase flips going to the denser medium
    float R12 = thinFilmSchlick(thinFilmF0OfIor(vec3(n2), f.outsideIor), c1).x;
    float T121 = 1.0 - R12;
    float phi21 = n2 < f.outsideIor ? 0.0 : PI;
    // film | base, per channel
    vec3 R23 = thinFilmSchlick(thinFilmF0OfIor(f.baseIor, n2), c2);
    vec3 phi23 = mix(vec3(0.0), vec3(PI), lessThan(f.baseIor, vec3(n2)));
    float opd = 2.0 * n2 * f.thickness * c2;
    vec3 phi = vec3(phi21) + phi23;
    vec3 R123 = clamp(R12 * R23, 0.0, 0.9999);
    vec3 r123 = sqrt(R123);
    vec3 Rs = T121 * T121 * R23 / (1.0 - R123);
    vec3 I = R12 + Rs;
    vec3 Cm = Rs - T121;
    for (int m = 1; m <= THIN_FILM_ORDERS; m++) {
        Cm *= r123;
        I += Cm * 2.0 * thinFilmSensitivity(float(m) * opd, float(m) * phi);
    }
    return max(I, vec3(0.0));
}
