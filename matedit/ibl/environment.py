"""Environments: HDR images (equirect or cube cross) and the built-ins, as linear float RGB.

`load_environment` accepts a file path or a built-in name. LDR files (8/16-bit PNG,
JPEG, ...) are taken as sRGB, linearised, and flagged in `Environment.warnings`; every
unreadable input raises `EnvironmentMapError` (a ValueError) whose message starts with
the file name.
"""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from matedit.ibl.builtin import builtin_environment
from matedit.ibl.cubemap import cross_to_faces
from matedit.io.images import ImageError, read_image
from matedit.io.inputs import (
    BuiltinNameError,
    builtin_name,
    cube_face_files,
    spellings,
)

DEFAULT_ENVIRONMENT = "studio"


class EnvironmentMapError(ValueError):
    """An environment that cannot be used; the message names the file and what is wrong."""


@dataclass
class Environment:
    """Linear RGB radiance, as an equirect image (h, w, 3) or cube faces (6, n, n, 3)."""

    name: str
    equirect: np.ndarray | None = None
    faces: np.ndarray | None = None
    warnings: list[str] = field(default_factory=list)

    def content_hash(self) -> str:
        """SHA-256 of the pixels (not of the file): same radiance, same key."""
        h = hashlib.sha256()
        arr = self.equirect if self.equirect is not None else self.faces
        kind = "equirect" if self.equirect is not None else "cube"
        h.update(f"{kind}:{arr.shape}".encode())
        h.update(np.ascontiguousarray(arr, dtype=np.float32).tobytes())
        return h.hexdigest()


def srgb_to_linear(x: np.ndarray) -> np.ndarray:
    """The sRGB transfer function, inverted (IEC 61966-2-1)."""
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4).astype(np.float32)


def _to_rgb(pixels: np.ndarray) -> np.ndarray:
    c = pixels.shape[2]
    if c >= 3:
        return pixels[..., :3]
    return np.repeat(pixels[..., :1], 3, axis=2)  # grey, or grey + alpha


def builtin(name: str, size: int = 256) -> Environment:
    """A built-in environment drawn at a resolution that suits cube faces of `size`."""
    width = max(256, 4 * int(size))
    return Environment(name=name, equirect=builtin_environment(name, width))


def load_cube_faces(folder: str | os.PathLike) -> Environment:
    """Six square face images in one folder, named by face: px nx py ny pz nz (or posx/negx...,
    or right/left/top/bottom/front/back), optionally after a prefix and "_" or "-", e.g.
    sky_px.hdr. Faces are in the OpenGL cube-map orientation, the same as the faces of a
    cube cross (matedit.ibl.cubemap). LDR faces are read as sRGB, as for other files."""
    name = os.fspath(folder)  # as the user wrote it (`./studio`)
    folder = Path(folder)
    found: dict[str, Path] = {}
    for key, p in cube_face_files(folder):  # the same files `matedit.io.inputs` protects
        if key in found:
            raise EnvironmentMapError(f"{name}: two files for cube face {key}: "
                                      f"{found[key].name} and {p.name}")
        found[key] = p
    from matedit.ibl.cubemap import FACE_NAMES

    missing = [f for f in FACE_NAMES if f not in found]
    if missing:
        raise EnvironmentMapError(
            f"{name}: a folder environment needs six cube-face files (px nx py ny pz nz, "
            f"e.g. sky_px.hdr); missing {' '.join(missing)}")
    faces, warnings = [], []
    for f in FACE_NAMES:
        env = load_environment_file(found[f], square=True)
        warnings += env.warnings
        faces.append(env.equirect)
    sizes = {x.shape for x in faces}
    if len(sizes) != 1:
        raise EnvironmentMapError(f"{name}: cube faces differ in size: "
                                  + ", ".join(f"{f} {x.shape[1]}x{x.shape[0]}"
                                              for f, x in zip(FACE_NAMES, faces)))
    return Environment(name=name, faces=np.ascontiguousarray(np.stack(faces)),
                       warnings=warnings)


def load_environment_file(path: Path, square: bool = False) -> Environment:
    """One image file as linear RGB (`square`: a cube face, returned in `equirect`)."""
    text = str(path)
    try:
        image = read_image(path)
    except ImageError as exc:
        raise EnvironmentMapError(str(exc)) from exc
    warnings: list[str] = []
    rgb = _to_rgb(image.pixels)
    if image.is_ldr:
        rgb = srgb_to_linear(rgb)
        warnings.append(f"{text}: LDR image ({image.format_name}) read as sRGB and linearised")
    bad = ~np.isfinite(rgb) | (rgb < 0)
    if bad.any():
        warnings.append(
            f"{text}: {int(bad.any(axis=-1).sum())} pixels negative or not finite, set to 0")
        rgb = np.where(bad, 0.0, rgb).astype(np.float32)
    if square and rgb.shape[0] != rgb.shape[1]:
        raise EnvironmentMapError(f"{text}: a cube face must be square, not "
                                  f"{rgb.shape[1]}x{rgb.shape[0]}")
    return Environment(name=text, equirect=np.ascontiguousarray(rgb), warnings=warnings)


def load_environment(spec: str | os.PathLike, size: int = 256) -> Environment:
    """Load an environment from a file or folder, or draw a built-in.

    `builtin:studio` and a bare `studio` are the built-in (`sky` likewise), even where a file
    or folder of that name exists; `./studio` is that file or folder
    (`matedit.io.inputs.builtin_name`).
    Layout comes from the aspect ratio: 2:1 is equirectangular, 4:3 or 3:4 a cube cross.
    A folder holds six cube-face files (see `load_cube_faces`). `size` only sets the
    resolution the built-ins are drawn at.
    """
    try:
        name = builtin_name(spec, "environment")
    except BuiltinNameError as exc:
        raise EnvironmentMapError(str(exc)) from None
    if name is not None:
        return builtin(name, size)
    text = os.fspath(spec)
    path = Path(text)
    if os.path.isdir(path):  # isdir and exists are False, not errors, for over-long names
        return load_cube_faces(path)
    if not os.path.exists(path):
        raise EnvironmentMapError(f"{text}: no such file or folder (an environment is "
                                  f"{spellings('environment')})")
    try:
        image = read_image(path)
    except ImageError as exc:
        raise EnvironmentMapError(str(exc)) from exc
    warnings: list[str] = []
    rgb = _to_rgb(image.pixels)
    if image.is_ldr:
        rgb = srgb_to_linear(rgb)
        warnings.append(
            f"{text}: LDR image ({image.format_name}) read as sRGB and linearised; "
            "it has no light brighter than 1, so lighting will look flat (prefer .hdr or .exr)"
        )
    bad = ~np.isfinite(rgb) | (rgb < 0)
    if bad.any():
        warnings.append(
            f"{text}: {int(bad.any(axis=-1).sum())} pixels negative or not finite, set to 0"
        )
        rgb = np.where(bad, 0.0, rgb).astype(np.float32)
    h, w = rgb.shape[:2]
    if abs(w - 2 * h) <= max(1, w // 100):
        return Environment(name=text, equirect=np.ascontiguousarray(rgb), warnings=warnings)
    if (w * 3 == h * 4 and w % 4 == 0) or (w * 4 == h * 3 and w % 3 == 0):
        faces = cross_to_faces(rgb)
        return Environment(name=text, faces=np.ascontiguousarray(faces), warnings=warnings)
    raise EnvironmentMapError(
        f"{text}: a {w}x{h} image is neither equirectangular (2:1) nor a cube cross (4:3 or 3:4)"
    )
