"""Noise kinds: value, gradient (Perlin-style), cellular (Worley), fractal and hash noise.

Integer hashes are uint32 arithmetic and match the GPU bit for bit.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from matedit.nodes.kind import (
    _FILTER,
    _SEED,
    _UV,
    BAKE,
    MESH_UV,
    UNIT,
    NodeDef,
    Thumbnail,
    _fn,
    _i,
    _o,
    register,
)
from matedit.nodes.twin import _clamp, _col, _mix, filtered_step, fwidth

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported at first use (matedit.nodes.lazy_numpy)
    from matedit.nodes.lazy_numpy import np


NOISE_MAX_OCTAVES = 6


def pcg_hash(v: np.ndarray) -> np.ndarray:
    """nodeNoisePcg: Jarzynski & Olano 2020, "Hash Functions for GPU Rendering", pcg; uint32
    arithmetic wrapping like the GPU's."""
    state = v.astype(np.uint32) * np.uint32(747796405) + np.uint32(2891336453)
    word = ((state >> ((state >> np.uint32(28)) + np.uint32(4))) ^ state) * np.uint32(277803737)
    return (word >> np.uint32(22)) ^ word


def noise_lattice(cx: np.ndarray, cy: np.ndarray, seed) -> np.ndarray:
    """nodeNoiseLattice: pcg(x + pcg(y + seed)) of uint32 cell coordinates, its top 24 bits
    as a float in [0, 1) (exact in float32)."""
    h = pcg_hash(cx + pcg_hash(cy + np.asarray(seed, dtype=np.uint32)))
    return (h >> np.uint32(8)).astype(np.float32) * np.float32(1.0 / 16777216.0)


def _noise_octave(p: np.ndarray, seed: int) -> np.ndarray:
    i = np.floor(p)
    f = p - i
    # int(floor(p)) then uint(): two's complement, as GLSL converts int to uint.
    c = i.astype(np.int64).astype(np.uint32)
    cx, cy = c[:, 0], c[:, 1]
    one = np.uint32(1)
    v00 = noise_lattice(cx, cy, seed)
    v10 = noise_lattice(cx + one, cy, seed)
    v01 = noise_lattice(cx, cy + one, seed)
    v11 = noise_lattice(cx + one, cy + one, seed)
    u = f * f * (3.0 - 2.0 * f)
    return _mix(_mix(v00, v10, u[:, 0]), _mix(v01, v11, u[:, 0]), u[:, 1])




def _as_uint(cells: np.ndarray) -> np.ndarray:
    """GLSL uint(ivec(floor(x))): two's complement of the integer cell."""
    return cells.astype(np.int64).astype(np.uint32)


def hash_cell2(cx, cy, seed) -> np.ndarray:
    """nodeHashCell2: pcg(x + pcg(y + seed)) of uint32 cell coordinates."""
    return pcg_hash(cx + pcg_hash(cy + np.asarray(seed, dtype=np.uint32)))


def hash_cell3(cx, cy, cz, seed) -> np.ndarray:
    """nodeHashCell3: pcg(x + pcg(y + pcg(z + seed)))."""
    return pcg_hash(cx + pcg_hash(cy + pcg_hash(cz + np.asarray(seed, dtype=np.uint32))))


def hash_unit(h: np.ndarray, dtype="float32") -> np.ndarray:
    """nodeHashUnit: the top 24 bits in [0, 1), exact in float32."""
    return ((h >> np.uint32(8)).astype(np.float32) * np.float32(1.0 / 16777216.0)).astype(dtype)


def node_seed(seed) -> np.ndarray:
    """nodeSeed: floor, negative reads 0, as uint32."""
    return np.maximum(np.floor(seed), 0.0).astype(np.int64).astype(np.uint32)


def _gradient2(h: np.ndarray, dtype) -> np.ndarray:
    d = np.float32(0.70710678)
    g = np.array([[1, 0], [-1, 0], [0, 1], [0, -1], [d, d], [-d, d], [d, -d], [-d, -d]],
                 dtype=np.float32)
    return g[h >> np.uint32(29)].astype(dtype)


def _fade(t):
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


