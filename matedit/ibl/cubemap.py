"""Cube map geometry on the CPU: texel directions, texel solid angles, cross layouts.

Faces follow OpenGL's order and orientation: index 0..5 = +X, -X, +Y, -Y, +Z, -Z, and a
face array `faces[f, j, i]` holds texel column i (s = (i + 0.5) / size) of row j
(t = (j + 0.5) / size), exactly as `TextureCube.write` uploads it. The GLSL twin of
`face_directions` is `cubeFaceDirection` in shaders/bake/cubemap.glsl.

The equirectangular convention (one place, used by the loaders, the built-in
environments and the GPU bake): world +Y is up; image row 0 is the zenith; the image's
centre column looks down -Z, and longitude grows towards +X (u = 0.75 is +X).
"""

from __future__ import annotations

import numpy as np

FACE_NAMES = ("px", "nx", "py", "ny", "pz", "nz")

# Placement of each face in a horizontal cross (4 x 3 faces), as (row, column) of the
# face grid, row 0 at the top of the image. With this placement and no flips every
# shared edge of the cross is continuous.
HCROSS_SLOTS = {2: (0, 1), 1: (1, 0), 4: (1, 1), 0: (1, 2), 5: (1, 3), 3: (2, 1)}
# Vertical cross (3 x 4): same, with -Z below -Y, rotated by 180 degrees.
VCROSS_SLOTS = {2: (0, 1), 1: (1, 0), 4: (1, 1), 0: (1, 2), 3: (2, 1), 5: (3, 1)}


def face_direction(face: int, s: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Unnormalised direction of face coordinates s, t in [0, 1] (OpenGL's table of faces)."""
    sc = 2.0 * np.asarray(s, dtype=np.float64) - 1.0
    tc = 2.0 * np.asarray(t, dtype=np.float64) - 1.0
    one = np.ones_like(sc)
    comps = {
        0: (one, -tc, -sc),
        1: (-one, -tc, sc),
        2: (sc, one, tc),
        3: (sc, -one, -tc),
        4: (sc, -tc, one),
        5: (-sc, -tc, -one),
    }[face]
    return np.stack(comps, axis=-1)


def face_directions(size: int) -> np.ndarray:
    """Unit directions of every texel centre, shape (6, size, size, 3), float64."""
    c = (np.arange(size) + 0.5) / size
    s, t = np.meshgrid(c, c)  # s varies along columns, t along rows
    d = np.stack([face_direction(f, s, t) for f in range(6)])
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def texel_solid_angles(size: int) -> np.ndarray:
    """Exact solid angle of each texel of one face, shape (size, size); six faces sum to 4 pi."""
    edges = np.linspace(-1.0, 1.0, size + 1)
    x, y = np.meshgrid(edges, edges)
    # Solid angle of the rectangle [0, x] x [0, y] on the plane z = 1, signed.
    f = np.arctan2(x * y, np.sqrt(x * x + y * y + 1.0))
    return f[1:, 1:] - f[1:, :-1] - f[:-1, 1:] + f[:-1, :-1]


def direction_to_equirect_uv(d: np.ndarray) -> np.ndarray:
    """Equirect coordinates (u, v) in [0, 1] of directions (..., 3); v = 0 at the zenith."""
    d = np.asarray(d, dtype=np.float64)
    d = d / np.linalg.norm(d, axis=-1, keepdims=True)
    u = 0.5 + np.arctan2(d[..., 0], -d[..., 2]) / (2.0 * np.pi)
    v = np.arccos(np.clip(d[..., 1], -1.0, 1.0)) / np.pi
    return np.stack([u, v], axis=-1)


def equirect_directions(height: int, width: int) -> np.ndarray:
    """Unit direction of every pixel centre of a width x height equirect image, (h, w, 3)."""
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    phi = 2.0 * np.pi * (u - 0.5)
    theta = np.pi * v
    st = np.sin(theta)[:, None]
    return np.stack(
        [
            st * np.sin(phi)[None, :],
            np.broadcast_to(np.cos(theta)[:, None], (height, width)),
            -st * np.cos(phi)[None, :],
        ],
        axis=-1,
    )


def sample_equirect(image: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Bilinear lookup of an equirect image (h, w, c) in directions (..., 3); wraps in u."""
    h, w = image.shape[:2]
    uv = direction_to_equirect_uv(d)
    x = uv[..., 0] * w - 0.5
    y = np.clip(uv[..., 1] * h - 0.5, 0.0, h - 1.0)
    x0 = np.floor(x).astype(np.int64)
    y0 = np.floor(y).astype(np.int64)
    fx = (x - x0)[..., None]
    fy = (y - y0)[..., None]
    y1 = np.minimum(y0 + 1, h - 1)
    x0w, x1w = x0 % w, (x0 + 1) % w
    top = image[y0, x0w] * (1 - fx) + image[y0, x1w] * fx
    bot = image[y1, x0w] * (1 - fx) + image[y1, x1w] * fx
    return top * (1 - fy) + bot * fy


def faces_to_cross(faces: np.ndarray, vertical: bool = False) -> np.ndarray:
    """Six faces (6, n, n, c) as one cross image, rows top first; empty slots are 0."""
    n, c = faces.shape[1], faces.shape[3]
    slots = VCROSS_SLOTS if vertical else HCROSS_SLOTS
    rows, cols = (4, 3) if vertical else (3, 4)
    out = np.zeros((rows * n, cols * n, c), dtype=faces.dtype)
    for f, (r, q) in slots.items():
        img = faces[f]
        if vertical and f == 5:
            img = img[::-1, ::-1]
        out[r * n : (r + 1) * n, q * n : (q + 1) * n] = img
    return out


def cross_to_faces(image: np.ndarray) -> np.ndarray:
    """Inverse of `faces_to_cross` for a 4:3 (horizontal) or 3:4 (vertical) cross."""
    h, w = image.shape[:2]
    if w * 3 == h * 4:
        n, slots, vertical = w // 4, HCROSS_SLOTS, False
    elif w * 4 == h * 3:
        n, slots, vertical = w // 3, VCROSS_SLOTS, True
    else:
        raise ValueError(f"a cube cross is 4:3 or 3:4, not {w}x{h}")
    faces = np.empty((6, n, n, image.shape[2]), dtype=image.dtype)
    for f, (r, q) in slots.items():
        img = image[r * n : (r + 1) * n, q * n : (q + 1) * n]
        faces[f] = img[::-1, ::-1] if (vertical and f == 5) else img
    return faces
