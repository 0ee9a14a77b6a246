"""The built-in library: the install's graphs/ folder (samples, layers, functions and
instances), read-only, and named in documents by a stable reference.

A document outside the library refers to a library file as `library:layers/gold.json`
(the file's path under graphs/, with forward slashes), so the reference survives moving
the document, reinstalling matedit or installing it elsewhere. Inside the library the
shipped files keep their relative references. Saving rewrites references (see
`matedit.io.document.rebase_references`); the editor never writes into the library.
"""

from __future__ import annotations

import os
from pathlib import Path, PurePosixPath

from matedit.resources import graphs_dir

PREFIX = "library:"


def root() -> Path:
    """The library folder, links resolved."""
    return Path(os.path.realpath(graphs_dir()))


def is_library_ref(ref: object) -> bool:
    return isinstance(ref, str) and ref.startswith(PREFIX)


def library_path(ref: str) -> Path:
    """The file a `library:` reference names; ValueError for a name that is not a plain path
    under the library (absolute, `..`, a backslash, a link out of it)."""
    rel = ref[len(PREFIX):]
    parts = rel.split("/")
    if not rel or "\\" in rel or "\0" in rel or PurePosixPath(rel).is_absolute() \
            or any(p in ("", "..", ".") for p in parts):
        raise ValueError(f"{ref!r} is not a library name (library:FOLDER/FILE.json)")
    base = root()
    target = Path(os.path.realpath(base.joinpath(*parts)))
    if not target.is_relative_to(base):
        raise ValueError(f"{ref!r} leads out of the library")
    return target


def inside(path: str | os.PathLike) -> bool:
    """Whether `path` (links resolved) lies in the library folder."""
    return Path(os.path.realpath(path)).is_relative_to(root())


def library_name(path: str | os.PathLike) -> str | None:
    """`library:REL` for a file in the library, None for any other file."""
    real = Path(os.path.realpath(path))
    base = root()
    if not real.is_relative_to(base) or real == base:
        return None
    return PREFIX + real.relative_to(base).as_posix()
