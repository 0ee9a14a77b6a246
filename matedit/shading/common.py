"""Twin of ``common.glsl``: constants and small vector helpers (vectors on the last axis)."""

from __future__ import annotations

import numpy as np

PI = np.pi
INV_PI = 1.0 / np.pi


def f64(x) -> np.ndarray:
    """Any scalar or array as a float64 array."""
    return np.asarray(x, dtype=np.float64)


def saturate(x) -> np.ndarray:
    return np.clip(f64(x), 0.0, 1.0)


def sq(x) -> np.ndarray:
    x = f64(x)
    return x * x


def pow5(x) -> np.ndarray:
    x = f64(x)
    x2 = x * x
    return x2 * x2 * x


def dot(a, b) -> np.ndarray:
    """Dot product over the last axis."""
    return np.sum(f64(a) * f64(b), axis=-1)


def length(a) -> np.ndarray:
    return np.sqrt(dot(a, a))


def normalize(a) -> np.ndarray:
    a = f64(a)
    return a / length(a)[..., None]


def cross(a, b) -> np.ndarray:
    return np.cross(f64(a), f64(b))


def reflect(incident, n) -> np.ndarray:
    """GLSL reflect: I - 2 dot(N, I) N."""
    incident = f64(incident)
    n = f64(n)
    return incident - 2.0 * dot(n, incident)[..., None] * n


def mix(x, y, a) -> np.ndarray:
    x, y, a = f64(x), f64(y), f64(a)
    return x * (1.0 - a) + y * a
