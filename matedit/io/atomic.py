"""The one way matedit writes files, and the one way it reads untrusted ones.

Writes (`atomic_write_bytes`, `atomic_write_text`, `atomic_output`):
- the data goes to a temporary file created exclusively (O_EXCL, O_NOFOLLOW) at an
  unpredictable name beside the target, is flushed to disk, then renamed over the target,
  so the target is either the old file or the complete new one;
- a failure at any step, or SIGINT/SIGTERM (the command line turns them into exceptions),
  removes the temporary file and leaves the old target untouched;
- `atomic_write_bytes` creates missing folders; `atomic_output` (images) expects the folder;
- new files get the user's umask (created 0o666 & ~umask); replacing a file keeps its mode;
- a symbolic link at the target's name is replaced by the new file and never written
  through (a link planted in a shared or downloaded folder cannot redirect an output).
  Only a document saved to the path it was opened from follows the link (`follow_link=True`,
  passed by the document, instance and rig saves through `saves_to_opened_path`).
Writers that need a file name of their own (OpenImageIO) use `atomic_output`, which gives
them a name inside a private folder (0o700, created exclusively) beside the target.

Outputs of several files (`staged_outputs`): every file is written into one private folder
beside them, and only when all are complete are they renamed into place; on any failure
nothing new remains and the old files are as they were.

Temporary names are `.<name>.<pid>-<host>.<random>.tmp` (or `.tmpdir`): each write into a
folder first removes the leftovers there of a process of this user and host that is gone
(killed with SIGKILL, or a machine that lost power), matching that exact pattern only and
never following a link (`remove_leftovers`).

Reads (`read_bounded`, `check_readable_file`, in `matedit.io.bounded` and named here too):
only regular files, with the size limit checked while reading (so /dev/zero cannot exhaust
memory), and opened non-blocking (so a FIFO cannot hang the reader).
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import stat
import zlib
from collections.abc import Iterator
from pathlib import Path

# the reading half, its own module (what a reader of documents imports); named here too
from matedit.io.bounded import UnsafeFileError as UnsafeFileError
from matedit.io.bounded import check_readable_file as check_readable_file
from matedit.io.bounded import read_bounded as read_bounded

_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)
_DIRECTORY = getattr(os, "O_DIRECTORY", 0)

# The part of a file name kept in a temporary name: enough to recognise it, short enough
# that the temporary name stays within the 255 bytes a name may have.
_NAME_KEPT = 96
_LEFTOVER = re.compile(r"\..+\.(?P<pid>[1-9][0-9]{0,9})-(?P<host>[0-9a-f]{8})\.[0-9a-f]{16}"
                       r"\.(?P<kind>tmp|tmpdir)", re.DOTALL)  # the whole name (fullmatch)


def saves_to_opened_path(target: str | os.PathLike, opened: str | os.PathLike | None) -> bool:
    """Whether a save to `target` is a save of a document to the name it was opened from
    (links not resolved): the one write that follows a link at its name."""
    if opened is None:
        return False
    return os.path.abspath(os.fspath(target)) == os.path.abspath(os.fspath(opened))


def resolve_target(path: str | os.PathLike, follow_link: bool = False) -> Path:
    """The name a write to `path` replaces: `path` itself (a link there is replaced), or
    with `follow_link` the final target of a link there."""
    p = Path(path)
    if follow_link and p.is_symlink():
        return Path(os.path.realpath(p))
    return p


def _lstat(path: Path) -> os.stat_result | None:
    try:
        return os.lstat(path)
    except OSError:
        return None


def _existing_mode(path: Path) -> int | None:
    """The mode of the regular file at `path` (a link there is not looked through)."""
    st = _lstat(path)
    return stat.S_IMODE(st.st_mode) if st is not None and stat.S_ISREG(st.st_mode) else None


def _refuse_folder(path: Path, given: str | os.PathLike) -> None:
    st = _lstat(path)
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(21, "is a folder", str(given))


def _fsync_dir(folder: Path) -> None:
    try:
        fd = os.open(folder, os.O_RDONLY | _DIRECTORY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _host_tag() -> str:
    """Eight hex digits naming this machine, so that only its own leftovers are judged by pid."""
    return f"{zlib.crc32(os.uname().nodename.encode('utf-8', 'surrogateescape')):08x}"


def temporary_name(name: str, kind: str = "tmp") -> str:
    """A fresh temporary name for `name`: `.<name>.<pid>-<host>.<random>.<kind>`, with at
    most `_NAME_KEPT` bytes of `name` (whole characters)."""
    import secrets  # here: a reader of documents (matedit validate) never needs it

    kept = name[:_NAME_KEPT]
    while len(kept.encode("utf-8", "surrogateescape")) > _NAME_KEPT:
        kept = kept[:-1]
    return f".{kept}.{os.getpid()}-{_host_tag()}.{secrets.token_hex(8)}.{kind}"


def pid_running(pid: int) -> bool:
    """Whether a process `pid` runs on this machine (signal 0 probes without sending); any
    integer may be asked, one no process can have is simply not running."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (OverflowError, ValueError):  # no process can have that number
        return False
    except OSError:  # PermissionError: alive, someone else's
        return True
    return True


