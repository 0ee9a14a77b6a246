"""The one way matedit writes files, and the one way it reads untrusted ones.

Writes (`atomic_write_bytes`, `atomic_write_text`, `atomic_output`):
- the data goes to a temporary file created exclusively (O_EXCL, O_NOFOLLOW) at an
  unpredictable name beside the target, is flushed to disk, then renamed over the target,
  so the target is either the old file or the complete new one;
- a failure at any step removes the temporary file and leaves the old target untouched;
- `atomic_write_bytes` creates missing folders; `atomic_output` (images) expects the folder;
- new files get the user's umask (created 0o666 & ~umask); replacing a file keeps its mode;
- a target that is a symbolic link is written through: the link's final target is replaced
  and the link stays in place.
Writers that need a file name of their own (OpenImageIO) use `atomic_output`, which gives
them a name inside a private folder (0o700, created exclusively) beside the target.

Reads (`read_bounded`, `check_readable_file`): only regular files, with the size limit
checked while reading (so /dev/zero cannot exhaust memory), and opened non-blocking (so a
FIFO cannot hang the reader).
"""

from __future__ import annotations

import contextlib
import os
import secrets
import shutil
import stat
from collections.abc import Iterator
from pathlib import Path

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)


class UnsafeFileError(OSError):
    """A path that is not a regular file, or a file larger than allowed."""


def resolve_target(path: str | os.PathLike) -> Path:
    """The file a write to `path` must replace: symbolic links are followed to their target."""
    p = Path(path)
    if p.is_symlink():
        return Path(os.path.realpath(p))
    return p


def _existing_mode(path: Path) -> int | None:
    try:
        st = os.stat(path)
    except OSError:
        return None
    return stat.S_IMODE(st.st_mode) if stat.S_ISREG(st.st_mode) else None


def _fsync_dir(folder: Path) -> None:
    try:
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _exclusive_temp(folder: Path, name: str) -> tuple[int, Path]:
    for _ in range(100):
        tmp = folder / f".{name}.{secrets.token_hex(8)}.tmp"
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW | _CLOEXEC, 0o666)
        except FileExistsError:
            continue
        return fd, tmp
    raise FileExistsError(f"{folder}: cannot create a temporary file")


def atomic_write_bytes(path: str | os.PathLike, data: bytes) -> Path:
    """Replace `path` with `data` atomically (see the module notes); returns the file written."""
    target = resolve_target(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    if target.is_dir():
        raise IsADirectoryError(f"{path}: is a folder")
    mode = _existing_mode(target)
    fd, tmp = _exclusive_temp(target.parent, target.name)
    try:
        try:
            if mode is not None:
                os.fchmod(fd, mode)
            view = memoryview(data)
            while view:
                n = os.write(fd, view)
                view = view[n:]
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    _fsync_dir(target.parent)
    return target


def atomic_write_text(path: str | os.PathLike, text: str) -> Path:
    return atomic_write_bytes(path, text.encode("utf-8"))


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike) -> Iterator[Path]:
    """For writers that open a file by name: yields a name to write to; on a clean exit the
    file is moved over `path` (atomically), on an exception nothing of it remains."""
    target = resolve_target(path)
    if not target.parent.is_dir():
        raise FileNotFoundError(2, "the folder does not exist", str(target.parent))
    if target.is_dir():
        raise IsADirectoryError(f"{path}: is a folder")
    mode = _existing_mode(target)
    for _ in range(100):
        private = target.parent / f".{target.name}.{secrets.token_hex(8)}.tmpdir"
        try:
            os.mkdir(private, 0o700)
            break
        except FileExistsError:
            continue
    else:
        raise FileExistsError(f"{target.parent}: cannot create a temporary folder")
    try:
        inner = private / f"out{target.suffix}"
        yield inner
        st = os.lstat(inner)
        if not stat.S_ISREG(st.st_mode):
            raise UnsafeFileError(f"{path}: the writer produced no regular file")
        if mode is not None:
            os.chmod(inner, mode)
        with open(inner, "rb") as f:
            os.fsync(f.fileno())
        os.replace(inner, target)
        _fsync_dir(target.parent)
    finally:
        shutil.rmtree(private, ignore_errors=True)


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
