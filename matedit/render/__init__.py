"""moderngl preview renderer: meshes, camera, lights, IBL, program cache (no Qt).

The names below load on first use, so that importing a light module of the package (the pipe
to the render server, say) does not import moderngl and the renderer with it: the editor's
own process never draws (matedit.render.server does).
"""

from __future__ import annotations

import importlib
from typing import Any

_NAMES = {"OrbitCamera": "camera", "BUILTIN_MESHES": "mesh", "MeshError": "mesh",
          "MODES": "renderer", "MaterialStatus": "renderer", "Renderer": "renderer"}

__all__ = ["BUILTIN_MESHES", "MODES", "MaterialStatus", "MeshError", "OrbitCamera", "Renderer"]


def __getattr__(name: str) -> Any:
    module = _NAMES.get(name)
    if module is None:
        raise AttributeError(f"module 'matedit.render' has no attribute {name!r}")
    return getattr(importlib.import_module(f"matedit.render.{module}"), name)
