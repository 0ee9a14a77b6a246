"""Subcommands of the `matedit` command line, one module each.

Each module exposes `register(subparsers)`, which adds its parser and sets
`run=` to a function of the parsed arguments returning the exit status.
Bad input raises `matedit.cli_support.UsageError` (one line, exit 2).
"""

from matedit.commands import bake as bake_cmd
from matedit.commands import bake_ibl, brdf_lut, contact_sheet, nodes, render, stats, validate
from matedit.commands import compile as compile_cmd
from matedit.commands import export as export_cmd
from matedit.commands import import_ as import_cmd

REGISTRY = [
    validate.register,
    compile_cmd.register,
    render.register,
    bake_ibl.register,
    brdf_lut.register,
    nodes.register,
    contact_sheet.register,
    bake_cmd.register,
    export_cmd.register,
    import_cmd.register,
    stats.register,
]
