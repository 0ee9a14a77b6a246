"""The kinds of input a command argument may name, and `declare_inputs`, which records them
on a command's parser: what every command's parser needs, in a module of its own so that
building one (`matedit validate`) does not import the rest of `matedit.io.inputs` (which
names both too, and collects and checks the inputs a command read)."""

from __future__ import annotations

# The kinds of input a command argument may name (see `declare_inputs`).
INPUT_KINDS = ("document", "documents", "mesh", "environment", "rig", "mtlx")


def declare_inputs(parser, **kinds: str) -> None:
    """Record on a command's parser which arguments name inputs, and of which kind:
    'document' (a loaded material or instance, passed to `command_inputs`), 'documents'
    (the files or folders of several), 'mesh', 'environment', 'rig' (a light-rig file, or
    default/none) or 'mtlx' (a MaterialX document). A command that reads nothing says so
    explicitly: `declare_inputs(p)`."""
    bad = [k for k in kinds.values() if k not in INPUT_KINDS]
    if bad:
        raise ValueError(f"unknown input kinds {bad} (known: {', '.join(INPUT_KINDS)})")
    parser.set_defaults(inputs=dict(kinds))
