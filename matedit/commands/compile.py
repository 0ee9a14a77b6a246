"""`matedit compile FILE -o DIR [--target glsl330|glsl450|essl300|hlsl|msl|all]`.

Writes DIR/STEM.TARGET.vert and DIR/STEM.TARGET.frag (HLSL and MSL: DIR/STEM.vert.hlsl,
DIR/STEM.frag.metal and so on, matedit.interop.export) and DIR/STEM.reflection.json; refuses an
output that is, or resolves to, the document or a file it references."""

from __future__ import annotations

import sys
from pathlib import Path

from matedit.cli_support import UsageError, report
from matedit.compiler.targets import CROSS_TARGETS, TARGETS
from matedit.io.input_kinds import declare_inputs


def register(sub) -> None:
    p = sub.add_parser("compile", help="compile a material or material instance to GLSL",
                       description="Compile a material to vertex and fragment GLSL plus a "
                       "reflection JSON (uniforms, textures, targets).")
    p.add_argument("file", metavar="FILE")
    p.add_argument("-o", "--output", required=True, metavar="DIR")
    p.add_argument("--target", default="glsl330", choices=[*TARGETS, *CROSS_TARGETS, "all"],
                   help="GLSL dialect, HLSL/MSL (via SPIR-V and spirv-cross), or all (HLSL and "
                   "MSL only when spirv-cross is installed)")
    declare_inputs(p, file="document")
    p.set_defaults(run=run)


def run(args) -> int:
    # Imported here, not at the top, so that other subcommands start without the compiler.
    from matedit.compiler import CompileError
    from matedit.interop.cross import CrossCompileError, available
    from matedit.interop.export import compile_targets, export_shaders, shader_files
    from matedit.io.document import FileResolver, FormatError
    from matedit.io.inputs import OverwriteError, command_inputs, refuse_overwrite
    from matedit.io.instance import InstanceError, load_effective

    path = Path(args.file)
    try:
        doc, notes = load_effective(path)  # a material, or an instance's effective material
    except (FormatError, InstanceError) as exc:
        raise UsageError(str(exc)) from None
    for note in notes:
        report("warning", note.format())
    if doc.is_function:
        raise UsageError(f"{path}: is a material function; compile a material that calls it")
    resolver = FileResolver()
    targets = [*TARGETS, *(CROSS_TARGETS if available() else ())] if args.target == "all" \
        else [args.target]
    try:
        compiled = compile_targets(doc, resolver, targets)
    except CrossCompileError as exc:
        raise UsageError(f"{path}: {exc}") from None
    except CompileError as exc:
        for d in exc.diagnostics[1:]:
            report("error", f"{d.file or path}: {d.format()}")
        first = exc.diagnostics[0] if exc.diagnostics else None
        raise UsageError(f"{first.file or path}: {first.format()}" if first else str(exc)) \
            from None
    out = Path(args.output)
    try:
        refuse_overwrite(shader_files(doc, compiled, out), command_inputs(args, [doc], resolver))
        export_shaders(doc, resolver, targets, out, compiled)
    except (OverwriteError, NotADirectoryError) as exc:
        raise UsageError(str(exc)) from None
    except OSError as exc:
        raise UsageError(f"{getattr(exc, 'filename', None) or out}: cannot write: "
                         f"{exc.strerror or exc}") from None
    if sys.stderr.isatty():
        print(f"compiled {path} for {', '.join(targets)} into {out}", file=sys.stderr)
    return 0