def _process_gone(pid: int) -> bool:
    return pid != os.getpid() and not pid_running(pid)


def remove_leftovers(folder: str | os.PathLike) -> list[str]:
    """Remove from `folder` the temporary files and folders of our own dead processes:
    names of the exact temporary pattern, owned by this user, made on this host by a pid
    that no longer runs; a link is never followed, nor removed. Returns the names removed."""
    removed: list[str] = []
    if os.name != "posix":  # pids are judged with kill(pid, 0)
        return removed
    host, uid = _host_tag(), os.geteuid()
    try:
        entries = list(os.scandir(os.fsdecode(folder)))
    except OSError:
        return removed
    for entry in entries:
        m = _LEFTOVER.fullmatch(entry.name)
        if m is None or m["host"] != host:
            continue
        try:
            st = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        if st.st_uid != uid or not _process_gone(int(m["pid"])):
            continue
        try:
            if m["kind"] == "tmp" and stat.S_ISREG(st.st_mode):
                os.unlink(entry.path)
            elif m["kind"] == "tmpdir" and stat.S_ISDIR(st.st_mode):
                shutil.rmtree(entry.path)  # fd-based: never follows a link inside
            else:
                continue
        except OSError:
            continue
        removed.append(entry.name)
    return removed


def _renamed(exc: OSError, path: Path) -> OSError:
    """`exc` naming `path` (the same errno, so the same OSError subclass)."""
    if exc.errno is None:
        return exc
    return OSError(exc.errno, exc.strerror, str(path))


def _exclusive_temp(folder: Path, name: str) -> tuple[int, Path]:
    for _ in range(100):
        tmp = folder / temporary_name(name)
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW | _CLOEXEC, 0o666)
        except FileExistsError:
            continue
        except OSError as exc:  # named by the file asked for, not its temporary
            raise _renamed(exc, folder / name) from None
        return fd, tmp
    raise FileExistsError(f"{folder}: cannot create a temporary file")


def _private_folder(folder: Path, name: str) -> Path:
    """A new folder (0o700, created exclusively) inside `folder`, at a temporary name."""
    for _ in range(100):
        private = folder / temporary_name(name, "tmpdir")
        try:
            os.mkdir(private, 0o700)
        except FileExistsError:
            continue
        except OSError as exc:  # a read-only or full folder: named as the user knows it
            raise _renamed(exc, folder) from None
        return private
    raise FileExistsError(f"{folder}: cannot create a temporary folder")


def atomic_write_bytes(path: str | os.PathLike, data: bytes, *,
                       follow_link: bool = False) -> Path:
    """Replace `path` with `data` atomically (see the module notes); returns the file written.
    A link at `path` is replaced, unless `follow_link` (a document's own save)."""
    target = resolve_target(path, follow_link)
    target.parent.mkdir(parents=True, exist_ok=True)
    _refuse_folder(target, path)
    remove_leftovers(target.parent)
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


def atomic_write_text(path: str | os.PathLike, text: str, *,
                      follow_link: bool = False) -> Path:
    return atomic_write_bytes(path, text.encode("utf-8"), follow_link=follow_link)


def _fsync_file(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY | _NOFOLLOW | _CLOEXEC)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike, *, follow_link: bool = False) -> Iterator[Path]:
    """For writers that open a file by name: yields a name to write to; on a clean exit the
    file is moved over `path` (atomically; a link there is replaced unless `follow_link`),
    on an exception nothing of it remains."""
    target = resolve_target(path, follow_link)
    if not target.parent.is_dir():
        raise FileNotFoundError(2, "the folder does not exist", str(target.parent))
    _refuse_folder(target, path)
    remove_leftovers(target.parent)
    mode = _existing_mode(target)
    private = _private_folder(target.parent, target.name)
    try:
        inner = private / f"out{target.suffix}"
        yield inner
        st = os.lstat(inner)
        if not stat.S_ISREG(st.st_mode):
            raise UnsafeFileError(f"{path}: the writer produced no regular file")
        if mode is not None:
            os.chmod(inner, mode)
        _fsync_file(inner)
        os.replace(inner, target)
        _fsync_dir(target.parent)
    finally:
        shutil.rmtree(private, ignore_errors=True)


