"""Waiting for the GL without holding Python's interpreter lock.

moderngl's `Context.finish()` and a framebuffer's `read()` keep the interpreter lock while
the driver works, so every other Python thread (the editor's UI thread, when the preview
renders on a thread of its own) stops for as long as a frame takes. `finish(ctx)` calls the
driver's glFinish through ctypes instead, which lets go of the lock for the call; a read
after it finds the work done and returns at once. Where no GL library can be opened this
way, it falls back to the context's own finish().
"""

from __future__ import annotations

import ctypes
import ctypes.util
from typing import Any

_LIBRARIES = ("libOpenGL.so.0", "libGL.so.1", "OpenGL", "GL")
_finish: Any = None  # the library's glFinish, False where none could be opened


def _gl_finish() -> Any:
    global _finish
    if _finish is None:
        _finish = False
        for name in _LIBRARIES:
            path = name if "." in name else ctypes.util.find_library(name)
            if not path:
                continue
            try:
                _finish = ctypes.CDLL(path).glFinish
            except (OSError, AttributeError):
                continue
            _finish.restype, _finish.argtypes = None, []
            break
    return _finish


def finish(ctx: Any) -> None:
    """Waits until the GL work issued in `ctx` (current on this thread) is done, letting other
    Python threads run meanwhile."""
    fn = _gl_finish()
    if fn:
        fn()
    else:  # pragma: no cover - every Linux with GL has one of the libraries
        ctx.finish()
