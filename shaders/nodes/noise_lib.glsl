// Shared noise helpers (not a node kind): integer hashes, gradient and cellular noise.
//
// Every random number comes from integer hashing of integer cell coordinates, never from
// sin() of a large float, so patterns stay exact far from the origin (UV 1,000 and beyond)
// and the numpy twins in matedit.compiler.cpu_nodes reproduce the hashes bit for bit.
// Integers are highp: ES fragment shaders default int to mediump.

highp uint nodeHashPcg(highp uint v) {
    // Jarzynski & Olano 2020, "Hash Functions for GPU Rendering": pcg (RXS-M-XS output)
    highp uint state = v * 747796405u + 2891336453u;
    highp uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

highp uint nodeHashCell2(highp ivec2 c, highp uint seed) {
    // Jarzynski & Olano 2020: nest the 1D hash for more dimensions, pcg(x + pcg(y + seed))
    return nodeHashPcg(uint(c.x) + nodeHashPcg(uint(c.y) + seed));
}

highp uint nodeHashCell3(highp ivec3 c, highp uint seed) {
    // Jarzynski & Olano 2020: nested pcg, pcg(x + pcg(y + pcg(z + seed)))
    return nodeHashPcg(uint(c.x) + nodeHashPcg(uint(c.y) + nodeHashPcg(uint(c.z) + seed)));
}

float nodeHashUnit(highp uint h) {
    // The hash's top 24 bits as a float in [0, 1): exact in float32
    return float(h >> 8u) * (1.0 / 16777216.0);
}

highp uint nodeSeed(float seed) {
    // A seed input as an integer: floor, negative reads 0
    return uint(int(max(floor(seed), 0.0)));
}

vec2 nodeGradient2(highp uint h) {
    // Perlin 2002, "Improving Noise": gradients from a small fixed set, here the 8 unit
    // directions of the axes and diagonals chosen by the hash's top 3 bits:
    // k = 0..3: (1, 0), (-1, 0), (0, 1), (0, -1); k = 4..7: (d, d), (-d, d), (d, -d), (-d, -d).
    // Selects, not a ladder of returns: llvmpipe runs every branch of a divergent ladder
    // (execution masks), and the selects JIT to less code; bit k & 1 is the sign of the
    // first non-zero component, k & 2 that of the diagonal's y (the values are exactly the
    // table's: +-1 * d is exact).
    highp uint k = h >> 29u;
    float s = (k & 1u) == 0u ? 1.0 : -1.0;
    float d = 0.70710678;
    return k < 2u ? vec2(s, 0.0)
                  : (k < 4u ? vec2(0.0, s) : vec2(s * d, (k & 2u) == 0u ? d : -d));
}

float nodeGradDot3(highp uint h, vec3 d) {
    // Perlin 2002, "Improving Noise": dot with one of the 12 cube-edge gradients (4 repeated
    // to make 16), chosen by the hash's top 4 bits
    highp uint k = h >> 28u;
    float u = k < 8u ? d.x : d.y;
    float v = k < 4u ? d.y : ((k == 12u || k == 14u) ? d.x : d.z);
    return ((k & 1u) == 0u ? u : -u) + ((k & 2u) == 0u ? v : -v);
}

vec2 nodeFade2(vec2 t) {
    // Perlin 2002: quintic fade 6t^5 - 15t^4 + 10t^3, C2 at the cell borders
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}

vec3 nodeFade3(vec3 t) {
    // Perlin 2002: quintic fade 6t^5 - 15t^4 + 10t^3, C2 at the cell borders
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}

float nodeGradientNoise2(vec2 p, highp uint seed) {
    // Perlin 1985/2002 gradient noise: dot products with lattice gradients, blended by the
    // quintic fade; scaled by sqrt(2) so the range is about [-1, 1]
    vec2 i = floor(p);
    vec2 f = p - i;
    highp ivec2 c = ivec2(i);
    float n00 = dot(nodeGradient2(nodeHashCell2(c, seed)), f);
    float n10 = dot(nodeGradient2(nodeHashCell2(c + ivec2(1, 0), seed)), f - vec2(1.0, 0.0));
    float n01 = dot(nodeGradient2(nodeHashCell2(c + ivec2(0, 1), seed)), f - vec2(0.0, 1.0));
    float n11 = dot(nodeGradient2(nodeHashCell2(c + ivec2(1, 1), seed)), f - vec2(1.0, 1.0));
    vec2 u = nodeFade2(f);
    return mix(mix(n00, n10, u.x), mix(n01, n11, u.x), u.y) * 1.41421356;
}

float nodeGradientNoise3(vec3 p, highp uint seed) {
    // Perlin 2002, "Improving Noise": 3D gradient noise, trilinear blend of 8 corner dots
    vec3 i = floor(p);
    vec3 f = p - i;
    highp ivec3 c = ivec3(i);
    vec3 u = nodeFade3(f);
    float n000 = nodeGradDot3(nodeHashCell3(c, seed), f);
    float n100 = nodeGradDot3(nodeHashCell3(c + ivec3(1, 0, 0), seed),
                     f - vec3(1.0, 0.0, 0.0));
    float n010 = nodeGradDot3(nodeHashCell3(c + ivec3(0, 1, 0), seed),
                     f - vec3(0.0, 1.0, 0.0));
    float n110 = nodeGradDot3(nodeHashCell3(c + ivec3(1, 1, 0), seed),
                     f - vec3(1.0, 1.0, 0.0));
    float n001 = nodeGradDot3(nodeHashCell3(c + ivec3(0, 0, 1), seed),
                     f - vec3(0.0, 0.0, 1.0));
    float n101 = nodeGradDot3(nodeHashCell3(c + ivec3(1, 0, 1), seed),
                     f - vec3(1.0, 0.0, 1.0));
    float n011 = nodeGradDot3(nodeHashCell3(c + ivec3(0, 1, 1), seed),
                     f - vec3(0.0, 1.0, 1.0));
    float n111 = nodeGradDot3(nodeHashCell3(c + ivec3(1, 1, 1), seed),
                     f - vec3(1.0, 1.0, 1.0));
    float x00 = mix(n000, n100, u.x);
    float x10 = mix(n010, n110, u.x);
    float x01 = mix(n001, n101, u.x);
    float x11 = mix(n011, n111, u.x);
    return mix(mix(x00, x10, u.y), mix(x01, x11, u.y), u.z);
}

const int NODE_FBM_MAX_OCTAVES = 8;

float nodeFbm2(vec2 p, float octaves, float lacunarity, float gain, highp uint seed) {
    // Musgrave, in Ebert et al. 2003, "Texturing and Modeling": fBm, summed octaves of
    // gradient noise divided by the summed amplitudes; a fractional count fades the last in
    float n = clamp(octaves, 1.0, float(NODE_FBM_MAX_OCTAVES));
    float sum = 0.0;
    float norm = 0.0;
    float amplitude = 1.0;
    vec2 q = p;
    for (int k = 0; k < NODE_FBM_MAX_OCTAVES; ++k) {
        float w = clamp(n - float(k), 0.0, 1.0) * amplitude;
        if (w <= 0.0) {
            break;
        }
        sum += w * nodeGradientNoise2(q, seed + uint(k));
        norm += w;
        amplitude *= gain;
        q *= lacunarity;
    }
    return norm > 0.0 ? sum / norm : 0.0;
}

float nodeFbm3(vec3 p, float octaves, float lacunarity, float gain, highp uint seed) {
    // Musgrave, in Ebert et al. 2003: fBm of 3D gradient noise, normalised by the amplitudes
    float n = clamp(octaves, 1.0, float(NODE_FBM_MAX_OCTAVES));
    float sum = 0.0;
    float norm = 0.0;
    float amplitude = 1.0;
    vec3 q = p;
    for (int k = 0; k < NODE_FBM_MAX_OCTAVES; ++k) {
        float w = clamp(n - float(k), 0.0, 1.0) * amplitude;
        if (w <= 0.0) {
            break;
        }
        sum += w * nodeGradientNoise3(q, seed + uint(k));
        norm += w;
        amplitude *= gain;
        q *= lacunarity;
    }
    return norm > 0.0 ? sum / norm : 0.0;
}

void nodeCellular2(vec2 p, float jitter, highp uint seed, out float f1, out float f2,
                   out float id) {
    // Worley 1996, "A Cellular Texture Basis Function": one jittered feature point per cell,
    // the two smallest distances over the 3 x 3 neighbourhood, computed relative to the
    // cell so accuracy does not depend on the distance from the origin
    vec2 i = floor(p);
    vec2 f = p - i;
    highp ivec2 c = ivec2(i);
    float d1 = 64.0;
    float d2 = 64.0;
    id = 0.0;
    for (int y = -1; y <= 1; ++y) {
        for (int x = -1; x <= 1; ++x) {
            highp uint h = nodeHashCell2(c + ivec2(x, y), seed);
            highp uint h2 = nodeHashPcg(h);
            vec2 o = vec2(nodeHashUnit(h), nodeHashUnit(h2)) - 0.5;
            vec2 d = vec2(float(x), float(y)) + 0.5 + o * jitter - f;
            float dd = dot(d, d);
            if (dd < d1) {
                d2 = d1;
                d1 = dd;
                id = nodeHashUnit(nodeHashPcg(h2));
            } else if (dd < d2) {
                d2 = dd;
            }
        }
    }
    f1 = sqrt(d1);
    f2 = sqrt(d2);
}

void nodeCellular3(vec3 p, float jitter, highp uint seed, out float f1, out float f2,
                   out float id) {
    // Worley 1996: cellular noise in 3D over the 3 x 3 x 3 neighbourhood
    vec3 i = floor(p);
    vec3 f = p - i;
    highp ivec3 c = ivec3(i);
    float d1 = 64.0;
    float d2 = 64.0;
    id = 0.0;
    for (int z = -1; z <= 1; ++z) {
        for (int y = -1; y <= 1; ++y) {
            for (int x = -1; x <= 1; ++x) {
                highp uint h = nodeHashCell3(c + ivec3(x, y, z), seed);
                highp uint h2 = nodeHashPcg(h);
                highp uint h3 = nodeHashPcg(h2);
                vec3 o = vec3(nodeHashUnit(h), nodeHashUnit(h2), nodeHashUnit(h3)) - 0.5;
                vec3 d = vec3(float(x), float(y), float(z)) + 0.5 + o * jitter - f;
                float dd = dot(d, d);
                if (dd < d1) {
                    d2 = d1;
                    d1 = dd;
                    id = nodeHashUnit(nodeHashPcg(h3));
                } else if (dd < d2) {
                    d2 = dd;
                }
            }
        }
    }
    f1 = sqrt(d1);
    f2 = sqrt(d2);
}