def gradient_noise2(p: np.ndarray, seed) -> np.ndarray:
    """nodeGradientNoise2 (shaders/nodes/noise_lib.glsl) at points p (N, 2)."""
    i = np.floor(p)
    f = p - i
    c = _as_uint(i)
    cx, cy = c[:, 0], c[:, 1]
    one = np.uint32(1)
    dt = p.dtype

    def corner(ox, oy, hx, hy):
        g = _gradient2(hash_cell2(cx + hx, cy + hy, seed), dt)
        return g[:, 0] * (f[:, 0] - ox) + g[:, 1] * (f[:, 1] - oy)

    n00 = corner(0.0, 0.0, np.uint32(0), np.uint32(0))
    n10 = corner(1.0, 0.0, one, np.uint32(0))
    n01 = corner(0.0, 1.0, np.uint32(0), one)
    n11 = corner(1.0, 1.0, one, one)
    u = _fade(f)
    return _mix(_mix(n00, n10, u[:, 0]), _mix(n01, n11, u[:, 0]), u[:, 1]) * np.asarray(
        1.41421356, dtype=np.float32).astype(dt)


def _grad_dot3(h, d):
    k = h >> np.uint32(28)
    u = np.where(k < 8, d[:, 0], d[:, 1])
    v = np.where(k < 4, d[:, 1], np.where((k == 12) | (k == 14), d[:, 0], d[:, 2]))
    return np.where((k & 1) == 0, u, -u) + np.where((k & 2) == 0, v, -v)


def gradient_noise3(p: np.ndarray, seed) -> np.ndarray:
    """nodeGradientNoise3 at points p (N, 3)."""
    i = np.floor(p)
    f = p - i
    c = _as_uint(i)
    u = _fade(f)
    vals = {}
    for ox in (0, 1):
        for oy in (0, 1):
            for oz in (0, 1):
                h = hash_cell3(c[:, 0] + np.uint32(ox), c[:, 1] + np.uint32(oy),
                               c[:, 2] + np.uint32(oz), seed)
                off = np.asarray([ox, oy, oz], dtype=p.dtype)
                vals[ox, oy, oz] = _grad_dot3(h, f - off)
    x00 = _mix(vals[0, 0, 0], vals[1, 0, 0], u[:, 0])
    x10 = _mix(vals[0, 1, 0], vals[1, 1, 0], u[:, 0])
    x01 = _mix(vals[0, 0, 1], vals[1, 0, 1], u[:, 0])
    x11 = _mix(vals[0, 1, 1], vals[1, 1, 1], u[:, 0])
    return _mix(_mix(x00, x10, u[:, 1]), _mix(x01, x11, u[:, 1]), u[:, 2])


FBM_MAX_OCTAVES = 8


def _octaves(noise, p, octaves, lacunarity, gain, seed, shape=None):
    """The fBm loop of nodeFbm2/3: per-point weights, seed + k per octave; `shape` maps
    each octave's noise (ridged)."""
    n = _clamp(octaves, 1.0, float(FBM_MAX_OCTAVES))
    total = np.zeros(len(p), dtype=p.dtype)
    norm = np.zeros(len(p), dtype=p.dtype)
    amplitude = np.ones(len(p), dtype=p.dtype)
    q = p
    for k in range(FBM_MAX_OCTAVES):
        w = _clamp(n - k, 0.0, 1.0) * amplitude
        if not np.any(w > 0.0):
            break
        v = noise(q, seed + np.uint32(k))
        total = total + w * (shape(v) if shape else v)
        norm = norm + w
        amplitude = amplitude * gain
        q = q * _col(lacunarity)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(norm > 0.0, total / norm, 0.0).astype(p.dtype)


def fbm2(p, octaves, lacunarity, gain, seed):
    return _octaves(gradient_noise2, p, octaves, lacunarity, gain, seed)


