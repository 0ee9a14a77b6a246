"""Reads of untrusted files: only regular files, with the size limit checked while reading
(so /dev/zero cannot exhaust memory), and opened non-blocking (so a FIFO cannot hang the
reader). The reading half of `matedit.io.atomic` (which names these too), in a module of its
own so that a reader of documents does not import the writers."""

from __future__ import annotations

import os
import stat
from pathlib import Path

_CLOEXEC = getattr(os, "O_CLOEXEC", 0)
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)


class UnsafeFileError(OSError):
    """A path that is not a regular file, or a file larger than allowed."""


def check_readable_file(path: str | os.PathLike) -> Path:
    """Raise UnsafeFileError unless `path` names a regular file (links followed)."""
    p = Path(path)
    try:
        st = os.stat(p)
    except FileNotFoundError:
        raise
    if stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(f"{p}: is a folder, not a file")
    if not stat.S_ISREG(st.st_mode):
        raise UnsafeFileError(f"{p}: is not a regular file (a device, FIFO or socket)")
    return p


def read_bounded(path: str | os.PathLike, limit: int) -> bytes:
    """The bytes of a regular file of at most `limit` bytes, counted while reading."""
    p = Path(path)
    fd = os.open(p, os.O_RDONLY | _NONBLOCK | _CLOEXEC)
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise IsADirectoryError(f"{p}: is a folder, not a file")
        if not stat.S_ISREG(st.st_mode):
            raise UnsafeFileError(f"{p}: is not a regular file (a device, FIFO or socket)")
        if _NONBLOCK:
            os.set_blocking(fd, True)
        chunks, total = [], 0
        while True:
            chunk = os.read(fd, min(1 << 20, limit + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
            if total > limit:
                raise UnsafeFileError(f"{p}: file is larger than {_size(limit)}")
        return b"".join(chunks)
    finally:
        os.close(fd)


def _size(n: int) -> str:
    return f"{n >> 20} MiB" if n >= 1 << 20 else f"{n} bytes"
