"""The compiled-shader files of one material: what `matedit compile` and the editor's
Export write, the same bytes from both.

DIR/STEM.TARGET.vert and DIR/STEM.TARGET.frag per GLSL target (glslang picks the stage by that
extension), DIR/STEM.vert.hlsl / .frag.hlsl and DIR/STEM.vert.metal / .frag.metal for HLSL and
MSL (the extensions their compilers and IDEs know), and DIR/STEM.reflection.json. No file
may replace the document or anything it reads (`matedit.io.inputs`); nothing written names a
folder of this machine (the reflection's `source` is the document's file name).
"""

from __future__ import annotations

import json
from pathlib import Path

from matedit.compiler.api import CompiledMaterial, compile_all
from matedit.graph.model import MaterialDocument
from matedit.io.atomic import staged_outputs
from matedit.io.inputs import document_inputs, refuse_overwrite


def stem_of(doc: MaterialDocument) -> str:
    name = Path(doc.path).name if doc.path else (doc.name or "material").replace(" ", "_")
    return name[:-5] if name.endswith(".json") else name


# Targets whose files end in their language's extension rather than the stage's.
LANGUAGE_SUFFIX = {"hlsl": "hlsl", "msl": "metal"}


def stage_file_name(stem: str, target: str, stage: str) -> str:
    """The file name of one stage ("vert" or "frag") of `target`."""
    suffix = LANGUAGE_SUFFIX.get(target)
    return f"{stem}.{stage}.{suffix}" if suffix else f"{stem}.{target}.{stage}"


def shader_files(doc: MaterialDocument, compiled: dict[str, CompiledMaterial],
                 folder: Path) -> dict[Path, str]:
    """Output path -> text for every file of the export."""
    folder = Path(folder)
    stem = stem_of(doc)
    files: dict[Path, str] = {}
    reflection: dict = {"source": Path(doc.path).name if doc.path else stem, "targets": {}}
    for name, cm in compiled.items():
        files[folder / stage_file_name(stem, name, "vert")] = cm.vertex_text
        files[folder / stage_file_name(stem, name, "frag")] = cm.fragment_text
        reflection["targets"][name] = cm.reflection()
    first = next(iter(compiled.values())).reflection()
    for key in ("attributes", "uniforms", "textures", "uniform_block"):
        reflection[key] = first[key]
    if "static_switches" in first:
        reflection["static_switches"] = first["static_switches"]
    files[folder / f"{stem}.reflection.json"] = json.dumps(reflection, sort_keys=True,
                                                           indent=2) + "\n"
    return files


def export_shaders(doc: MaterialDocument, resolver, targets: list[str], folder: Path,
                   compiled: dict[str, CompiledMaterial] | None = None) -> list[Path]:
    """Compile (unless given) and write; raises CompileError, OverwriteError or OSError.
    Every output is checked against the inputs before the first file is written, and the
    files appear together or not at all (`staged_outputs`)."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise NotADirectoryError(f"{folder}: exists and is not a folder")
    if compiled is None:
        compiled = compile_targets(doc, resolver, targets)
    files = shader_files(doc, compiled, folder)
    refuse_overwrite(files, document_inputs(doc, resolver))
    with staged_outputs(folder) as stage:
        for path, text in files.items():  # the reflection last
            stage.write_text(path, text)
    return list(files)


def compile_targets(doc: MaterialDocument, resolver, targets: list[str]) -> dict:
    """`compile_all`, plus the HLSL/MSL targets (translated from glsl450 by
    `matedit.interop.cross`; raises its CrossCompileError when a tool is missing)."""
    from matedit.compiler.targets import CROSS_TARGETS

    cross = [t for t in targets if t in CROSS_TARGETS]
    glsl = [t for t in targets if t not in CROSS_TARGETS]
    if not cross:
        return compile_all(doc, resolver, glsl)
    from matedit.interop.cross import cross_compile_many, tool

    for name in ("glslangValidator", "spirv-val", "spirv-cross"):
        tool(name)
    base = compile_all(doc, resolver, sorted(set(glsl) | {"glsl450"}))
    out = {t: base[t] for t in glsl}
    out.update(cross_compile_many(base["glsl450"], cross))
    return {t: out[t] for t in targets}
