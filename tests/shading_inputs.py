"""Random inputs for the shading tests: float32-exact, with grazing and extreme cases."""

from __future__ import annotations

import numpy as np


def f32(x) -> np.ndarray:
    """Round to float32 and back, so numpy sees exactly what the GPU sees."""
    return np.asarray(x, dtype=np.float32).astype(np.float64)


def unit01(rng, n: int) -> np.ndarray:
    """Values in [0, 1]: half uniform, a quarter crowding 0, a quarter crowding 1, exact ends."""
    u = rng.uniform(0.0, 1.0, n)
    q = n // 4
    u[:q] = 10.0 ** rng.uniform(-6, 0, q)
    u[q : 2 * q] = 1.0 - 10.0 ** rng.uniform(-6, 0, q)
    u[:4] = (0.0, 1.0, 0.5, 1e-7)
    return f32(rng.permutation(u))


def roughness(rng, n: int, lo: float = 0.03) -> np.ndarray:
    """Perceptual roughness in [lo, 1], crowding both ends."""
    return f32(lo + (1.0 - lo) * unit01(rng, n))


def unit_vectors(rng, n: int) -> np.ndarray:
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def frame_with_cos(rng, N: np.ndarray, cos: np.ndarray) -> np.ndarray:
    """Unit vectors making angle acos(cos) with N, random azimuth."""
    t = np.cross(N, unit_vectors(rng, len(N)))
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    sin = np.sqrt(np.maximum(0.0, 1.0 - cos**2))
    return cos[:, None] * N + sin[:, None] * t


def normal_and_view(rng, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(N, V), V in N's hemisphere with NoV from 1e-4 (grazing) to 1."""
    N = unit_vectors(rng, n)
    cos = np.clip(unit01(rng, n), 1e-4, 1.0)
    V = frame_with_cos(rng, N, cos)
    return f32(N), f32(V / np.linalg.norm(V, axis=1, keepdims=True))
