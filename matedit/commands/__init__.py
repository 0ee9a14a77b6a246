"""Subcommands of the `matedit` command line, one module each.

Each module exposes `register(subparsers)`, which adds its parser and sets
`run=` to a function of the parsed arguments returning the exit status.
Bad input raises `matedit.cli_support.UsageError` (one line, exit 2).

`COMMANDS` names each command and its module, in the order `matedit --help` lists them, so
that a command line naming one command imports that module only (`register`'s `only`): the
others' imports (the compiler's back-ends, the interop packages) are no part of its start-up.
"""

from __future__ import annotations

# command name -> its module under matedit.commands (the name `add_parser` is given)
COMMANDS: dict[str, str] = {
    "validate": "validate",
    "compile": "compile",
    "render": "render",
    "bake-ibl": "bake_ibl",
    "brdf-lut": "brdf_lut",
    "nodes": "nodes",
    "contact-sheet": "contact_sheet",
    "bake": "bake",
    "export": "export",
    "import": "import_",
    "stats": "stats",
}


def register(sub, only: str | None = None) -> None:
    """Add every command's parser to `sub` (argparse subparsers), or only the one named
    `only` (a key of COMMANDS)."""
    for name, module in COMMANDS.items():
        if only is None or name == only:
            # __import__, not importlib.import_module: `python -X importtime` (the start-up
            # benchmark's breakdown) lists only what the import statement machinery loads
            __import__(f"matedit.commands.{module}", fromlist=["register"]).register(sub)
