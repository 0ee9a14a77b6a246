"""What the numpy twins of the node kinds share: the surface they read (`SurfaceArrays`, the
numpy counterpart of shaders/nodes/context.glsl), GLSL's built-ins by their definitions,
screen-space derivatives on 2 x 2 pixel quads, and the filtered steps and pulses.

A kind's twin, `NodeDef.numpy(surface, *inputs)`, returns its outputs as a tuple in
declaration order. Floats are arrays of shape (N,), vectors (N, k), textures (H, W, 4)
float arrays and MaterialAttributes dicts {field: array}. Generic (`T`) inputs arrive
splatted to one shape. Each twin follows its GLSL's order of operations, so float32 inputs
give float32 results within a few ulps of the GPU.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported at first use (matedit.nodes.lazy_numpy)
    from matedit.nodes.lazy_numpy import np



Attributes = dict[str, "np.ndarray"]


@dataclass
class SurfaceArrays:
    """The numpy counterpart of `SurfaceContext` (shaders/nodes/context.glsl), one row a point."""

    uv: np.ndarray  # (N, 2) mesh UV set 0
    position: np.ndarray  # (N, 3) world space, metres
    normal: np.ndarray  # (N, 3) world geometric normal
    view: np.ndarray  # (N, 3) unit vector surface -> eye
    time: float = 0.0  # seconds
    # The footprint: the points as an image of (rows, columns), row-major, so that screen
    # derivatives are the GPU's 2 x 2 quad differences (see `derivatives`); None: the
    # points are scattered, derivatives read 0 and filtered patterns have hard edges.
    grid: tuple[int, int] | None = None
    tangent: np.ndarray | None = None  # (N, 4) world tangent and handedness; None: +X, +1
    model: np.ndarray | None = None  # (4, 4) object to world; None: identity
    view_projection: np.ndarray | None = None  # (4, 4) world to clip; None: no camera

    @property
    def count(self) -> int:
        return len(self.uv)


def sphere_surface(size: int) -> tuple[SurfaceArrays, np.ndarray]:
    """A unit sphere seen head-on from +Z, as the mesh preview's UVs lay it out; and the mask
    of pixels that see it (top row first)."""
    t = (np.arange(size) + 0.5) / size * 2 - 1
    x, y = np.meshgrid(t, -t)
    r2 = x * x + y * y
    inside = (r2 < 1.0).ravel()
    z = np.sqrt(np.clip(1 - r2, 0, 1))
    n = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    # the preview UV sphere: u around +Y from +X, v from the south pole up
    u = (np.arctan2(-n[:, 2], n[:, 0]) / (2 * np.pi)) % 1.0
    v = 1.0 - np.arccos(np.clip(n[:, 1], -1, 1)) / np.pi
    view = np.tile([0.0, 0.0, 1.0], (len(n), 1))
    return SurfaceArrays(np.stack([u, v], axis=1), n.copy(), n, view, 0.0,
                         grid=(size, size)), inside  # the footprint: filtered edges, bumps


def _col(x: np.ndarray) -> np.ndarray:
    """A per-point float (N,) as a column (N, 1), to scale vectors (N, k) row by row."""
    return x[..., None]


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """GLSL dot: a product of floats, or the sum of component products of vectors."""
    return a * b if a.ndim == 1 else np.sum(a * b, axis=-1)


def _mix(a, b, t):
    """GLSL mix, by its definition a (1 - t) + b t."""
    return a * (1.0 - t) + b * t


def _clamp(x, lo, hi):
    """GLSL clamp, by its definition min(max(x, lo), hi)."""
    return np.minimum(np.maximum(x, lo), hi)


def _smoothstep(e0, e1, x):
    """GLSL smoothstep: t = clamp((x - e0) / (e1 - e0), 0, 1); t t (3 - 2 t)."""
    t = _clamp((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _safe_normalize(v: np.ndarray, fallback) -> np.ndarray:
    """nodeSafeNormalize (shaders/nodes/normal_math.glsl): v / |v|, fallback where v = 0."""
    len2 = np.sum(v * v, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        unit = v * _col(1.0 / np.sqrt(len2))
    return np.where(_col(len2 > 0.0), unit, np.asarray(fallback, dtype=v.dtype))


_Z = (0.0, 0.0, 1.0)
_X = (1.0, 0.0, 0.0)


def derivatives(ctx, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """dFdx and dFdy of per-point values `p`, as a GPU computes them on 2 x 2 pixel quads
    with fine derivatives (llvmpipe's, measured): dFdx is the difference across the pixel's
    quad along its own row, dFdy along its own column. Needs `ctx.grid`; without one
    (scattered points, or constant folding with no surface) both are zero. A last odd row
    or column pairs with its neighbour before it."""
    grid = getattr(ctx, "grid", None)
    p = np.asarray(p)
    if grid is None or p.ndim == 0 or p.shape[0] == 1:
        z = np.zeros_like(p)
        return z, z
    h, w = grid
    if h * w != p.shape[0]:
        raise ValueError(f"footprint grid {h} x {w} does not hold {p.shape[0]} points")
    a = p.reshape(h, w, *p.shape[1:])
    return (_quad_diff(a, 1).reshape(p.shape), _quad_diff(a, 0).reshape(p.shape))


def _quad_diff(a: np.ndarray, axis: int) -> np.ndarray:
    a = np.moveaxis(a, axis, 0)
    n = a.shape[0]
    out = np.zeros_like(a)
    m = n // 2 * 2
    d = a[1:m:2] - a[0:m:2]
    out[0:m:2] = d
    out[1:m:2] = d
    if n % 2 and n > 1:
        out[n - 1] = a[n - 1] - a[n - 2]
    return np.moveaxis(out, 0, axis)


def fwidth(ctx, p: np.ndarray) -> np.ndarray:
    """GLSL fwidth: |dFdx p| + |dFdy p| (see `derivatives`)."""
    dx, dy = derivatives(ctx, p)
    return np.abs(dx) + np.abs(dy)


def _need(ctx) -> SurfaceArrays:
    """The surface, for kinds that read it; refusing keeps them out of constant folding."""
    if ctx is None:
        raise TypeError("this node reads the surface")
    return ctx


def _bc(cond: np.ndarray, like: np.ndarray) -> np.ndarray:
    """A per-point condition (N,) shaped to select rows of `like` (N,) or (N, k)."""
    return cond if like.ndim == cond.ndim else cond[..., None]


def _where(cond, a, b):
    a, b = np.asarray(a), np.asarray(b)
    like = a if a.ndim >= b.ndim else b
    return np.where(_bc(np.asarray(cond), like), a, b)


def filtered_step(edge, x, w):
    """nodeFilteredStep (shaders/nodes/filter_lib.glsl)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        soft = _clamp((x - edge) / w + 0.5, 0.0, 1.0)
    return np.where(w > 0.0, soft, np.where(x < edge, 0.0, 1.0)).astype(np.asarray(x).dtype)


def _pulse_integral(x, duty):
    i = np.floor(x)
    return i * duty + np.minimum(x - i, duty)


def filtered_pulse(x, duty, w):
    """nodeFilteredPulse: the period-1 pulse train (1 on [0, duty)) box-filtered over w."""
    x = x - np.floor(x)
    hard = np.where(x < duty, 1.0, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        soft = (_pulse_integral(x + 0.5 * w, duty) - _pulse_integral(x - 0.5 * w, duty)) / w
    return np.where(w > 0.0, soft, hard).astype(x.dtype)


def _square_integral(x):
    return 1.0 - np.abs(x - 2.0 * np.floor(0.5 * x) - 1.0)


def filtered_square(x, w):
    """nodeFilteredSquare: +1 where floor(x) is even, -1 where odd, box-filtered over w."""
    x = x - 2.0 * np.floor(0.5 * x)
    hard = np.where(x < 1.0, 1.0, -1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        soft = (_square_integral(x + 0.5 * w) - _square_integral(x - 0.5 * w)) / w
    return np.where(w > 0.0, soft, hard).astype(x.dtype)


def _turns(d):
    a = np.arctan2(d[:, 1], d[:, 0]) * np.asarray(0.15915494, dtype=np.float32).astype(d.dtype)
    t = a - np.floor(a)
    return np.where((d[:, 0] == 0.0) & (d[:, 1] == 0.0), 0.0, t).astype(d.dtype)