def cellular2(p: np.ndarray, jitter, seed):
    """nodeCellular2: (F1, F2, cell id) over the 3 x 3 neighbourhood, in the GLSL's order."""
    i = np.floor(p)
    f = p - i
    c = _as_uint(i)
    dt = p.dtype
    d1 = np.full(len(p), 64.0, dtype=dt)
    d2 = np.full(len(p), 64.0, dtype=dt)
    cid = np.zeros(len(p), dtype=dt)
    for y in (-1, 0, 1):
        for x in (-1, 0, 1):
            h = hash_cell2(c[:, 0] + np.uint32(x % 2**32), c[:, 1] + np.uint32(y % 2**32), seed)
            h2 = pcg_hash(h)
            o = np.stack([hash_unit(h, dt), hash_unit(h2, dt)], -1) - 0.5
            d = np.asarray([x, y], dtype=dt) + 0.5 + o * _col(jitter) - f
            dd = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1]
            nearer = dd < d1
            second = ~nearer & (dd < d2)
            d2 = np.where(nearer, d1, np.where(second, dd, d2))
            cid = np.where(nearer, hash_unit(pcg_hash(h2), dt), cid)
            d1 = np.where(nearer, dd, d1)
    return np.sqrt(d1), np.sqrt(d2), cid


def cellular3(p: np.ndarray, jitter, seed):
    """nodeCellular3: (F1, F2, cell id) over the 3 x 3 x 3 neighbourhood."""
    i = np.floor(p)
    f = p - i
    c = _as_uint(i)
    dt = p.dtype
    d1 = np.full(len(p), 64.0, dtype=dt)
    d2 = np.full(len(p), 64.0, dtype=dt)
    cid = np.zeros(len(p), dtype=dt)
    for z in (-1, 0, 1):
        for y in (-1, 0, 1):
            for x in (-1, 0, 1):
                h = hash_cell3(c[:, 0] + np.uint32(x % 2**32), c[:, 1] + np.uint32(y % 2**32),
                               c[:, 2] + np.uint32(z % 2**32), seed)
                h2 = pcg_hash(h)
                h3 = pcg_hash(h2)
                o = np.stack([hash_unit(h, dt), hash_unit(h2, dt), hash_unit(h3, dt)], -1) - 0.5
                d = np.asarray([x, y, z], dtype=dt) + 0.5 + o * _col(jitter) - f
                dd = d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2]
                nearer = dd < d1
                second = ~nearer & (dd < d2)
                d2 = np.where(nearer, d1, np.where(second, dd, d2))
                cid = np.where(nearer, hash_unit(pcg_hash(h3), dt), cid)
                d1 = np.where(nearer, dd, d1)
    return np.sqrt(d1), np.sqrt(d2), cid


def _three_units(h, dt):
    h2 = pcg_hash(h)
    h3 = pcg_hash(h2)
    return hash_unit(h, dt), np.stack([hash_unit(h, dt), hash_unit(h2, dt), hash_unit(h3, dt)],
                                      -1)


def _value_noise(ctx, uv, scale, octaves):
    n = _clamp(octaves, 1.0, float(NOISE_MAX_OCTAVES))
    total = np.zeros(len(uv), dtype=uv.dtype)
    norm = np.zeros(len(uv), dtype=uv.dtype)
    amplitude = 1.0
    frequency = scale
    for k in range(NOISE_MAX_OCTAVES):
        # Per point, as the GPU's loop: octaves of weight 0 add nothing (the GPU breaks).
        w = _clamp(n - k, 0.0, 1.0) * amplitude
        if not np.any(w > 0.0):
            break
        total = total + w * _noise_octave(uv * _col(frequency), k)
        norm = norm + w
        amplitude *= 0.5
        frequency = frequency * 2.0
    return (total / norm,)


register(NodeDef(
    "value_noise", "Value Noise", "Procedural",
    "Smooth value noise in [0, 1] over uv, summed over octaves.",
    inputs=(_i("uv", "vec2", MESH_UV), _i("scale", "float", 8.0, "cells per UV unit", (0.0, 64.0)),
            _i("octaves", "float", 3.0, "detail levels (1-6)", (1.0, 6.0),
               limits=(1.0, float(NOISE_MAX_OCTAVES)))),
    outputs=(_o("value", "float"),),
    glsl="node_value_noise", thumbnail=Thumbnail.ALWAYS,
    mtlx=BAKE,
    numpy=_value_noise,  # our PCG-hash lattice noise: the stdlib has no integer hash
))

