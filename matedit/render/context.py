"""Headless OpenGL contexts: the one place below the application that creates a context."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import moderngl


@contextlib.contextmanager
def headless() -> Iterator[moderngl.Context]:
    """A headless context for the duration of a `with` block, released after it."""
    ctx = headless_context()
    try:
        yield ctx
    finally:
        ctx.release()


def headless_context() -> moderngl.Context:
    """A headless OpenGL 3.3+ context: EGL first (no display needed), then the platform's."""
    try:
        return moderngl.create_standalone_context(require=330, backend="egl")
    except Exception:
        return moderngl.create_standalone_context(require=330)
