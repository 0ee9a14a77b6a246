"""File references as documents store them: relative to the document's own file."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

from matedit.graph.model import MaterialDocument
from matedit.io import library
from matedit.io.document import reference_from

if TYPE_CHECKING:
    from matedit.compiler.api import CompiledMaterial


def reference_for(doc: MaterialDocument, target: str | os.PathLike) -> str:
    """How `doc` should store a reference to `target`: relative to the document's folder
    once it has one; absolute (made relative on the first save) while it is unsaved."""
    target = Path(target).resolve()
    if doc.path is None:
        return target.as_posix()
    try:
        return reference_from(target, Path(doc.path).resolve().parent)
    except ValueError:  # another drive on Windows
        return target.as_posix()


def absolute_of(doc: MaterialDocument, ref: str) -> Path | None:
    if not ref:
        return None
    if library.is_library_ref(ref):
        try:
            return library.library_path(ref)
        except ValueError:
            return None
    p = Path(ref)
    if p.is_absolute():
        return p
    base = Path(doc.path).resolve().parent if doc.path else Path.cwd()
    return (base / p).resolve()


def relativise_references(doc: MaterialDocument, new_path: Path) -> None:
    """Absolute references (made while the document was unsaved) become relative to the
    file it is about to be saved as. Called just before the first save."""
    from matedit.io.document import reference_fields

    base = Path(new_path).resolve().parent
    for container, key in reference_fields(doc):
        ref = container[key]
        if isinstance(ref, str) and ref and Path(ref).is_absolute():
            try:
                container[key] = reference_from(Path(ref), base)
            except ValueError:
                pass


def texture_paths(compiled: CompiledMaterial, doc: MaterialDocument) -> dict[str, Path | None]:
    """Each texture uniform's file, from the texture parameter's current `path` setting."""
    out: dict[str, Path | None] = {}
    for t in compiled.ir.textures:
        node = doc.graph.nodes.get(t.node)
        ref = node.settings.get("path", t.path) if node is not None else t.path
        out[t.name] = absolute_of(doc, ref) if isinstance(ref, str) and ref else None
    return out