# --- noise -----------------------------------------------------------------------------------
_SCALE = ("scale", "float", 8.0, "features per UV unit", (0.0, 64.0))


def _gradient_noise(ctx, uv, scale, seed):
    return (gradient_noise2(uv * _col(scale), node_seed(seed)),)


_fn("gradient_noise", "Gradient Noise", "Noise",
    "Perlin-style gradient noise over uv, in about [−1, 1], smooth (quintic fade).",
    [_i(*_UV), _i(*_SCALE), _i(*_SEED)], [_o("value", "float")], thumbnail=Thumbnail.ALWAYS,
    numpy=_gradient_noise)


def _gradient_noise_3d(ctx, position, scale, seed):
    return (gradient_noise3(position * _col(scale), node_seed(seed)),)


_fn("gradient_noise_3d", "Gradient Noise 3D", "Noise",
    "Perlin-style gradient noise over a 3D position (e.g. world position), about [−1, 1].",
    [_i("position", "vec3", [0.0, 0.0, 0.0]), _i("scale", "float", 2.0, "features per unit",
                                                 (0.0, 64.0)), _i(*_SEED)],
    [_o("value", "float")], thumbnail=Thumbnail.ALWAYS,
    numpy=_gradient_noise_3d)


def _cellular_noise(ctx, uv, scale, jitter, edge_width, seed, filter_width):
    f1, f2, cid = cellular2(uv * _col(scale), jitter, node_seed(seed))
    edge = f2 - f1
    edges = 1.0 - filtered_step(edge_width, edge, fwidth(ctx, edge) * filter_width)
    return f1, f2, edge, cid, edges


_fn("cellular_noise", "Cellular Noise", "Noise",
    "Worley noise over uv: distances to the nearest (F1) and second nearest (F2) feature "
    "points, F2 − F1 (cell borders), a random value per cell, and a filtered edge mask.",
    [_i(*_UV), _i(*_SCALE), _i("jitter", "float", 1.0, "feature point randomness", UNIT),
     _i("edge_width", "float", 0.05, "border width, in cells, of the edge mask", (0.0, 0.5)),
     _i(*_SEED), _i(*_FILTER)],
    [_o("f1", "float"), _o("f2", "float"), _o("edge", "float"), _o("cell_id", "float"),
     _o("edges", "float")], thumbnail=Thumbnail.ALWAYS,
     numpy=_cellular_noise)


def _cellular_noise_3d(ctx, position, scale, jitter, seed):
    f1, f2, cid = cellular3(position * _col(scale), jitter, node_seed(seed))
    return f1, f2, f2 - f1, cid


_fn("cellular_noise_3d", "Cellular Noise 3D", "Noise",
    "Worley noise over a 3D position: F1, F2, F2 − F1 and a random value per cell.",
    [_i("position", "vec3", [0.0, 0.0, 0.0]), _i("scale", "float", 2.0, "cells per unit",
                                                 (0.0, 64.0)),
     _i("jitter", "float", 1.0, "", UNIT), _i(*_SEED)],
    [_o("f1", "float"), _o("f2", "float"), _o("edge", "float"), _o("cell_id", "float")],
    thumbnail=Thumbnail.ALWAYS,
    numpy=_cellular_noise_3d)
_OCT = [_i("octaves", "float", 4.0, "detail levels (fractional fades the last in)", (1.0, 8.0),
           limits=(1.0, float(FBM_MAX_OCTAVES))),
        _i("lacunarity", "float", 2.0, "frequency ratio between octaves", (1.0, 4.0)),
        _i("gain", "float", 0.5, "amplitude ratio between octaves", (0.0, 1.0))]


def _fbm(ctx, uv, scale, octaves, lacunarity, gain, seed):
    return (0.5 + 0.5 * fbm2(uv * _col(scale), octaves, lacunarity, gain, node_seed(seed)),)


