"""The built-in environments, drawn by deterministic code (no downloads, no randomness).

* ``studio`` (the default): a dark gradient room, a large warm key soft box, a cool
  fill, a rim strip behind, an overhead panel and a grey floor with a bounce pool.
* ``sky``: an outdoor sky (blue zenith, pale horizon, warm ground) with a sun.

Both are HDR (lights well above 1) equirectangular images in the convention of
`matedit.ibl.cubemap` (+Y up, image centre looking down -Z). Lights are anti-aliased
by their coverage of each pixel, and the sun's energy is normalised to its solid
angle, so the lighting does not change with the resolution it is drawn at.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matedit.ibl.cubemap import equirect_directions

BUILTIN_NAMES = ("studio", "sky")


@dataclass(frozen=True)
class SoftBox:
    """A rectangular emitter: centre direction, rectangle half-extents (tangent units), RGB."""

    direction: tuple[float, float, float]
    half_width: float
    half_height: float
    radiance: tuple[float, float, float]


_STUDIO_BOXES = (
    SoftBox((-0.65, 0.45, 0.55), 0.45, 0.55, (14.0, 12.6, 11.0)),  # key, warm
    SoftBox((0.85, 0.25, 0.45), 0.35, 0.55, (2.6, 3.0, 3.6)),  # fill, cool
    SoftBox((0.35, 0.35, -0.87), 0.08, 0.7, (9.0, 9.0, 9.0)),  # rim strip behind
    SoftBox((0.0, 1.0, 0.05), 0.3, 0.3, (3.0, 3.0, 3.0)),  # overhead panel
)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v)


def _pixel_solid_angles(height: int, width: int) -> np.ndarray:
    theta = np.pi * (np.arange(height) + 0.5) / height
    return (2.0 * np.pi / width) * (np.pi / height) * np.sin(theta)[:, None] * np.ones(width)


def _softbox(dirs: np.ndarray, box: SoftBox, pixel_angle: float) -> np.ndarray:
    """Coverage (0..1) of a soft box, with a gentle fall-off towards its edges."""
    c = _unit(box.direction)
    helper = np.array([0.0, 1.0, 0.0]) if abs(c[1]) < 0.9 else np.array([0.0, 0.0, 1.0])
    right = _unit(np.cross(helper, c))
    up = np.cross(c, right)
    cos_c = dirs @ c
    safe = np.where(cos_c > 1e-3, cos_c, 1.0)
    x = (dirs @ right) / safe
    y = (dirs @ up) / safe
    # Signed distance outside the rectangle, in tangent units ~ radians near the centre.
    edge = np.maximum(np.abs(x) - box.half_width, np.abs(y) - box.half_height)
    cover = np.clip(0.5 - edge / max(pixel_angle, 1e-6), 0.0, 1.0)
    # Diffuser: 15% dimmer at the rim than at the centre.
    rx = x / box.half_width
    ry = y / box.half_height
    falloff = 1.0 - 0.15 * np.clip(rx * rx + ry * ry, 0.0, 1.0)
    return np.where(cos_c > 1e-3, cover * falloff, 0.0)


def studio(width: int = 1024) -> np.ndarray:
    """The studio environment as a (width / 2, width, 3) float32 equirect image."""
    height = width // 2
    d = equirect_directions(height, width)
    y = d[..., 1]
    pixel_angle = 2.0 * np.pi / width
    # Walls and ceiling: a dark gradient, brighter towards the horizon, slightly cool.
    wall = 0.025 + 0.09 * np.clip(1.0 - y, 0.0, 1.0) ** 3
    img = wall[..., None] * np.array([0.9, 0.95, 1.05])
    # Floor: neutral grey with a bounce pool under the subject, blended across the horizon.
    below = np.clip(-y, 0.0, 1.0)
    pool = 0.3 * np.exp(-((1.0 - below) ** 2) / 0.08)
    floor = (0.1 + pool)[..., None] * np.array([1.0, 0.97, 0.93])
    blend = np.clip(-y / (2.0 * pixel_angle) + 0.5, 0.0, 1.0)[..., None]
    img = img * (1.0 - blend) + floor * blend
    for box in _STUDIO_BOXES:
        img += _softbox(d, box, pixel_angle)[..., None] * np.asarray(box.radiance)
    return img.astype(np.float32)


SUN_DIRECTION = (0.45, 0.57, 0.69)  # 35 degrees up, in front and to the right
SUN_RADIUS = 0.02  # radians (a large, soft-looking sun; about 2.3 degrees across)
SUN_IRRADIANCE = (9.0, 8.4, 7.4)  # at normal incidence, linear RGB


def sky(width: int = 1024) -> np.ndarray:
    """The sky environment as a (width / 2, width, 3) float32 equirect image."""
    height = width // 2
    d = equirect_directions(height, width)
    y = d[..., 1]
    pixel_angle = 2.0 * np.pi / width
    up = np.clip(y, 0.0, 1.0)[..., None]
    zenith = np.array([0.25, 0.45, 1.0])
    horizon = np.array([0.95, 1.05, 1.2])
    sky_rgb = horizon + (zenith - horizon) * np.sqrt(up)
    sun = _unit(SUN_DIRECTION)
    cos_s = np.clip(d @ sun, -1.0, 1.0)
    ang = np.arccos(cos_s)
    # Forward scattering glow around the sun, and a brighter band near the horizon.
    sky_rgb = sky_rgb + (0.6 * np.exp(-ang / 0.25))[..., None] * np.array([1.0, 0.9, 0.7])
    ground = np.array([0.16, 0.13, 0.1]) * (0.6 + 0.4 * np.clip(-y, 0.0, 1.0))[..., None]
    blend = np.clip(-y / (2.0 * pixel_angle) + 0.5, 0.0, 1.0)[..., None]
    img = sky_rgb * (1.0 - blend) + ground * blend
    # The sun disc: coverage anti-aliased over a pixel, then scaled so that its solid angle
    # (and so its irradiance) is exact whatever the resolution.
    width_px = max(pixel_angle, 1e-6)
    cover = np.clip((SUN_RADIUS - ang) / width_px + 0.5, 0.0, 1.0)
    covered = float(np.sum(cover * _pixel_solid_angles(height, width)))
    disc = np.pi * SUN_RADIUS**2
    radiance = np.asarray(SUN_IRRADIANCE) / disc
    img += (cover * (disc / covered))[..., None] * radiance
    return img.astype(np.float32)


def builtin_environment(name: str, width: int = 1024) -> np.ndarray:
    """A built-in environment by name ('studio' or 'sky') as an equirect image."""
    if name == "studio":
        return studio(width)
    if name == "sky":
        return sky(width)
    raise ValueError(f"unknown built-in environment {name!r}; expected one of {BUILTIN_NAMES}")
