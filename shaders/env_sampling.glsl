// Importance sampling of the environment by its luminance, for the reference mode.
//
// The distribution is one RG32F texture of (W + 1) x H texels, built on the CPU by
// matedit/ibl/importance.py (its module doc is the layout's definition): texel (i, j),
// i < W: r = conditional CDF of row j at the end of column i, g = the pixel's density
// p(u, v) over the unit square; texel (W, j): r = marginal CDF over rows at the end of
// row j. Rows are polar bands from the zenith (+Y) down; columns longitude bands in the
// equirect convention of matedit/ibl/cubemap.py (u = 0.5 looks down -Z, u = 0.75 is +X).
// Inversion is by binary search (texelFetch, no filtering), uniform within the pixel.
// Solid-angle density: p(u, v) / (2 pi^2 sin(theta)) (Pharr, Jakob and Humphreys,
// "Physically Based Rendering", infinite area lights).
#include "common.glsl"

// Unit direction of equirect coordinates (u, v), v = 0 at the zenith.
vec3 equirectDirection(vec2 uv) {
    // matedit/ibl/cubemap.py: phi = 2 pi (u - 0.5), theta = pi v, +Y up, u = 0.5 at -Z
    float phi = 2.0 * PI * (uv.x - 0.5);
    float theta = PI * uv.y;
    float st = sin(theta);
    return vec3(st * sin(phi), cos(theta), -st * cos(phi));
}

// Equirect coordinates of a unit direction (inverse of equirectDirection).
vec2 directionToEquirect(vec3 d) {
    // matedit.ibl.cubemap.direction_to_equirect_uv; theta by atan, not acos (acos loses
    // ~1e-4 near the poles in float32 drivers)
    float u = 0.5 + atan(d.x, -d.z) * (0.5 * INV_PI);
    float v = atan(length(d.xz), d.y) * INV_PI;
    return vec2(u, v);
}

// First index k in [0, n) along row `row` whose CDF value (the r channel) exceeds x;
// CDFs end at 1 and x < 1, so one always does.
int searchCdfRow(sampler2D dist, int row, int n, float x) {
    // binary search for the smallest k with cdf[k] > x
    int lo = 0;
    int hi = n - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (texelFetch(dist, ivec2(mid, row), 0).r > x) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

// The same down column `col` (the marginal CDF is column W).
int searchCdfColumn(sampler2D dist, int col, int n, float x) {
    // binary search for the smallest k with cdf[k] > x, down the column
    int lo = 0;
    int hi = n - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (texelFetch(dist, ivec2(col, mid), 0).r > x) hi = mid;
        else lo = mid + 1;
    }
    return lo;
}

// A direction drawn from the environment's distribution for the uniform point u in
// [0, 1)^2; `pdf` receives its solid-angle density (0 at the poles, a set of measure 0).
vec3 sampleEnvironmentDirection(sampler2D dist, vec2 u, out float pdf) {
    // Pharr, Jakob and Humphreys, PBRT, 2-D piecewise-constant distribution: the row by the
    // marginal CDF, then the column by that row's conditional CDF, each inverted linearly
    ivec2 size = textureSize(dist, 0);
    int w = size.x - 1;
    int h = size.y;
    int j = searchCdfColumn(dist, w, h, u.y);
    float r0 = j > 0 ? texelFetch(dist, ivec2(w, j - 1), 0).r : 0.0;
    float r1 = texelFetch(dist, ivec2(w, j), 0).r;
    float dv = r1 > r0 ? clamp((u.y - r0) / (r1 - r0), 0.0, 1.0) : 0.5;
    int i = searchCdfRow(dist, j, w, u.x);
    float c0 = i > 0 ? texelFetch(dist, ivec2(i - 1, j), 0).r : 0.0;
    vec2 c1 = texelFetch(dist, ivec2(i, j), 0).rg;
    float du = c1.r > c0 ? clamp((u.x - c0) / (c1.r - c0), 0.0, 1.0) : 0.5;
    vec2 uv = vec2((float(i) + du) / float(w), (float(j) + dv) / float(h));
    float sinTheta = sin(PI * uv.y);
    pdf = sinTheta > 1e-7 ? c1.g / (2.0 * PI * PI * sinTheta) : 0.0;
    return equirectDirection(uv);
}

// Solid-angle density with which sampleEnvironmentDirection draws the unit direction L.
float environmentPdf(sampler2D dist, vec3 L) {
    // p(u, v) of L's pixel over the Jacobian 2 pi^2 sin(theta)
    float sinTheta = length(L.xz);
    if (sinTheta <= 1e-7) return 0.0;
    ivec2 size = textureSize(dist, 0);
    int w = size.x - 1;
    int h = size.y;
    vec2 uv = directionToEquirect(L);
    int i = clamp(int(uv.x * float(w)), 0, w - 1);
    int j = clamp(int(uv.y * float(h)), 0, h - 1);
    return texelFetch(dist, ivec2(i, j), 0).g / (2.0 * PI * PI * sinTheta);
}
