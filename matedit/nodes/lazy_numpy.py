"""`np`: numpy, imported when a twin first reads one of its names.

The node modules define their numpy twins next to their GLSL, but only evaluation calls a
twin; checking or compiling a material never does. Importing numpy costs more than the rest
of `matedit validate`, so the catalogue's modules (and the compiler's, which fold constants
only when there are some) bind `np` to this stand-in rather than to numpy itself:

    if TYPE_CHECKING:
        import numpy as np
    else:
        from matedit.nodes.lazy_numpy import np

so the type checker sees numpy. The first read of a name imports numpy and keeps the value on
the stand-in, so later reads are plain attribute look-ups. Module-level code of those
modules must not read `np` (that would import numpy at once); tests/test_validate_startup.py
holds the valid `matedit validate` path to that.
"""

from __future__ import annotations

from typing import Any


class _DeferredNumpy:
    """Stands in for the numpy module; each attribute is fetched from it once."""

    def __getattr__(self, name: str) -> Any:  # called only for names not yet kept
        if name.startswith("__") and name.endswith("__"):
            raise AttributeError(name)  # copy, pickle and inspect probe these: not numpy's
        import numpy

        value = getattr(numpy, name)
        self.__dict__[name] = value
        return value

    def __repr__(self) -> str:
        return "<numpy, imported on first use>"


np = _DeferredNumpy()
