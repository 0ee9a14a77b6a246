"""The `matedit` command (docs/cli.md: a contract)."""

from __future__ import annotations

import argparse
import contextlib
import errno
import os
import signal
import sys

from matedit.cli_support import UsageError, report

QUIT_AFTER_FIRST_FRAME = "MATEDIT_QUIT_AFTER_FIRST_FRAME"


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the program is so that every write in progress cleans up."""


_STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
_STOPPING: list[int] = []  # set once a stop signal has interrupted the command


def _on_stop_signal(signum, frame) -> None:
    """The first SIGINT or SIGTERM interrupts the command; later ones are ignored, so a
    second Ctrl+C cannot cut short the removal of temporaries the first one started."""
    for s in _STOP_SIGNALS:
        signal.signal(s, signal.SIG_IGN)
    _STOPPING.append(signum)
    raise Terminated if signum == signal.SIGTERM else KeyboardInterrupt


def _catch_sigterm() -> tuple:
    """Turn SIGTERM into `Terminated` (and SIGINT into KeyboardInterrupt, once) while a
    command runs (not the editor, whose event loop would defer it); returns what
    `_restore_sigterm` needs."""
    import threading

    if threading.current_thread() is not threading.main_thread():
        return ()
    saved = []
    for s in _STOP_SIGNALS:
        previous = signal.signal(s, _on_stop_signal)
        saved.append((s, signal.SIG_DFL if previous is None else previous))
    return tuple(saved)


def _restore_sigterm(saved: tuple) -> None:
    """The handlers from before the command; after a stop signal they stay ignored, since
    the process is ending and a second signal still pending must not raise past main."""
    if _STOPPING:
        return
    for s, handler in saved:
        signal.signal(s, handler)


class StdoutError(Exception):
    """Standard output could not be written (closed, full, or a reader that went away)."""

    def __init__(self, cause: OSError) -> None:
        self.cause = cause
        super().__init__(cause.strerror or str(cause))


class _GuardedStdout:
    """sys.stdout while a command runs: a failed write or flush becomes a StdoutError, so it
    is told apart from the command's own file errors. Everything else is the stream's."""

    def __init__(self, stream) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except OSError as exc:
            raise StdoutError(exc) from None

    def flush(self) -> None:
        try:
            self._stream.flush()
        except OSError as exc:
            raise StdoutError(exc) from None

    def isatty(self) -> bool:
        try:
            return self._stream.isatty()
        except (OSError, ValueError):
            return False

    def __getattr__(self, name: str):
        return getattr(self._stream, name)


def _hold_standard_fds() -> None:
    """Put /dev/null on stdin, stdout or stderr where the caller closed them, so files the
    command opens never take descriptors 0-2. Stdout gets it read-only: a write fails (EBADF)
    and is reported, rather than vanishing; stderr gets it writable: messages are dropped."""
    for fd, flags in ((0, os.O_RDONLY), (1, os.O_RDONLY), (2, os.O_WRONLY)):
        try:
            os.fstat(fd)
            continue
        except OSError:
            pass
        try:
            new = os.open(os.devnull, flags)
        except OSError:
            continue
        if new != fd:
            os.dup2(new, fd)
            os.close(new)
        if fd == 2 and sys.stderr is None:
            sys.stderr = open(2, "w", encoding="utf-8", errors="backslashreplace",
                              closefd=False)


@contextlib.contextmanager
def _command_stdout():
    """sys.stdout guarded for the command's run; file names that are not UTF-8 are written
    as their own bytes (surrogateescape), as the shell passed them."""
    saved = sys.stdout
    if saved is None:  # started with stdout closed: writes go to the descriptor held on 1
        try:
            saved = open(1, "w", encoding="utf-8", errors="surrogateescape", closefd=False)
        except OSError:
            saved = open(os.devnull, "w", encoding="utf-8")
        sys.stdout = saved
    errors = getattr(saved, "errors", None)
    with contextlib.suppress(AttributeError, ValueError, OSError, TypeError):
        saved.reconfigure(errors="surrogateescape")
    sys.stdout = _GuardedStdout(saved)
    try:
        yield
    finally:
        sys.stdout = saved
        if errors:
            with contextlib.suppress(AttributeError, ValueError, OSError, TypeError):
                saved.reconfigure(errors=errors)


def _stdout_failed(exc: StdoutError) -> int:
    """A broken pipe ends quietly with status 141 (128 + SIGPIPE, what `yes | head -1`
    reports); any other write failure is one error line and status 2. Either way fd 1 then
    points at /dev/null, so the interpreter's flush at exit finds nothing to fail on."""
    with contextlib.suppress(OSError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.close(devnull)
    if isinstance(exc.cause, BrokenPipeError) or exc.cause.errno == errno.EPIPE:
        return 141
    report("error", f"cannot write to standard output: {exc}")
    return 2


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # argparse would print usage and exit 2
        raise UsageError(message)


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The whole command line's parser; with `only` (a command name), one holding that
    command's parser alone: what parsing a command line that names it needs."""
    parser = _Parser(prog="matedit", description="Node-based material editor (Karis 2013). "
                     "`matedit [FILE]` opens the editor (no FILE: the built-in sample "
                     "layered material); the commands below run headless.")
    parser.add_argument("--version", action="store_true",
                        help="print the version and exit")
    sub = parser.add_subparsers(dest="command", parser_class=_Parser)
    from matedit import commands

    commands.register(sub, only)
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
    from matedit.app.render_client import prelaunch

    prelaunch()  # the viewport's render process starts while the editor imports and builds
    from matedit.app.app import quit_after_first_frame, run

    if os.environ.get(QUIT_AFTER_FIRST_FRAME):
        quit_after_first_frame(os.environ[QUIT_AFTER_FIRST_FRAME])
    return run(path)


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    _hold_standard_fds()
    try:
        from matedit.commands import COMMANDS

        named = argv[0] if argv and argv[0] in COMMANDS else None
        parser = build_parser(named)
        editor = not argv or (not argv[0].startswith("-") and named is None)
    except Exception as exc:  # pragma: no cover - a broken command registry
        report("error", f"internal: {type(exc).__name__}: {exc}")
        return 1
    if editor:
        return _run(argv, parser, editor)
    with _command_stdout():
        try:
            try:
                rc = _run(argv, parser, editor)
            except SystemExit as exc:  # argparse's --help: its text is flushed here too
                rc = exc.code if isinstance(exc.code, int) else int(exc.code is not None)
            sys.stdout.flush()
            return rc
        except StdoutError as exc:
            return _stdout_failed(exc)
        except KeyboardInterrupt as exc:  # a stop signal just as the command was ending
            report("error", "interrupted")
            return 143 if isinstance(exc, Terminated) else 130


def _run(argv: list[str], parser: argparse.ArgumentParser, editor: bool) -> int:
    saved_sigterm: tuple = ()
    try:
        if editor:
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
    except StdoutError:
        raise
    except KeyboardInterrupt as exc:  # SIGINT, or SIGTERM (Terminated): temporaries removed
        report("error", "interrupted")
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
