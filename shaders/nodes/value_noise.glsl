// Value Noise node: random values on an integer lattice, smoothly interpolated, summed
// over octaves of doubling frequency and halving amplitude, in [0, 1].
//
// The lattice values come from an integer hash, so the numpy twin
// (matedit.compiler.cpu_nodes) reproduces them bit for bit; only the interpolation is
// float arithmetic. Integers are highp: ES fragment shaders default int to mediump.

const int NODE_NOISE_MAX_OCTAVES = 6;

highp uint nodeNoisePcg(highp uint v) {
    // Jarzynski & Olano 2020, "Hash Functions for GPU Rendering": pcg (RXS-M-XS output)
    highp uint state = v * 747796405u + 2891336453u;
    highp uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The lattice value of one cell, in [0, 1): the hash's top 24 bits, exact in a float.
float nodeNoiseLattice(highp ivec2 cell, highp uint seed) {
    // Jarzynski & Olano 2020: nest the 1D hash for more dimensions, pcg(x + pcg(y + seed))
    highp uint h = nodeNoisePcg(uint(cell.x) + nodeNoisePcg(uint(cell.y) + seed));
    return float(h >> 8u) * (1.0 / 16777216.0);
}

// One octave: bilinear blend of the cell's four corner values with a C1 Hermite fade.
float nodeValueNoiseOctave(vec2 p, highp uint seed) {
    // Ebert et al. 2003, "Texturing and Modeling", ch. 2: value noise, Hermite fade
    vec2 i = floor(p);
    vec2 f = p - i;
    highp ivec2 c = ivec2(i);
    float v00 = nodeNoiseLattice(c, seed);
    float v10 = nodeNoiseLattice(c + ivec2(1, 0), seed);
    float v01 = nodeNoiseLattice(c + ivec2(0, 1), seed);
    float v11 = nodeNoiseLattice(c + ivec2(1, 1), seed);
    vec2 u = f * f * (3.0 - 2.0 * f);
    return mix(mix(v00, v10, u.x), mix(v01, v11, u.x), u.y);
}

void node_value_noise(vec2 uv, float scale, float octaves, out float value) {
    // Musgrave, in Ebert et al. 2003, "Texturing and Modeling": fBm, octaves of
    // lacunarity 2 and gain 1/2, here divided by the summed amplitudes to stay in [0, 1]
    // A fractional octave count weights the last octave, so a slider fades detail in.
    float n = clamp(octaves, 1.0, float(NODE_NOISE_MAX_OCTAVES));
    float sum = 0.0;
    float norm = 0.0;
    float amplitude = 1.0;
    float frequency = scale;
    for (int k = 0; k < NODE_NOISE_MAX_OCTAVES; ++k) {
        float w = clamp(n - float(k), 0.0, 1.0) * amplitude;
        if (w <= 0.0) {
            break;
        }
        // Each octave gets its own lattice (seed k), so octaves never line up at the origin.
        sum += w * nodeValueNoiseOctave(uv * frequency, uint(k));
        norm += w;
        amplitude *= 0.5;
        frequency *= 2.0;
    }
    value = sum / norm;
}
