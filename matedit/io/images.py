"""Image files through OpenImageIO: float pixels in, float pixels out, clear errors.

`read_image` returns linear-or-not float32 pixels exactly as stored (8- and 16-bit
integer files are scaled to [0, 1]; whether they are sRGB is the caller's business,
`ImageData.is_ldr` says which kind of file it was). Every failure - missing, empty,
truncated, corrupt or unsupported - is an `ImageError` (a ValueError) naming the file.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from matedit.io.atomic import atomic_output, check_readable_file

try:  # OpenImageIO is a hard dependency, but keep the import error readable.
    import OpenImageIO as oiio
except ImportError as exc:  # pragma: no cover - broken install
    raise ImportError(
        "matedit needs the OpenImageIO Python module (pip install OpenImageIO)"
    ) from exc

# Integer storage means a display-referred (LDR) image; float/half means scene-linear HDR.
_LDR_BASETYPES = {
    oiio.UINT8,
    oiio.INT8,
    oiio.UINT16,
    oiio.INT16,
}


MAX_IMAGE_PIXELS = 16384 * 8192


def _reason(exc: OSError) -> str:
    text = str(exc)
    return text.split(": ", 1)[1] if ": " in text and not exc.strerror else (
        exc.strerror or text)


class ImageError(ValueError):
    """An image that cannot be read or written; the message starts with the file name."""


@dataclass
class ImageData:
    """Pixels as float32, shape (height, width, channels), row 0 the top row of the file."""

    pixels: np.ndarray
    path: str
    format_name: str
    is_ldr: bool
    channel_names: tuple[str, ...]

    @property
    def height(self) -> int:
        return int(self.pixels.shape[0])

    @property
    def width(self) -> int:
        return int(self.pixels.shape[1])

    @property
    def channels(self) -> int:
        return int(self.pixels.shape[2])


def _oiio_error(obj=None) -> str:
    msg = ""
    if obj is not None:
        try:
            msg = obj.geterror()
        except Exception:  # pragma: no cover - defensive
            msg = ""
    if not msg:
        msg = oiio.geterror()
    msg = " ".join(str(msg).split())
    return msg or "unknown OpenImageIO error"


def read_image(path: str | os.PathLike) -> ImageData:
    """Read the first subimage of `path` as float32 (H, W, C); raises ImageError."""
    p = Path(path)
    name = str(p)
    try:
        check_readable_file(p)
    except FileNotFoundError:
        raise ImageError(f"{name}: no such file") from None
    except IsADirectoryError:
        raise ImageError(f"{name}: is a directory, not an image") from None
    except OSError as exc:
        raise ImageError(f"{name}: {_reason(exc)}") from None
    if p.stat().st_size == 0:
        raise ImageError(f"{name}: empty file")
    inp = oiio.ImageInput.open(name)
    if inp is None:
        raise ImageError(f"{name}: cannot read image: {_oiio_error()}")
    try:
        spec = inp.spec()
        w, h, c = spec.width, spec.height, spec.nchannels
        if w <= 0 or h <= 0 or c <= 0:
            raise ImageError(f"{name}: image has no pixels ({w}x{h}, {c} channels)")
        if w * h > MAX_IMAGE_PIXELS or c > 64:
            raise ImageError(f"{name}: image is too large ({w}x{h}, {c} channels; at most "
                             f"{MAX_IMAGE_PIXELS} pixels)")
        pixels = inp.read_image(0, 0, 0, c, "float")
        err = inp.geterror() if inp.has_error else ""
        if pixels is None or err:
            raise ImageError(
                f"{name}: corrupt or truncated image: {_oiio_error(inp) if not err else err}"
            )
        pixels = np.asarray(pixels, dtype=np.float32)
        if pixels.ndim == 2:
            pixels = pixels[:, :, None]
        if pixels.shape != (h, w, c):
            raise ImageError(f"{name}: unexpected pixel array shape {pixels.shape}")
        data = ImageData(
            pixels=np.ascontiguousarray(pixels),
            path=name,
            format_name=inp.format_name(),
            is_ldr=spec.format.basetype in _LDR_BASETYPES,
            channel_names=tuple(spec.channelnames),
        )
    finally:
        inp.close()
    return data


def write_image(path: str | os.PathLike, pixels: np.ndarray, *, half: bool = False) -> None:
    """Write float pixels (H, W, C) or (H, W) to `path` (format from the extension), atomically.

    Float formats (EXR) store 32-bit floats, or 16-bit with `half=True`. The file appears
    complete or not at all: it is written beside the target, then renamed over it.
    """
    p = Path(path)
    name = str(p)
    arr = np.asarray(pixels, dtype=np.float32)
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if arr.ndim != 3 or arr.shape[0] == 0 or arr.shape[1] == 0:
        raise ImageError(f"{name}: cannot write an image of shape {arr.shape}")
    h, w, c = arr.shape
    spec = oiio.ImageSpec(w, h, c, "half" if half else "float")
    if c in (3, 4):
        spec.channelnames = ("R", "G", "B", "A")[:c]
    elif c == 2:
        spec.channelnames = ("R", "G")
    write_oiio(p, spec, arr)


def write_oiio(path: Path, spec, pixels: np.ndarray) -> None:
    """Write `pixels` with OpenImageIO, atomically, through `atomic_output`."""
    name = str(path)
    try:
        with atomic_output(path) as tmp:
            out = oiio.ImageOutput.create(str(tmp))
            if out is None:
                raise ImageError(f"{name}: no image writer for this file type: {_oiio_error()}")
            ok = out.open(str(tmp), spec) and out.write_image(np.ascontiguousarray(pixels))
            err = "" if ok else _oiio_error(out)
            out.close()
            if not ok:
                raise ImageError(f"{name}: cannot write image: {err}")
    except OSError as exc:
        raise ImageError(f"{name}: cannot write image: {exc.strerror or exc}") from exc
