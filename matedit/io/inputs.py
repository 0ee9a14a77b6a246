"""The files a document reads, and the rule that no output may overwrite one of them.

`document_inputs` collects the document itself, every material function, layer and blend it
calls (transitively, through the functions' own references), every texture, the preview
mesh and environment when they are files, and for an instance's effective material
(`matedit.io.instance`) every file of its parent chain. `refuse_overwrite` compares output
paths with those inputs after resolving links, `..` and hard links, and raises
`OverwriteError` naming both paths when an output would replace an input.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

BUILTIN_MESHES = frozenset({"sphere", "cube", "plane", "cylinder"})
BUILTIN_ENVIRONMENTS = frozenset({"studio", "sky"})


class OverwriteError(ValueError):
    """An output path that is, or resolves to, one of the inputs."""

    def __init__(self, output: Path, source: Path, what: str) -> None:
        self.output, self.source = output, source
        super().__init__(f"{output}: refusing to write over {what} {source}; choose another "
                         "output path")


def preview_file(doc, key: str) -> Path | None:
    """The file named by `doc.preview[key]` (mesh or environment), relative to the document;
    None for built-in names and for absent or non-string values."""
    value = doc.preview.get(key) if isinstance(doc.preview, dict) else None
    if not isinstance(value, str) or not value:
        return None
    if value in (BUILTIN_MESHES if key == "mesh" else BUILTIN_ENVIRONMENTS):
        return None
    base = Path(doc.path).parent if doc.path else Path.cwd()
    return base / value


def document_inputs(doc, resolver=None) -> dict[Path, str]:
    """Every file `doc` reads, resolved, mapped to a description ('the document', ...)."""
    from matedit.io.document import reference_fields

    found: dict[Path, str] = {}
    todo = [(doc, "the document")]
    seen_docs: set[Path] = set()
    while todo:
        d, what = todo.pop()
        if d.path is not None:
            p = _real(d.path)
            found.setdefault(p, what)
            if p in seen_docs:
                continue
            seen_docs.add(p)
        base = Path(d.path).parent if d.path else Path.cwd()
        for container, key in reference_fields(d):
            ref = container[key]
            if not isinstance(ref, str) or not ref:
                continue
            target = _real(base / ref)
            kind = "the texture" if key == "path" else "the material function"
            found.setdefault(target, kind)
            if key != "path" and resolver is not None and target not in seen_docs:
                try:
                    sub = resolver.resolve(ref, d)
                except LookupError:
                    continue
                todo.append((sub, kind))
        for parent in getattr(d, "instance_chain", ()):  # an instance's parents
            found.setdefault(_real(parent), "a parent of the instance")
        for key, what_ in (("mesh", "the preview mesh"), ("environment", "the environment")):
            f = preview_file(d, key)
            if f is not None:
                found.setdefault(_real(f), what_)
    return found


def refuse_overwrite(outputs: Iterable[str | os.PathLike], inputs: dict[Path, str]) -> None:
    """Raise OverwriteError if any output resolves to (or is a hard link of) an input."""
    ids = {}
    for p, what in inputs.items():
        try:
            st = os.stat(p)
            ids[(st.st_dev, st.st_ino)] = (p, what)
        except OSError:
            pass
    for out in outputs:
        o = Path(out)
        real = _real(o)
        if real in inputs:
            raise OverwriteError(o, real, inputs[real])
        try:
            st = os.stat(real)
        except OSError:
            continue
        hit = ids.get((st.st_dev, st.st_ino))
        if hit:
            raise OverwriteError(o, hit[0], hit[1])


def _real(p: str | os.PathLike) -> Path:
    try:
        return Path(os.path.realpath(os.fspath(p)))
    except (OSError, ValueError):  # a NUL byte or an over-long name: no file has that path
        return Path(os.path.abspath(os.fspath(p)).replace("\0", "\\0"))
