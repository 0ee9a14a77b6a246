"""The `matedit` command (see ARCHITECTURE.md, "Command line": a contract)."""

from __future__ import annotations

import argparse
import os
import signal
import sys

QUIT_AFTER_FIRST_FRAME = "MATEDIT_QUIT_AFTER_FIRST_FRAME"


def one_line(text: object) -> str:
    """Text for one line of a terminal report: line breaks and other control characters from
    file names or fields are shown escaped, so a message is always exactly one line."""
    return "".join(c if c.isprintable() or c == " " else
                   c.encode("unicode_escape").decode("ascii") for c in str(text))


def report(severity: str, message: object) -> None:
    print(f"{severity}: {one_line(message)}", file=sys.stderr)


class UsageError(Exception):
    """Bad input: reported as one `error: ...` line and exit status 2."""


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the program is so that every write in progress cleans up."""


def _on_sigterm(signum, frame) -> None:
    raise Terminated


def _catch_sigterm() -> tuple:
    """Turn SIGTERM into `Terminated` while a command runs (not the editor, whose event loop
    would defer it); returns what `_restore_sigterm` needs."""
    import threading

    if threading.current_thread() is not threading.main_thread():
        return ()
    previous = signal.signal(signal.SIGTERM, _on_sigterm)
    return (signal.SIG_DFL if previous is None else previous,)


def _restore_sigterm(saved: tuple) -> None:
    if saved:
        signal.signal(signal.SIGTERM, saved[0])


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # argparse would print usage and exit 2
        raise UsageError(message)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="matedit", description="Node-based material editor (Karis 2013). "
                     "`matedit [FILE]` opens the editor (no FILE: the built-in sample "
                     "layered material); the commands below run headless.")
    parser.add_argument("--version", action="store_true",
                        help="print the version and exit")
    sub = parser.add_subparsers(dest="command", parser_class=_Parser)
    from matedit import commands

    for register in commands.REGISTRY:
        register(sub)
    return parser


def subcommand_names(parser: argparse.ArgumentParser) -> set[str]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return set(action.choices)
    return set()


def open_editor(argv: list[str]) -> int:
    """`matedit [FILE]`: the editor, on FILE or on the built-in sample material."""
    if len(argv) > 1:
        raise UsageError(f"unexpected arguments after {argv[0]}: {' '.join(argv[1:])} "
                         "(usage: matedit [FILE] | matedit COMMAND ...)")
    path = argv[0] if argv else None
    if path is not None:  # bad input is reported here, as for every command
        from matedit.io.document import FormatError, load

        try:
            doc = load(path)
        except FormatError as exc:
            raise UsageError(str(exc)) from None
        if doc.is_function:
            raise UsageError(f"{path}: is a material function; open a material that uses it")
    from matedit.app.app import quit_after_first_frame, run

    if os.environ.get(QUIT_AFTER_FIRST_FRAME):
        quit_after_first_frame(os.environ[QUIT_AFTER_FIRST_FRAME])
    return run(path)


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    saved_sigterm: tuple = ()
    try:
        parser = build_parser()
        if not argv or (not argv[0].startswith("-") and argv[0] not in
                        subcommand_names(parser)):
            return open_editor(argv)
        args = parser.parse_args(argv)
        if args.version and not args.command:
            from matedit import __version__

            print(f"matedit {__version__}")
            return 0
        if not getattr(args, "run", None):
            parser.print_help()
            return 0
        saved_sigterm = _catch_sigterm()
        return int(args.run(args) or 0)
    except UsageError as exc:
        report("error", exc)
        return 2
    except KeyboardInterrupt as exc:  # SIGINT, or SIGTERM (Terminated): temporaries removed
        print("error: interrupted", file=sys.stderr)
        return 143 if isinstance(exc, Terminated) else 130
    except Exception as exc:  # internal failure: still one line, status 1
        report("error", f"internal: {type(exc).__name__}: {exc}")
        if "MATEDIT_DEBUG" in __import__("os").environ:
            raise
        return 1
    finally:
        _restore_sigterm(saved_sigterm)


if __name__ == "__main__":
    raise SystemExit(main())
