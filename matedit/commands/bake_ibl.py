"""`matedit bake-ibl ENV -o DIR [--size N] [--samples N]`: bake an environment to files.

ENV is an HDR image (equirect 2:1 or cube cross 4:3 / 3:4; .hdr, .exr, ...) or a built-in
name (studio, sky). The files written are described in matedit/ibl/output.py.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from matedit.cli_support import UsageError, report
from matedit.io.input_kinds import declare_inputs


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "bake-ibl",
        help="bake an environment: prefiltered cube mips, BRDF LUT, SH irradiance",
        description=__doc__.splitlines()[0].split(": ", 1)[1],
    )
    p.add_argument("env", metavar="ENV", help="environment image, a folder of six cube-face "
                   "files, or a built-in: studio, sky (or builtin:studio, builtin:sky; "
                   "./studio is a file or folder of that name)")
    p.add_argument("-o", "--output", metavar="DIR", required=True, help="output folder")
    p.add_argument("--size", type=int, default=256, help="face size of mip 0 (default 256)")
    p.add_argument(
        "--samples", type=int, default=256, help="GGX samples per texel of mip 1 (default 256)"
    )
    p.add_argument("--no-cache", action="store_true", help="bake even if a cached bake exists")
    declare_inputs(p, env="environment")
    p.set_defaults(run=run)


def terminal_progress(label: str):
    """A progress callback drawing one line on stderr, or None when stderr is no terminal."""
    if not sys.stderr.isatty():
        return None

    def show(fraction: float, message: str) -> None:
        sys.stderr.write(f"\r{label}: {100 * fraction:3.0f}% {message:<40}")
        if fraction >= 1.0:
            sys.stderr.write("\n")
        sys.stderr.flush()

    return show


def run(args: argparse.Namespace) -> int:
    from matedit.ibl import BakeSettings, EnvironmentMapError, bake, load_environment, write_bake
    from matedit.io.images import ImageError

    settings = BakeSettings(size=args.size, samples=args.samples)
    try:
        settings = settings.resolved()
    except ValueError as exc:
        raise UsageError(f"{args.env}: {exc}") from exc
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise UsageError(f"{out}: exists and is not a folder")
    from matedit.io.inputs import OverwriteError, command_inputs, refuse_overwrite

    names = ["brdf_lut.exr", "sh.json", "ibl.json"]
    names += [f"prefiltered_mip{m}.exr" for m in range(16)]
    try:
        refuse_overwrite([out / n for n in names], command_inputs(args))
    except OverwriteError as exc:
        raise UsageError(str(exc)) from None
    try:
        env = load_environment(args.env, settings.size)
    except EnvironmentMapError as exc:
        raise UsageError(str(exc)) from exc
    for warning in env.warnings:
        report("warning", warning)
    env.warnings = []  # printed already
    from matedit.render.context import headless_context

    ctx = headless_context()
    try:
        result = bake(env, settings, ctx=ctx, use_cache=not args.no_cache,
                      progress=terminal_progress("bake-ibl"))
    finally:
        ctx.release()
    for warning in result.warnings:
        report("warning", warning)
    try:
        written = write_bake(result, out)
    except ImageError as exc:
        raise UsageError(str(exc)) from exc
    except OSError as exc:
        raise UsageError(f"{exc.filename or out}: {exc.strerror or exc}") from exc
    for path in written:
        print(path)
    return 0
