"""What the `matedit` command and every subcommand module share: the one-line error report
and the error of bad input. Its own module, below `matedit.cli` and `matedit.commands`, so
that the subcommands do not import the command line that imports them."""

from __future__ import annotations

import sys


def _escaped(c: str) -> str:
    if "\udc80" <= c <= "\udcff":  # a byte of a file name that is not UTF-8 (PEP 383)
        return f"\\x{ord(c) - 0xdc00:02x}"
    return c.encode("unicode_escape", errors="backslashreplace").decode("ascii")


def one_line(text: object) -> str:
    """Text for one line of a terminal report: line breaks and other control characters from
    file names or fields are shown escaped (a non-UTF-8 byte of a name as \\xNN), so a message
    is always exactly one printable line."""
    return "".join(c if c.isprintable() or c == " " else _escaped(c) for c in str(text))


def report(severity: str, message: object) -> None:
    """One `severity: message` line on stderr; a stderr that cannot be written is ignored
    (there is nowhere left to say so)."""
    stream = sys.stderr
    if stream is None:
        return
    try:
        stream.write(f"{severity}: {one_line(message)}\n")
        stream.flush()
    except (OSError, ValueError):
        pass


class UsageError(Exception):
    """Bad input: reported as one `error: ...` line and exit status 2."""
