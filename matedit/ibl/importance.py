"""Importance sampling of an environment: a piecewise-constant luminance distribution over
the equirectangular (u, v) square, as the table the reference mode searches on the GPU.

Pure numpy (no Qt, no moderngl). The layout of the table (`EnvironmentDistribution.table`,
uploaded as one RG32F texture, read with texelFetch by shaders/env_sampling.glsl):

    shape (H, W + 1, 2) float32; row j is the band of polar angle theta in
    [pi j / H, pi (j + 1) / H] (row 0 at the zenith, +Y), column i the longitude band
    u in [i / W, (i + 1) / W] in the convention of matedit.ibl.cubemap;
    [j, i, 0], i < W: conditional CDF of row j at the end of column i (1 at i = W - 1);
    [j, i, 1], i < W: density p(u, v) of pixel (i, j) over the unit square (mean 1);
    [j, W, 0]: marginal CDF over rows at the end of row j (1 at j = H - 1);
    [j, W, 1]: marginal density of row j over v (mean 1).

Each pixel's weight is its luminance times sin(theta) at the row centre, so that
p(u, v) follows radiance times the solid angle of the pixel. A direction drawn with
density p(u, v) has the solid-angle density p(u, v) / (2 pi^2 sin(theta)), the Jacobian
of (u, v) -> (theta = pi v, phi = 2 pi u). An environment that is black everywhere gets
the weights sin(theta) alone: uniform over the sphere.

The table is built from the cube that the renderer reads (mip 0 of the bake), so that it
describes what the shader will see: every cube texel's luminance is averaged, by solid
angle, into the pixel its centre falls in, and pixels no texel centre falls in (near the
poles, where pixels are small) take the nearest texel's luminance.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matedit.ibl.cubemap import direction_to_equirect_uv, face_directions, texel_solid_angles

# Rec. 709 / sRGB primaries: the luminance the distribution follows.
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
MAX_WIDTH = 512  # the table's resolution is at most 512 x 256 (plus the marginal column)


@dataclass(frozen=True)
class EnvironmentDistribution:
    """The sampling table of one environment (see the module doc for its layout)."""

    table: np.ndarray  # (H, W + 1, 2) float32

    @property
    def width(self) -> int:
        return self.table.shape[1] - 1

    @property
    def height(self) -> int:
        return self.table.shape[0]

    @property
    def density(self) -> np.ndarray:
        """p(u, v) of each pixel, (H, W)."""
        return self.table[:, :-1, 1]


def luminance(rgb: np.ndarray) -> np.ndarray:
    return np.asarray(rgb, dtype=np.float64)[..., :3] @ LUMINANCE


def build_distribution(lum: np.ndarray) -> EnvironmentDistribution:
    """The table for a (H, W) luminance image in the equirect layout; negative and
    non-finite values count as 0."""
    lum = np.asarray(lum, dtype=np.float64)
    if lum.ndim != 2 or lum.shape[0] < 1 or lum.shape[1] < 1:
        raise ValueError(f"luminance must be a (H, W) image, not {lum.shape}")
    h, w = lum.shape
    lum = np.where(np.isfinite(lum) & (lum > 0.0), lum, 0.0)
    sin_theta = np.sin(np.pi * (np.arange(h) + 0.5) / h)
    f = lum * sin_theta[:, None]
    total = f.sum()
    if not total > 0.0 or not np.isfinite(total):
        f = np.broadcast_to(sin_theta[:, None], (h, w)).astype(np.float64)
        total = f.sum()
    rows = f.sum(axis=1)
    cond = np.cumsum(f, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        cond = np.where(rows[:, None] > 0.0, cond / rows[:, None],
                        (np.arange(w) + 1.0)[None, :] / w)
    cond[:, -1] = 1.0
    marginal = np.cumsum(rows) / total
    marginal[-1] = 1.0
    table = np.zeros((h, w + 1, 2), dtype=np.float32)
    table[:, :w, 0] = cond
    table[:, :w, 1] = f * (w * h / total)
    table[:, w, 0] = marginal
    table[:, w, 1] = rows * (h / total)
    return EnvironmentDistribution(table)


def table_size(face_size: int, max_width: int = MAX_WIDTH) -> tuple[int, int]:
    """(W, H) of the table for cube faces of `face_size`: 4 pixels a face width across
    the equator, at most `max_width`."""
    w = int(min(max_width, max(8, 4 * int(face_size))))
    return w, max(w // 2, 1)


def _cube_nearest(faces: np.ndarray, d: np.ndarray) -> np.ndarray:
    """The texel of `faces` (6, n, n, c) nearest to unit directions d (..., 3) (OpenGL's
    face selection, matedit.ibl.cubemap's orientation)."""
    n = faces.shape[1]
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    ax, ay, az = np.abs(x), np.abs(y), np.abs(z)
    face = np.where((ax >= ay) & (ax >= az), np.where(x >= 0, 0, 1),
                    np.where(ay >= az, np.where(y >= 0, 2, 3), np.where(z >= 0, 4, 5)))
    m = np.maximum(np.maximum(ax, ay), az)
    m = np.where(m > 0, m, 1.0)
    sc = np.choose(face, [-z, z, x, x, x, -x]) / m
    tc = np.choose(face, [-y, -y, z, -z, -y, -y]) / m
    col = np.clip(((sc + 1.0) * 0.5 * n).astype(np.int64), 0, n - 1)
    row = np.clip(((tc + 1.0) * 0.5 * n).astype(np.int64), 0, n - 1)
    return faces[face, row, col]


def cube_luminance_equirect(faces: np.ndarray, width: int, height: int) -> np.ndarray:
    """Mean luminance of the cube (6, n, n, 3) over each pixel of a width x height equirect,
    by solid angle (see the module doc)."""
    faces = np.asarray(faces)
    n = faces.shape[1]
    lum = luminance(faces).reshape(-1)
    dirs = face_directions(n).reshape(-1, 3)
    omega = np.broadcast_to(texel_solid_angles(n), (6, n, n)).reshape(-1)
    uv = direction_to_equirect_uv(dirs)
    col = np.clip((uv[:, 0] * width).astype(np.int64), 0, width - 1)
    row = np.clip((uv[:, 1] * height).astype(np.int64), 0, height - 1)
    idx = row * width + col
    wsum = np.bincount(idx, weights=omega, minlength=width * height)
    lsum = np.bincount(idx, weights=omega * lum, minlength=width * height)
    out = np.zeros(width * height)
    hit = wsum > 0
    out[hit] = lsum[hit] / wsum[hit]
    if not hit.all():
        j, i = np.divmod(np.flatnonzero(~hit), width)
        u, v = (i + 0.5) / width, (j + 0.5) / height
        phi, theta = 2.0 * np.pi * (u - 0.5), np.pi * v
        d = np.stack([np.sin(theta) * np.sin(phi), np.cos(theta),
                      -np.sin(theta) * np.cos(phi)], axis=-1)
        out[~hit] = luminance(_cube_nearest(faces, d))
    return out.reshape(height, width)


def dilate(lum: np.ndarray) -> np.ndarray:
    """The maximum of each pixel's 3 x 3 neighbourhood (columns wrap around, rows clamp)."""
    out = np.maximum(lum, np.maximum(np.roll(lum, 1, axis=1), np.roll(lum, -1, axis=1)))
    up = np.concatenate([out[:1], out[:-1]])
    down = np.concatenate([out[1:], out[-1:]])
    return np.maximum(out, np.maximum(up, down))


def distribution_from_cube(faces: np.ndarray, max_width: int = MAX_WIDTH
                           ) -> EnvironmentDistribution:
    """The sampling table of cube faces (6, n, n, 3), e.g. mip 0 of an IBL bake.

    The pixel means are dilated (`dilate`): a texel straddles pixels, and the shader reads
    the cube filtered, so a bright texel's light reaches the pixels around the one its
    centre falls in. Without this, directions there would be drawn with the density of
    their dim pixel and carry a bright texel's radiance: rare, huge samples (fireflies)."""
    faces = np.asarray(faces)
    if faces.ndim != 4 or faces.shape[0] != 6 or faces.shape[1] != faces.shape[2]:
        raise ValueError(f"cube faces must be (6, n, n, c), not {faces.shape}")
    w, h = table_size(faces.shape[1], max_width)
    return build_distribution(dilate(cube_luminance_equirect(faces, w, h)))