_fn("fbm", "Fractal Noise", "Noise",
    "Fractal Brownian motion: octaves of gradient noise, in about [0, 1] around 0.5.",
    [_i(*_UV), _i("scale", "float", 4.0, "base features per UV unit", (0.0, 64.0)), *_OCT,
     _i(*_SEED)], [_o("value", "float")], thumbnail=Thumbnail.ALWAYS,
     numpy=_fbm)


def _fbm_3d(ctx, position, scale, octaves, lacunarity, gain, seed):
    v = _octaves(gradient_noise3, position * _col(scale), octaves, lacunarity, gain,
                 node_seed(seed))
    return (0.5 + 0.5 * v,)


_fn("fbm_3d", "Fractal Noise 3D", "Noise",
    "Fractal Brownian motion over a 3D position, in about [0, 1] around 0.5.",
    [_i("position", "vec3", [0.0, 0.0, 0.0]), _i("scale", "float", 2.0, "", (0.0, 64.0)),
     *_OCT, _i(*_SEED)], [_o("value", "float")], thumbnail=Thumbnail.ALWAYS,
     numpy=_fbm_3d)


def _ridged_noise(ctx, uv, scale, octaves, lacunarity, gain, seed):
    def ridge(v):
        r = 1.0 - np.abs(v)
        return r * r

    return (_octaves(gradient_noise2, uv * _col(scale), octaves, lacunarity, gain,
                     node_seed(seed), ridge),)


_fn("ridged_noise", "Ridged Noise", "Noise",
    "Ridged multifractal: octaves of (1 − |noise|)², sharp crests like cracks and veins, "
    "in [0, 1].",
    [_i(*_UV), _i("scale", "float", 4.0, "", (0.0, 64.0)), *_OCT, _i(*_SEED)],
    [_o("value", "float")], thumbnail=Thumbnail.ALWAYS,
    numpy=_ridged_noise)


def _white_noise(ctx, value, seed):
    # The float32 bit pattern, as floatBitsToUint sees it on the GPU.
    b = np.ascontiguousarray(value, dtype=np.float32).view(np.uint32)
    h = pcg_hash(b[:, 0] + pcg_hash(b[:, 1] + pcg_hash(b[:, 2] + node_seed(seed))))
    return _three_units(h, value.dtype)


_fn("white_noise", "White Noise", "Noise",
    "A random value (and colour) for every distinct input, from its bits: per-pixel grain, "
    "or per cell when fed a cell id.",
    [_i("value", "vec3", [0.0, 0.0, 0.0]), _i(*_SEED)],
    [_o("value", "float"), _o("color", "vec3")],
    numpy=_white_noise)


def _cell_hash(ctx, cell, seed):
    c = _as_uint(np.floor(cell))
    return _three_units(hash_cell2(c[:, 0], c[:, 1], node_seed(seed)), cell.dtype)


_fn("cell_hash", "Random per Cell", "Noise",
    "A random value and colour per integer cell of the input (floor of each component).",
    [_i("cell", "vec2", [0.0, 0.0]), _i(*_SEED)], [_o("value", "float"), _o("color", "vec3")],
    numpy=_cell_hash)


def _domain_warp(ctx, uv, scale, strength, octaves, seed):
    s = node_seed(seed) * np.uint32(2)
    p = uv * _col(scale)
    two = np.full(len(uv), 2.0, dtype=uv.dtype)
    half = np.full(len(uv), 0.5, dtype=uv.dtype)
    d = np.stack([fbm2(p, octaves, two, half, s),
                  fbm2(p, octaves, two, half, s + np.uint32(101))], -1)
    return (uv + _col(strength) * d,)


_fn("domain_warp", "Domain Warp", "Noise",
    "Displaces uv by fractal noise, so any pattern fed the result swirls and breaks up.",
    [_i(*_UV), _i("scale", "float", 4.0, "", (0.0, 64.0)),
     _i("strength", "float", 0.1, "displacement in UV units", (0.0, 1.0)),
     _i("octaves", "float", 3.0, "", (1.0, 8.0), limits=(1.0, float(FBM_MAX_OCTAVES))),
     _i(*_SEED)], [_o("uv", "vec2")],
    thumbnail=Thumbnail.ALWAYS,
    numpy=_domain_warp)