class OutputSet:
    """The files of one output written whole or not at all (see `staged_outputs`)."""

    def __init__(self, folder: Path, private: Path) -> None:
        self.folder, self.private = folder, private
        self._staged: dict[str, Path] = {}  # final name -> staged file, in commit order
        self.written: list[Path] = []  # the final paths, once in place

    def path(self, final: str | os.PathLike) -> Path:
        """Where to write the file that will be `final` (a name in the output folder)."""
        final = Path(final)
        if os.path.abspath(final.parent) != os.path.abspath(self.folder):
            raise ValueError(f"{final}: not in the output folder {self.folder}")
        if final.name in self._staged:
            raise ValueError(f"{final}: written twice in one output")
        staged = self.private / final.name
        self._staged[final.name] = staged
        return staged

    def write_bytes(self, final: str | os.PathLike, data: bytes) -> Path:
        return atomic_write_bytes(self.path(final), data)

    def write_text(self, final: str | os.PathLike, text: str) -> Path:
        return atomic_write_text(self.path(final), text)

    def _name_finals(self, exc: BaseException) -> None:
        """Make an error raised while writing name the output, not its staged temporary."""
        pairs = [(str(s), str(self.folder / n)) for n, s in self._staged.items()]
        pairs.append((str(self.private), str(self.folder)))

        def fix(text):
            if isinstance(text, str):
                for staged, final in pairs:
                    text = text.replace(staged, final)
            return text

        if isinstance(exc, OSError):
            exc.filename = fix(exc.filename)
            exc.filename2 = fix(exc.filename2)
        else:
            exc.args = tuple(fix(a) for a in exc.args)

    def _commit(self) -> list[Path]:
        """Rename every staged file into place; if one rename fails, the files already moved
        are put back as they were (the old file, or none) and the error is raised."""
        moves = []
        for i, (name, staged) in enumerate(self._staged.items()):
            st = _lstat(staged)
            if st is None or not stat.S_ISREG(st.st_mode):
                raise UnsafeFileError(f"{self.folder / name}: the writer produced no regular "
                                      "file")
            final = self.folder / name
            _refuse_folder(final, final)
            mode = _existing_mode(final)
            if mode is not None:
                os.chmod(staged, mode)
            _fsync_file(staged)
            existed, backup = _lstat(final) is not None, None
            if existed:  # kept (a hard link) to be put back on failure
                backup = self.private / f".old.{i}"
                try:
                    os.link(final, backup, follow_symlinks=False)
                except OSError:
                    backup = None
            moves.append((staged, final, existed, backup))
        done = []
        try:
            for staged, final, existed, backup in moves:
                os.replace(staged, final)
                done.append((final, existed, backup))
        except BaseException:
            for final, existed, backup in reversed(done):
                with contextlib.suppress(OSError):
                    if backup is not None:
                        os.replace(backup, final)
                    elif not existed:
                        os.unlink(final)
            raise
        _fsync_dir(self.folder)
        return [final for _, final, _, _ in moves]


@contextlib.contextmanager
def staged_outputs(folder: str | os.PathLike) -> Iterator[OutputSet]:
    """An output of several files in `folder` (created if missing): write each through
    `OutputSet.path`/`write_*`; on a clean exit all are renamed into place (a link at a
    name is replaced, never written through), on any exception none is, and the folders
    this created are removed again."""
    folder = Path(folder)
    created = []
    probe = folder
    while _lstat(probe) is None and probe != probe.parent:
        created.append(probe)
        probe = probe.parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
        if not folder.is_dir():
            raise NotADirectoryError(20, "not a folder", str(folder))
        remove_leftovers(folder)
        private = _private_folder(folder, "output")
        try:
            outputs = OutputSet(folder, private)
            try:
                yield outputs
                outputs.written = outputs._commit()
            except BaseException as exc:
                outputs._name_finals(exc)
                raise
        finally:
            shutil.rmtree(private, ignore_errors=True)
    except BaseException:
        for made in created:  # deepest first; only while still empty
            with contextlib.suppress(OSError):
                os.rmdir(made)
        raise
