"""The files a command reads, and the rule that no output may overwrite one of them.

`command_inputs` is the one collector: each command declares, on its parser, which of its
arguments name inputs and of what kind (`declare_inputs`), and calls `command_inputs` with
the documents it loaded before it writes anything. `document_inputs` collects what one
document reads: itself, every material function, layer and blend it calls (transitively),
every texture, the preview mesh and environment when they are files (the six face files of
a folder environment), and for an instance's effective material (`matedit.io.instance`)
every file of its parent chain. `refuse_overwrite` compares output paths with those inputs
after resolving links, `..` and hard links, and raises `OverwriteError` naming both paths
when an output would replace an input.

Mesh and environment names: `builtin:NAME` is always a built-in, a bare built-in name
(`studio`) is the built-in too unless it is written as a path (`./studio`, absolute, or
holding a `/`); anything else is a file or folder (`builtin_name`).
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from pathlib import Path

# The kinds of input a command argument may name, and the declaration of a command's inputs:
# matedit.io.input_kinds (what every command's parser needs, without the rest of this module)
from matedit.io.input_kinds import INPUT_KINDS as INPUT_KINDS
from matedit.io.input_kinds import declare_inputs as declare_inputs

BUILTIN_MESHES = ("sphere", "cube", "plane", "cylinder")
BUILTIN_ENVIRONMENTS = ("studio", "sky")
BUILTIN_PREFIX = "builtin:"
_BUILTINS = {"mesh": BUILTIN_MESHES, "environment": BUILTIN_ENVIRONMENTS}


class OverwriteError(ValueError):
    """An output path that is, or resolves to, one of the inputs."""

    def __init__(self, output: Path, source: Path, what: str) -> None:
        self.output, self.source = output, source
        super().__init__(f"{output}: refusing to write over {what} {source}; choose another "
                         "output path")


class BuiltinNameError(ValueError):
    """`builtin:NAME` with a NAME that is no built-in; the message lists the spellings."""


def spellings(kind: str) -> str:
    """How a mesh or environment may be named, for error messages."""
    names = _BUILTINS[kind]
    files = "an OBJ file" if kind == "mesh" else \
        "an HDR/EXR file or a folder of six cube-face files"
    return (f"{', '.join(names)} (or {', '.join(BUILTIN_PREFIX + n for n in names)}), or "
            f"{files}; write ./{names[0]} for a file or folder of a built-in's name")


def builtin_name(spec, kind: str) -> str | None:
    """The built-in `spec` names, or None when it names a file or folder.

    `builtin:NAME` always means the built-in (an unknown NAME raises BuiltinNameError); a
    bare built-in name means it too, whatever the folder holds; a path object, or text
    written as a path (`./studio`, absolute, holding a `/`), never does."""
    if not isinstance(spec, str):  # a Path was made from a file reference
        return None
    names = _BUILTINS[kind]
    if spec.startswith(BUILTIN_PREFIX):
        name = spec[len(BUILTIN_PREFIX):]
        if name not in names:
            raise BuiltinNameError(f"{spec}: no built-in {kind} of that name (a {kind} is "
                                   f"{spellings(kind)})")
        return name
    return spec if spec in names else None


def as_reference(relative: str, kind: str) -> str:
    """A relative file reference spelled so that it cannot read as a built-in name."""
    if relative.startswith(BUILTIN_PREFIX) or relative in _BUILTINS[kind]:
        return "./" + relative
    return relative


# Cube-face file names of a folder environment (matedit.ibl.environment.load_cube_faces).
FACE_ALIASES = {"px": ("px", "posx", "right"), "nx": ("nx", "negx", "left"),
                "py": ("py", "posy", "top", "up"), "ny": ("ny", "negy", "bottom", "down"),
                "pz": ("pz", "posz", "front"), "nz": ("nz", "negz", "back")}
FACE_EXTENSIONS = frozenset({".exr", ".hdr", ".png", ".jpg", ".jpeg", ".tif", ".tiff"})


def face_key(stem: str) -> str | None:
    """The cube face a file stem names (`sky_px`, `posx`, `right`...), or None."""
    s = stem.lower()
    for face, names in FACE_ALIASES.items():
        for n in names:
            if s == n or s.endswith(("_" + n, "-" + n, "." + n)):
                return face
    return None


def cube_face_files(folder: str | os.PathLike) -> list[tuple[str, Path]]:
    """(face, file) for every file of `folder` a folder environment reads as a cube face,
    in name order (two for one face are possible: the loader refuses them)."""
    out = []
    try:
        entries = sorted(Path(folder).iterdir())
    except OSError:
        return []
    for p in entries:
        if p.suffix.lower() in FACE_EXTENSIONS and os.path.isfile(p):
            key = face_key(p.stem)
            if key is not None:
                out.append((key, p))
    return out


def environment_files(path: str | os.PathLike) -> list[Path]:
    """The files an environment at `path` reads: its cube faces for a folder, else itself."""
    p = Path(path)
    return [f for _, f in cube_face_files(p)] if os.path.isdir(p) else [p]


def preview_file(doc, key: str) -> Path | None:
    """The file named by `doc.preview[key]` (mesh or environment), relative to the document;
    None for built-in names (bare or `builtin:`) and for absent or non-string values."""
    value = doc.preview.get(key) if isinstance(doc.preview, dict) else None
    if not isinstance(value, str) or not value:
        return None
    if value.startswith(BUILTIN_PREFIX) or builtin_name(value, key) is not None:
        return None
    base = Path(doc.path).parent if doc.path else Path.cwd()
    return base / value


def preview_spec(doc, key: str, default: str):
    """What to load for the document's preview mesh or environment: its file (a Path), its
    built-in name as written, or `default`."""
    f = preview_file(doc, key)
    if f is not None:
        return f
    value = doc.preview.get(key) if isinstance(doc.preview, dict) else None
    return value if isinstance(value, str) and value else default


def document_inputs(doc, resolver=None, include_self: bool = True) -> dict[Path, str]:
    """Every file `doc` reads, resolved, mapped to a description ('the document', ...).
    `include_self=False` for a document about to be written (an import's): what it refers
    to is an input, its own path is not."""
    from matedit.io.document import reference_fields

    found: dict[Path, str] = {}
    todo = [(doc, "the document")]
    seen_docs: set[Path] = set()
    while todo:
        d, what = todo.pop()
        if d.path is not None:
            p = _real(d.path)
            if include_self or d is not doc:
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
            # and the file a reader that tidies `..` away first would open
            found.setdefault(_real(os.path.abspath(base / ref)), kind)
            if key != "path" and resolver is not None and target not in seen_docs:
                try:
                    sub = resolver.resolve(ref, d)
                except LookupError:
                    continue
                todo.append((sub, kind))
        for parent in getattr(d, "instance_chain", ()):  # an instance's parents
            found.setdefault(_real(parent), "a parent of the instance")
        for tex in getattr(d, "instance_textures", ()):  # its overrides, spelled as written
            found.setdefault(_real(tex), "the texture")
        for key, what_ in (("mesh", "the preview mesh"), ("environment", "the environment")):
            f = preview_file(d, key)
            if f is None:
                continue
            for g in environment_files(f) if key == "environment" else [f]:
                found.setdefault(_real(g), what_ if g == f else "a cube face of the environment")
    return found


_KIND_WHAT = {"mesh": "the mesh", "environment": "the environment", "rig": "the light rig",
              "mtlx": "the MaterialX document"}


def command_inputs(args, documents: Iterable = (), resolver=None,
                   written: Iterable = ()) -> dict[Path, str]:
    """Every file the command parsed into `args` reads, resolved, mapped to a description.

    `documents`: the documents it loaded (each with everything `document_inputs` finds);
    `written`: documents it is about to write, whose references are inputs too. The
    arguments named by the command's `declare_inputs` add the mesh, environment (each cube
    face of a folder), rig and other files they name. A command that declared nothing is a
    programming error (LookupError), so that no command can skip the check."""
    declared = getattr(args, "inputs", None)
    if declared is None:
        raise LookupError(f"command {getattr(args, 'command', '?')!r} declares no inputs "
                          "(matedit.io.inputs.declare_inputs)")
    found: dict[Path, str] = {}
    for dest, kind in declared.items():
        value = getattr(args, dest, None)
        values = value if isinstance(value, list) else [value]
        for v in values:
            if not isinstance(v, str) or not v:
                continue
            if kind in ("document", "documents"):  # read in full through `documents`
                if not os.path.isdir(v):  # False, not an error, for an over-long name
                    found.setdefault(_real(v), "the document")
                continue
            if kind == "rig" and v in ("default", "none"):
                continue
            if kind in ("mesh", "environment"):
                try:
                    if builtin_name(v, kind) is not None:
                        continue
                except BuiltinNameError:
                    continue  # reported when it is loaded
            files = environment_files(v) if kind == "environment" else [Path(v)]
            for f in files:
                found.setdefault(_real(f), _KIND_WHAT[kind] if f == Path(v) else
                                 "a cube face of the environment")
    for doc in documents:
        for p, what in document_inputs(doc, resolver).items():
            found.setdefault(p, what)
    for doc in written:
        for p, what in document_inputs(doc, resolver, include_self=False).items():
            found.setdefault(p, "an image a material reads" if what == "the texture" else what)
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
