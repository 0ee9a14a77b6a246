"""The pipe between the editor and its helper processes (the warm-up child, the render
server): each message a 4-byte big-endian length, then a pickle. Both ends are matedit's own
processes over their own pipes; nothing else writes to them. Also how such a child is
started and ended."""

from __future__ import annotations

import os
import pickle
import struct
import subprocess
import sys
from pathlib import Path
from typing import Any


def child_command(module: str, server_env: str,
                  paths: list[str] | None = None) -> tuple[list[str], dict[str, str]]:
    """The command line and environment of a helper process serving `module` on its stdin
    and stdout: `python -m module` with matedit (and `paths`, the editor's module path) on
    PYTHONPATH, or in a frozen bundle its own executable with `server_env` set (its entry
    point serves: packaging/matedit_entry.py)."""
    import matedit

    env = dict(os.environ)
    if getattr(sys, "frozen", False):
        env[server_env] = "1"
        return [sys.executable], env
    root = str(Path(matedit.__file__).resolve().parent.parent)
    env["PYTHONPATH"] = os.pathsep.join(dict.fromkeys(
        [root, *filter(None, [env.get("PYTHONPATH")]), *(paths or [])]))
    return [sys.executable, "-m", module], env


def end_child(proc: subprocess.Popen, timeout: float = 5.0) -> None:
    """Closes a helper's stdin (it ends by itself then), killing it after `timeout` s."""
    if proc.poll() is None:
        try:
            proc.stdin.close()
            proc.wait(timeout=timeout)
        except (OSError, subprocess.TimeoutExpired):
            proc.kill()


def encode(obj: Any) -> bytes:
    """One message as it goes down the pipe (raises what pickle raises)."""
    data = pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    return struct.pack(">I", len(data)) + data


def write(stream, message: bytes) -> None:
    stream.write(message)
    stream.flush()


def send(stream, obj: Any) -> None:
    write(stream, encode(obj))


def recv(stream) -> Any:
    head = stream.read(4)
    if len(head) < 4:
        raise EOFError("pipe closed")
    (n,) = struct.unpack(">I", head)
    data = stream.read(n)
    if len(data) < n:
        raise EOFError("pipe closed")
    return pickle.loads(data)  # noqa: S301 - our own process, over its own pipe
