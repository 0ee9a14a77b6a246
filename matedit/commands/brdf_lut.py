"""`matedit brdf-lut -o OUT.exr [--size N] [--samples N]`: write the environment BRDF LUT.

Layout (docs/shading.md#file-conventions): row k holds roughness (k + 0.5) / N, column i
NoV (i + 0.5) / N, R = A (scale), G = B (bias); float32 EXR.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from matedit.cli_support import UsageError
from matedit.io.input_kinds import declare_inputs


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "brdf-lut",
        help="write the split-sum environment BRDF LUT as EXR",
        description=__doc__.splitlines()[0].split(": ", 1)[1],
    )
    p.add_argument("-o", "--output", metavar="OUT.exr", required=True, help="output EXR file")
    p.add_argument("--size", type=int, default=128, help="LUT width and height (default 128)")
    p.add_argument(
        "--samples",
        type=int,
        default=1024,
        help="integrand evaluations per texel (default 1024; see matedit/ibl/lut.py)",
    )
    p.add_argument("--no-cache", action="store_true", help="compute even if cached")
    declare_inputs(p)  # computed, not read
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from matedit.ibl import bake_brdf_lut, write_lut
    from matedit.io.images import ImageError

    out = Path(args.output)
    if out.suffix.lower() != ".exr":
        raise UsageError(f"{out}: the LUT is written as OpenEXR; name it *.exr")
    if out.is_dir():
        raise UsageError(f"{out}: is a folder")
    if not out.parent.is_dir():
        raise UsageError(f"{out}: folder {out.parent} does not exist")
    from matedit.io.inputs import OverwriteError, command_inputs, refuse_overwrite

    try:
        refuse_overwrite([out], command_inputs(args))
    except OverwriteError as exc:
        raise UsageError(str(exc)) from None
    from matedit.render.context import headless_context

    ctx = headless_context()
    try:
        lut = bake_brdf_lut(args.size, args.samples, ctx=ctx, use_cache=not args.no_cache)
    except ValueError as exc:
        raise UsageError(f"{out}: {exc}") from exc
    finally:
        ctx.release()
    try:
        write_lut(out, lut)
    except ImageError as exc:
        raise UsageError(str(exc)) from exc
    if sys.stdout.isatty():
        print(f"wrote {out} ({args.size}x{args.size}, R = A, G = B)")
    else:
        print(out)
    return 0
