"""Headless OpenGL contexts: the one place below the application that creates a context."""

from __future__ import annotations

import moderngl


def headless_context() -> moderngl.Context:
    """A headless OpenGL 3.3+ context: EGL first (no display needed), then the platform's."""
    try:
        return moderngl.create_standalone_context(require=330, backend="egl")
    except Exception:
        return moderngl.create_standalone_context(require=330)
