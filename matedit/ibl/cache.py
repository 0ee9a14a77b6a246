"""On-disk cache of bakes: one .npz per (environment content, settings, bake shaders) key.

Location: ``matedit.dirs.cache_dir() / "ibl"``, that is ``$MATEDIT_CACHE_DIR/ibl`` when
that variable is set, else the platform's user cache folder (on Linux
``${XDG_CACHE_HOME:-~/.cache}/matedit/ibl``). Files are written to a temporary name in the
same folder and renamed into place, so a reader never sees half a file; an unreadable
entry counts as a miss and is baked again.
"""

from __future__ import annotations

import hashlib
import io
import json
import zipfile
from functools import cache
from pathlib import Path

import numpy as np

from matedit.dirs import cache_dir
from matedit.io.atomic import atomic_write_bytes
from matedit.resources import shaders_dir

# Bump when the meaning of cached arrays changes without any shader text changing.
CACHE_FORMAT = 1


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


def load(path: Path) -> dict[str, np.ndarray] | None:
    """The arrays of a cache file, or None when missing or unreadable."""
    try:
        with np.load(path, allow_pickle=False) as data:
            return {name: data[name] for name in data.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, KeyError):
        return None


def save(path: Path, arrays: dict[str, np.ndarray]) -> None:
    """Write arrays to `path` atomically (temporary file in the same folder, then rename)."""
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    atomic_write_bytes(path, buf.getvalue())
