"""The pipe between the editor and its helper processes (the warm-up child, the render
server): each message a 4-byte big-endian length, then a pickle. Both ends are matedit's own
processes over their own pipes; nothing else writes to them."""

from __future__ import annotations

import pickle
import struct
from typing import Any


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
