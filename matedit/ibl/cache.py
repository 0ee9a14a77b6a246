"""On-disk cache of bakes: one .npz per (environment content, settings, bake shaders) key.

Location: ``matedit.dirs.cache_dir() / "ibl"``, that is ``$MATEDIT_CACHE_DIR/ibl`` when
that variable is set, else the platform's user cache folder (on Linux
``${XDG_CACHE_HOME:-~/.cache}/matedit/ibl``). Files are written to a temporary name in the
same folder and renamed into place, so a reader never sees half a file.

Entries are untrusted input: anyone who can write the folder can plant one, and a crash or
a full disk can damage one. Each file stores its format version and a SHA-256 of its
arrays; `load` reads it only when it is a regular file (not a link, FIFO or device) of a
plausible size, checks every array's header against the caller's schema (names, shape,
dtype: never an object array, so nothing is unpickled) before reading its data, then the
version, the checksum and that every float is finite. An entry that fails is removed (the
link itself, never what it points to) and the caller bakes again.
"""

from __future__ import annotations

import hashlib
import io
import json
import math
import os
import stat
import zipfile
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

from matedit.dirs import cache_dir
from matedit.io.atomic import atomic_write_bytes, read_bounded
from matedit.resources import shaders_dir

# Bump when the meaning or the layout of cached files changes without any shader text
# changing. 2: each file holds VERSION_NAME and CHECKSUM_NAME.
CACHE_FORMAT = 2
VERSION_NAME = "format_version"
CHECKSUM_NAME = "sha256"
MAX_TEXT = 4096  # characters of a string array (the settings' JSON)
_MEMBER_OVERHEAD = 4096  # zip entry headers and the .npy header of one array, at most


class BadCacheEntry(ValueError):
    """A cache file that is not one matedit wrote for this key; the message says why."""


@dataclass(frozen=True)
class Spec:
    """What one array of an entry must be: its shape and dtype ("<f4", "<f8", "<i8", or
    "U" for a string of at most MAX_TEXT characters)."""

    shape: tuple[int, ...]
    dtype: str

    def check(self, name: str, shape: tuple[int, ...], dtype: np.dtype) -> None:
        if self.dtype == "U":
            ok = dtype.kind == "U" and dtype.itemsize <= 4 * MAX_TEXT
        else:
            ok = dtype == np.dtype(self.dtype)
        if not ok:
            raise BadCacheEntry(f"array {name!r} has dtype {dtype.str}, not {self.dtype}")
        if tuple(shape) != self.shape:
            raise BadCacheEntry(f"array {name!r} has shape {tuple(shape)}, not {self.shape}")

    @property
    def nbytes(self) -> int:
        size = 4 * MAX_TEXT if self.dtype == "U" else np.dtype(self.dtype).itemsize
        return math.prod(self.shape) * size


def cache_root() -> Path:
    """The matedit cache folder (not created)."""
    return cache_dir()


def ibl_cache_dir() -> Path:
    return cache_root() / "ibl"


@cache
def shader_fingerprint() -> str:
    """Hash of every shader a bake runs, so editing one invalidates old entries."""
    root = shaders_dir()
    h = hashlib.sha256()
    for rel in ("common.glsl", "sampling.glsl"):
        h.update((root / rel).read_bytes())
    for p in sorted((root / "bake").rglob("*")):
        if p.is_file():
            h.update(p.relative_to(root).as_posix().encode())
            h.update(p.read_bytes())
    return h.hexdigest()


def make_key(kind: str, **parts) -> str:
    """A stable hex key of JSON-able parts, the cache format and the shader fingerprint."""
    payload = {"kind": kind, "format": CACHE_FORMAT, "shaders": shader_fingerprint(), **parts}
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:40]


def _c_order(a) -> np.ndarray:
    """`a` as a C-ordered array of its own shape (np.ascontiguousarray makes 0-d arrays 1-d)."""
    a = np.asarray(a)
    return a if a.flags.c_contiguous else a.copy(order="C")


