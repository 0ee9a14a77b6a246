"""Image files through OpenImageIO: float pixels in, float pixels out, clear errors.

`read_image` returns linear-or-not float32 pixels exactly as stored (8- and 16-bit
integer files are scaled to [0, 1]; whether they are sRGB is the caller's business,
`ImageData.is_ldr` says which kind of file it was). Every failure - missing, empty,
truncated, corrupt or unsupported - is an `ImageError` (a ValueError) naming the file.

Only the file formats of `READ_FORMATS` are read: the name must end in one of their
extensions and OpenImageIO must report one of them after opening, so its synthetic readers
(`null`, which invents pixels from the file name) never run. The size is checked from the
header, before any pixel is allocated. OpenImageIO takes names as UTF-8 text: a name with
other bytes (valid on Linux) is reached through an ASCII link in a private temporary folder.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import stat
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

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
# At most 4 channels' worth of those pixels (2 GiB as float32): the limit on what one read
# may allocate, however the pixels and channels are split.
MAX_IMAGE_VALUES = MAX_IMAGE_PIXELS * 4

# File extension -> the OpenImageIO format that must read it (the formats the editor's
# file dialogs offer). Anything else - OpenImageIO's `null` reader, its output-only `term`,
# and formats matedit does not claim to read - is refused before it is opened.
READ_FORMATS = {
    ".png": "png", ".jpg": "jpeg", ".jpeg": "jpeg", ".exr": "openexr", ".hdr": "hdr",
    ".tif": "tiff", ".tiff": "tiff", ".tga": "targa", ".bmp": "bmp",
}
_READERS = frozenset(READ_FORMATS.values())


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
    is_8bit: bool = False  # stored as 8-bit integers (what an sRGB8 texture can upload)

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


def _is_utf8(name: str) -> bool:
    try:
        name.encode("utf-8")
    except UnicodeEncodeError:  # surrogate escapes: bytes of a name that is not UTF-8
        return False
    return True


@contextlib.contextmanager
def oiio_name(path: Path, *, folder: bool = False) -> Iterator[str]:
    """A name OpenImageIO can take for `path`: the path itself when it is UTF-8, otherwise
    an ASCII link to the file (or, with `folder`, to its folder, for a writer that creates
    the file) inside a private temporary folder, removed afterwards."""
    name = os.fspath(path)
    if _is_utf8(name):
        yield name
        return
    leaf = path.name if folder else f"in{path.suffix.lower()}"
    if not _is_utf8(leaf):
        raise ImageError(f"{name}: OpenImageIO cannot take this file name (it is not UTF-8); "
                         "rename the file")
    try:
        tmp = tempfile.mkdtemp(prefix="matedit-oiio-")
    except OSError as exc:
        raise ImageError(f"{name}: cannot make a temporary folder: {exc.strerror or exc}") \
            from None
    try:
        if not _is_utf8(tmp):
            raise ImageError(f"{name}: the file name is not UTF-8 and neither is the "
                             "temporary folder; rename the file")
        target = os.path.abspath(path.parent if folder else path)
        link = os.path.join(tmp, "d" if folder else leaf)
        os.symlink(target, link)
        yield os.path.join(link, leaf) if folder else link
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


@contextlib.contextmanager
def _opened(path: str | os.PathLike) -> Iterator[tuple[Any, str, tuple[int, int, int]]]:
    """(the open ImageInput, the file's name, its (width, height, channels)) once the file
    is known to be a regular, non-empty file of `READ_FORMATS` whose header is safe to
    read pixels from; closed afterwards. Raises ImageError."""
    p = Path(path)
    name = str(p)
    try:
        st = os.stat(check_readable_file(p))
    except FileNotFoundError:
        raise ImageError(f"{name}: no such file") from None
    except IsADirectoryError:
        raise ImageError(f"{name}: is a directory, not an image") from None
    except OSError as exc:
        raise ImageError(f"{name}: {_reason(exc)}") from None
    if not stat.S_ISREG(st.st_mode):  # pragma: no cover - replaced since the check
        raise ImageError(f"{name}: is not a regular file")
    if st.st_size == 0:
        raise ImageError(f"{name}: empty file")
    ext = p.suffix.lower()
    if ext not in READ_FORMATS:
        raise ImageError(f"{name}: not an image file matedit reads (the name must end in "
                         f"{', '.join(sorted(READ_FORMATS))})")
    with oiio_name(p) as oname:
        inp = oiio.ImageInput.open(oname, _STRAIGHT_ALPHA)
        if inp is None:
            raise ImageError(f"{name}: cannot read image: {_oiio_error()}")
        try:
            yield inp, name, _checked_size(inp, name)
        finally:
            inp.close()


def read_image(path: str | os.PathLike) -> ImageData:
    """Read the first subimage of `path` as float32 (H, W, C); raises ImageError."""
    with _opened(path) as (inp, name, _size):
        return _read_opened(inp, name)


def read_thumbnail(path: str | os.PathLike, size: int) -> tuple[ImageData, tuple[int, int]]:
    """The first subimage of `path` shrunk to fit `size` x `size` pixels (each pixel the
    mean of the file's pixels it covers; a smaller image is kept as it is), as float32,
    and the file's own (width, height). The file is read a band of rows at a time, so a
    large image is never held whole as floats. Raises ImageError as `read_image` does."""
    with _opened(path) as (inp, name, (w, h, c)):
        spec = inp.spec()
        scale = min(1.0, size / max(w, h))
        tw, th = max(1, round(w * scale)), max(1, round(h * scale))
        row_of = np.arange(h) * th // h  # the thumbnail row of each file row, and column
        col_starts = np.searchsorted(np.arange(w) * tw // w, np.arange(tw))
        tile = int(spec.tile_height) if spec.tile_width > 0 else 0
        band = max(1, (1 << 22) // (w * c))  # rows of about 16 MB of floats at a time
        if tile:
            band = max(tile, band // tile * tile)
        acc = np.zeros((th, tw, c), np.float64)
        for y0 in range(0, h, band):
            y1 = min(h, y0 + band)
            if tile:
                rows = inp.read_tiles(0, 0, spec.x, spec.x + w, spec.y + y0, spec.y + y1,
                                      spec.z, spec.z + 1, 0, c, "float")
            else:
                rows = inp.read_scanlines(0, 0, spec.y + y0, spec.y + y1, spec.z, 0, c,
                                          "float")
            err = inp.geterror() if inp.has_error else ""
            if rows is None or err:
                raise ImageError(f"{name}: corrupt or truncated image: "
                                 f"{_oiio_error(inp) if not err else err}")
            rows = np.asarray(rows, dtype=np.float32).reshape(y1 - y0, w, c)
            sums = np.add.reduceat(rows, col_starts, axis=1, dtype=np.float64)
            starts = np.flatnonzero(np.diff(row_of[y0:y1], prepend=-1))
            acc[row_of[y0 + starts]] += np.add.reduceat(sums, starts, axis=0)
        count = np.outer(np.bincount(row_of, minlength=th),
                         np.diff(np.append(col_starts, w)))
        pixels = (acc / count[:, :, None]).astype(np.float32)
        return ImageData(pixels=pixels, path=name, format_name=inp.format_name(),
                         is_ldr=spec.format.basetype in _LDR_BASETYPES,
                         channel_names=tuple(spec.channelnames),
                         is_8bit=spec.format.basetype in (oiio.UINT8, oiio.INT8)), (w, h)


# Colour and alpha as the file stores them: OpenImageIO would otherwise premultiply the
# colour of a PNG (or TIFF) with unassociated alpha by its alpha on reading. A texture's
# colour is read as painted (glTF's base colour and alpha are independent channels).
_STRAIGHT_ALPHA = oiio.ImageSpec()
_STRAIGHT_ALPHA.attribute("oiio:UnassociatedAlpha", 1)


def _checked_size(inp, name: str) -> tuple[int, int, int]:
    """(width, height, channels) of an open ImageInput, once its format and size are known
    to be safe to read."""
    fmt = inp.format_name()
    if fmt not in _READERS:
        raise ImageError(f"{name}: OpenImageIO reads it as {fmt!r}, not as an image format "
                         f"matedit reads ({', '.join(sorted(_READERS))})")
    spec = inp.spec()
    w, h, c, d = spec.width, spec.height, spec.nchannels, spec.depth
    if w <= 0 or h <= 0 or c <= 0:
        raise ImageError(f"{name}: image has no pixels ({w}x{h}, {c} channels)")
    if d > 1:
        raise ImageError(f"{name}: is a volume image ({w}x{h}x{d}); expected a 2D image")
    if w * h > MAX_IMAGE_PIXELS or c > 64 or w * h * c > MAX_IMAGE_VALUES:
        raise ImageError(f"{name}: image is too large ({w}x{h}, {c} channels; at most "
                         f"{MAX_IMAGE_PIXELS} pixels and {MAX_IMAGE_VALUES} values)")
    return w, h, c


def _read_opened(inp, name: str) -> ImageData:
    """The pixels of an open ImageInput whose size `_checked_size` has passed."""
    fmt = inp.format_name()
    spec = inp.spec()
    w, h, c = spec.width, spec.height, spec.nchannels
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
    return ImageData(
        pixels=np.ascontiguousarray(pixels),
        path=name,
        format_name=fmt,
        is_ldr=spec.format.basetype in _LDR_BASETYPES,
        channel_names=tuple(spec.channelnames),
        is_8bit=spec.format.basetype in (oiio.UINT8, oiio.INT8),
    )


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


# The bytes every complete file of these formats ends with: PNG's IEND chunk, JPEG's EOI.
_TRAILERS = {".png": b"\x00\x00\x00\x00IEND\xaeB`\x82", ".jpg": b"\xff\xd9",
             ".jpeg": b"\xff\xd9"}


def _written_problem(oname: str, spec) -> str:
    """Why the file just written is incomplete, or "". OpenImageIO's PNG and JPEG writers go
    through stdio and lose a full disk's error in their buffered close, so the file's
    trailer is checked (reading it back through libpng would print libpng's own errors)."""
    trailer = _TRAILERS.get(Path(oname).suffix.lower())
    if trailer is None:  # EXR, TIFF, ...: their writers report a failed write themselves
        return ""
    try:
        with open(oname, "rb") as f:
            f.seek(0, os.SEEK_END)
            size = f.tell()
            f.seek(max(0, size - len(trailer)))
            complete = f.read() == trailer
    except OSError as exc:
        return exc.strerror or str(exc)
    return "" if complete else "the file was written incomplete (is the disk full?)"


def write_oiio(path: Path, spec, pixels: np.ndarray) -> None:
    """Write `pixels` with OpenImageIO, atomically, through `atomic_output`."""
    name = str(path)
    try:
        with atomic_output(path) as tmp, oiio_name(Path(tmp), folder=True) as oname:
            out = oiio.ImageOutput.create(oname)
            if out is None:
                raise ImageError(f"{name}: no image writer for this file type: {_oiio_error()}")
            ok = out.open(oname, spec) and out.write_image(np.ascontiguousarray(pixels))
            err = "" if ok else _oiio_error(out)
            closed = out.close()
            if ok and not closed:
                ok, err = False, _oiio_error(out)
            if ok:
                err = _written_problem(oname, spec)
                ok = not err
            if not ok:
                err = err.replace(str(oname), name).replace(str(tmp), name)
                raise ImageError(f"{name}: cannot write image: {err}")
    except OSError as exc:
        raise ImageError(f"{name}: cannot write image: {exc.strerror or exc}") from exc