def checksum(arrays: dict[str, np.ndarray]) -> str:
    """SHA-256 of the arrays' names, dtypes, shapes and bytes, in name order."""
    h = hashlib.sha256()
    for name in sorted(arrays):
        a = _c_order(arrays[name])
        h.update(json.dumps([name, a.dtype.str, list(a.shape)]).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _full_schema(schema: dict[str, Spec]) -> dict[str, Spec]:
    if VERSION_NAME in schema or CHECKSUM_NAME in schema:
        raise ValueError(f"{VERSION_NAME} and {CHECKSUM_NAME} are the cache's own names")
    return {**schema, VERSION_NAME: Spec((), "<i8"), CHECKSUM_NAME: Spec((), "U")}


def _read_member(zf: zipfile.ZipFile, info: zipfile.ZipInfo, spec: Spec,
                 name: str) -> np.ndarray:
    """One .npy member: its header checked against `spec` before a byte of data is read."""
    if info.compress_type != zipfile.ZIP_STORED:
        raise BadCacheEntry(f"array {name!r} is compressed (matedit stores arrays as they are)")
    if info.file_size > spec.nbytes + _MEMBER_OVERHEAD:
        raise BadCacheEntry(f"array {name!r} is larger than its shape allows")
    with zf.open(info) as f:
        try:
            version = np.lib.format.read_magic(f)
            if version == (1, 0):
                shape, fortran, dtype = np.lib.format.read_array_header_1_0(f)
            elif version == (2, 0):
                shape, fortran, dtype = np.lib.format.read_array_header_2_0(f)
            else:
                raise BadCacheEntry(f"array {name!r} has .npy version {version}")
        except ValueError as exc:  # a bad magic string, header or dtype
            if isinstance(exc, BadCacheEntry):
                raise
            raise BadCacheEntry(f"array {name!r}: {exc}") from None
        if dtype.hasobject:
            raise BadCacheEntry(f"array {name!r} holds Python objects")
        spec.check(name, shape, dtype)
        if fortran and len(shape) > 1:
            raise BadCacheEntry(f"array {name!r} is in Fortran order")
        want = math.prod(shape) * dtype.itemsize
        data = f.read(want + 1)  # reaching the end checks the member's CRC
    if len(data) != want:
        raise BadCacheEntry(f"array {name!r} holds {len(data)} bytes, not {want}")
    return np.frombuffer(data, dtype=dtype).reshape(shape).copy()


def read_entry(path: Path, schema: dict[str, Spec]) -> dict[str, np.ndarray]:
    """The arrays of the cache file `path`, each as `schema` says, or BadCacheEntry
    (FileNotFoundError when there is none). See the module notes for what is checked."""
    full = _full_schema(schema)
    st = os.lstat(path)
    if stat.S_ISLNK(st.st_mode):
        raise BadCacheEntry("it is a symbolic link")
    if not stat.S_ISREG(st.st_mode):
        raise BadCacheEntry("it is not a regular file (a folder, device, FIFO or socket)")
    limit = sum(s.nbytes + _MEMBER_OVERHEAD for s in full.values()) + _MEMBER_OVERHEAD
    if st.st_size > limit:
        raise BadCacheEntry(f"it is {st.st_size} bytes, more than its arrays can take")
    try:
        data = read_bounded(path, limit)  # non-blocking: replaced by a FIFO since, it fails
    except FileNotFoundError:
        raise
    except OSError as exc:
        raise BadCacheEntry(f"it cannot be read: {exc}") from None
    arrays: dict[str, np.ndarray] = {}
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as zf:
            infos = zf.infolist()
            names = [i.filename for i in infos]
            want = sorted(f"{n}.npy" for n in full)
            if sorted(names) != want:
                raise BadCacheEntry(f"it holds {', '.join(sorted(names)) or 'nothing'}, "
                                    f"not {', '.join(want)}")
            for info in infos:
                name = info.filename.removesuffix(".npy")
                arrays[name] = _read_member(zf, info, full[name], name)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, OSError, KeyError) as exc:
        raise BadCacheEntry(f"it is not a valid archive: {exc}") from None
    version = int(arrays.pop(VERSION_NAME))
    if version != CACHE_FORMAT:
        raise BadCacheEntry(f"it is format {version}, not {CACHE_FORMAT}")
    stored = str(arrays.pop(CHECKSUM_NAME))
    if stored != checksum(arrays):
        raise BadCacheEntry("its checksum does not match its arrays")
    for name, a in arrays.items():
        if a.dtype.kind == "f" and not np.isfinite(a).all():
            raise BadCacheEntry(f"array {name!r} holds NaN or infinite values")
    return arrays


def discard(path: Path) -> None:
    """Removes a cache entry that failed its checks: a link is removed itself (what it
    points to is never touched), an empty folder too; anything else is left alone."""
    try:
        st = os.lstat(path)
    except OSError:
        return
    try:
        if stat.S_ISDIR(st.st_mode):
            os.rmdir(path)
        else:
            os.unlink(path)
    except OSError:
        pass  # then the write that follows fails, and the bake says so


def load(path: Path, schema: dict[str, Spec],
         problems: list[str] | None = None) -> dict[str, np.ndarray] | None:
    """The arrays of a cache entry, or None when there is none or it fails its checks (it
    is then discarded, and why is appended to `problems`)."""
    try:
        return read_entry(path, schema)
    except FileNotFoundError:
        return None
    except Exception as exc:  # noqa: BLE001 - BadCacheEntry, or whatever else a file does:
        discard(path)  # the entry can always be baked again
        if problems is not None:
            problems.append(f"{path}: discarded a damaged IBL cache entry ({exc}); baked again")
        return None


def save(path: Path, arrays: dict[str, np.ndarray]) -> None:
    """Write arrays, the format version and their checksum to `path` atomically (temporary
    file in the same folder, then rename)."""
    arrays = {k: _c_order(v) for k, v in arrays.items()}
    _full_schema({k: Spec((), "U") for k in arrays})  # the cache's own names are not taken
    full = {**arrays, VERSION_NAME: np.array(CACHE_FORMAT, dtype="<i8"),
            CHECKSUM_NAME: np.array(checksum(arrays))}
    buf = io.BytesIO()
    np.savez(buf, **full)
    atomic_write_bytes(path, buf.getvalue())
